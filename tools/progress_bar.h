// A one-line progress bar on stderr for long commands (`meshstream encode`):
// the stage, a bar, the percent and an estimate of the time left, redrawn
// in place. Only for a terminal: a log or a pipe gets no bar (and no
// carriage returns).
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>

namespace meshstream::tools {

class ProgressBar {
 public:
  // Draws on `out` when `enabled`; otherwise every call does nothing.
  ProgressBar(std::FILE* out, bool enabled);
  ~ProgressBar() { finish(); }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // Whether stderr is a terminal (the default for `--progress`).
  static bool stderr_is_terminal();

  // Shows `stage` at `fraction` (0..1) of the whole; redraws at most every
  // 0.1 s unless the stage changed. The time left is estimated from the
  // time since the first call once 2 % is done.
  void update(std::string_view stage, double fraction);
  // A stage without a percent yet (e.g. reading the input).
  void show_stage(std::string_view stage);
  // Clears the line (nothing is left behind on the terminal).
  void finish();

  // The line for `stage` at `fraction` after `elapsed_s` seconds (no
  // carriage return): "encode: coding records [#####     ]  42 %  1:05 left".
  static std::string format_line(std::string_view stage, double fraction, double elapsed_s);

 private:
  void draw(const std::string& line);

  std::FILE* out_;
  bool enabled_;
  bool drawn_ = false;
  std::string stage_;
  std::chrono::steady_clock::time_point start_{}, last_draw_{};
  bool started_ = false;
  size_t last_width_ = 0;
};

}  // namespace meshstream::tools
