#include "server/model_suggestions.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace meshstream::server {
namespace {

constexpr size_t kMaxRequestForSuggestions = 128;

}  // namespace

size_t edit_distance(std::string_view a, std::string_view b) {
  // Three rows: the one before the previous is needed for transpositions.
  std::vector<size_t> before(b.size() + 1), previous(b.size() + 1), current(b.size() + 1);
  std::iota(previous.begin(), previous.end(), size_t(0));
  for (size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t substitute = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitute});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        current[j] = std::min(current[j], before[j - 2] + 1);
      }
    }
    std::swap(before, previous);
    std::swap(previous, current);
  }
  return previous[b.size()];
}

std::vector<std::string> closest_names(std::string_view requested,
                                       const std::vector<std::string>& names, size_t limit) {
  if (requested.empty() || requested.size() > kMaxRequestForSuggestions) return {};
  const size_t max_distance = std::clamp<size_t>(requested.size() / 3, 1, 3);
  const auto dot = requested.rfind('.');
  const std::string_view stem =
      dot == std::string_view::npos || dot == 0 ? std::string_view() : requested.substr(0, dot);
  struct Candidate {
    size_t distance;
    const std::string* name;
  };
  std::vector<Candidate> close;
  for (const std::string& name : names) {
    if (name == requested) continue;
    // The request with its extension removed counts as one edit away.
    const size_t distance = (!stem.empty() && name == stem) ? 1 : edit_distance(requested, name);
    if (distance <= max_distance) close.push_back({distance, &name});
  }
  std::stable_sort(close.begin(), close.end(),
                   [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
  std::vector<std::string> out;
  for (size_t i = 0; i < close.size() && i < limit; ++i) out.push_back(*close[i].name);
  return out;
}

std::string printable(std::string_view text, size_t max_bytes) {
  std::string out;
  for (size_t i = 0; i < text.size() && i < max_bytes; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      out += escaped;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (text.size() > max_bytes) out += "...";
  return out;
}

std::string unknown_model_message(std::string_view requested,
                                  const std::vector<std::string>& suggestions) {
  std::string text = "unknown model '" + printable(requested) + "'";
  if (!suggestions.empty()) {
    text += ": did you mean ";
    for (size_t i = 0; i < suggestions.size(); ++i) {
      if (i > 0) text += i + 1 == suggestions.size() ? " or " : ", ";
      text += "'" + suggestions[i] + "'";
    }
    text += "?";
  }
  return text + " (see --list)";
}

}  // namespace meshstream::server
