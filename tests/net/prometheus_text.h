// For the --metrics tests: a strict checker of the Prometheus text
// exposition format (0.0.4) as the server must write it, and a parser of its
// samples; and scraping with the real curl binary (a real HTTP client, not
// ours). promtool is not packaged in Debian 12, so the rules are spelt out
// here: every line is "# HELP name text", "# TYPE name type" or a sample
// "name[{label="value",...}] number"; names match [a-zA-Z_:][a-zA-Z0-9_:]*,
// label names [a-zA-Z_][a-zA-Z0-9_]*, label values are quoted with only \\,
// \" and \n escaped; a family has one HELP and one TYPE, before its samples,
// and its samples are contiguous; a counter's name ends in _total; no
// series appears twice; the text ends with a newline.
#pragma once

#include <array>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace meshstream::nettest {

struct PrometheusText {
  std::string problem;                    // empty when the text is valid
  std::map<std::string, double> samples;  // series (name{labels} as written) -> value
  std::map<std::string, std::string> types;
  double value(const std::string& series) const {
    const auto it = samples.find(series);
    return it == samples.end() ? -1 : it->second;
  }
};

inline PrometheusText parse_prometheus(const std::string& text) {
  PrometheusText out;
  static const std::regex help(R"(# HELP ([a-zA-Z_:][a-zA-Z0-9_:]*) \S.*)");
  static const std::regex type(
      R"(# TYPE ([a-zA-Z_:][a-zA-Z0-9_:]*) (counter|gauge|histogram|summary|untyped))");
  static const std::regex sample(
      R"(([a-zA-Z_:][a-zA-Z0-9_:]*)(\{([a-zA-Z_][a-zA-Z0-9_]*="([^"\\\n]|\\[\\"n])*")(,[a-zA-Z_][a-zA-Z0-9_]*="([^"\\\n]|\\[\\"n])*")*\})? (-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?|NaN|[+-]Inf))");
  if (text.empty() || text.back() != '\n') {
    out.problem = "the text does not end with a newline";
    return out;
  }
  std::set<std::string> helped, typed, finished;
  std::string current;  // family of the samples being read
  std::istringstream in(text);
  std::string line;
  int number = 0;
  auto fail = [&](const std::string& why) {
    out.problem = "line " + std::to_string(number) + " '" + line + "': " + why;
    return out;
  };
  while (std::getline(in, line)) {
    ++number;
    std::smatch m;
    if (std::regex_match(line, m, help)) {
      if (!helped.insert(m[1]).second) return fail("second HELP for the family");
      if (typed.count(m[1])) return fail("HELP after TYPE");
      continue;
    }
    if (std::regex_match(line, m, type)) {
      const std::string name = m[1];
      if (!typed.insert(name).second) return fail("second TYPE for the family");
      if (finished.count(name) || current == name) return fail("TYPE after its samples");
      if (m[2] == "counter" && !name.ends_with("_total")) return fail("counter not named *_total");
      out.types[name] = m[2];
      continue;
    }
    if (!line.empty() && line[0] == '#') return fail("a comment that is neither HELP nor TYPE");
    if (!std::regex_match(line, m, sample)) return fail("not a sample line");
    const std::string name = m[1];
    if (name != current) {
      if (finished.count(name)) return fail("samples of the family are not contiguous");
      if (!current.empty()) finished.insert(current);
      current = name;
    }
    if (!typed.count(name) || !helped.count(name)) return fail("sample before its HELP and TYPE");
    const std::string series = line.substr(0, line.rfind(' '));
    if (out.samples.count(series)) return fail("the series appears twice");
    out.samples[series] = std::strtod(line.c_str() + line.rfind(' ') + 1, nullptr);
  }
  return out;
}

// An HTTP answer as the real curl saw it; status 0 = curl could not connect.
struct HttpAnswer {
  int status = 0;
  std::string content_type;
  std::string body;
};

inline bool have_curl() { return std::system("curl --version > /dev/null 2>&1") == 0; }

// curl -s with `extra` options (e.g. "-I", "-X POST") on `url`, 5 s at most.
inline HttpAnswer curl(const std::string& url, const std::string& extra = "") {
  HttpAnswer answer;
  const std::string command =
      "curl -s -m 5 " + extra + " -w '\\n%{http_code} %{content_type}' '" + url + "' 2>/dev/null";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return answer;
  std::string all;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) all.append(buffer.data(), n);
  ::pclose(pipe);
  const auto last = all.rfind('\n');
  if (last == std::string::npos) return answer;
  const std::string tail = all.substr(last + 1);
  answer.body = all.substr(0, last);
  answer.status = std::atoi(tail.c_str());
  const auto space = tail.find(' ');
  if (space != std::string::npos) answer.content_type = tail.substr(space + 1);
  return answer;
}

}  // namespace meshstream::nettest
