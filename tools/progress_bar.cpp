#include "tools/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace meshstream::tools {
namespace {

constexpr int kBarWidth = 24;

std::string minutes_seconds(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char buffer[32];
  if (s >= 3600)
    std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else
    std::snprintf(buffer, sizeof buffer, "%ld:%02ld", s / 60, s % 60);
  return buffer;
}

}  // namespace

ProgressBar::ProgressBar(std::FILE* out, bool enabled) : out_(out), enabled_(enabled) {}

bool ProgressBar::stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

std::string ProgressBar::format_line(std::string_view stage, double fraction, double elapsed_s) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(fraction * kBarWidth);
  std::string line = "encode: ";
  line += stage;
  line += " [";
  line.append(filled, '#');
  line.append(kBarWidth - filled, ' ');
  char percent[16];
  std::snprintf(percent, sizeof percent, "] %3d %%", static_cast<int>(fraction * 100));
  line += percent;
  // Too early for an estimate before 2 %: the first stage's start is not
  // typical of the rest.
  if (fraction >= 0.02 && fraction < 1) {
    line += "  ";
    line += minutes_seconds(elapsed_s * (1 - fraction) / fraction);
    line += " left";
  }
  return line;
}

void ProgressBar::update(std::string_view stage, double fraction) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (!started_) {
    started_ = true;
    start_ = now;
  }
  const bool new_stage = stage != stage_;
  if (!new_stage && drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  stage_ = stage;
  last_draw_ = now;
  draw(format_line(stage, fraction, std::chrono::duration<double>(now - start_).count()));
}

void ProgressBar::show_stage(std::string_view stage) {
  if (!enabled_) return;
  stage_ = stage;
  draw("encode: " + std::string(stage) + " ...");
}

void ProgressBar::finish() {
  if (!enabled_ || !drawn_) return;
  std::fprintf(out_, "\r%*s\r", static_cast<int>(last_width_), "");
  std::fflush(out_);
  drawn_ = false;
}

void ProgressBar::draw(const std::string& line) {
  // Pad over a longer previous line instead of relying on terminal escapes.
  const size_t pad = last_width_ > line.size() ? last_width_ - line.size() : 0;
  std::fprintf(out_, "\r%s%*s", line.c_str(), static_cast<int>(pad), "");
  std::fflush(out_);
  last_width_ = line.size();
  drawn_ = true;
}

}  // namespace meshstream::tools
