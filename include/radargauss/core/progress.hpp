// SPDX-License-Identifier: BSD-3-Clause
// A one-line progress bar on stderr, drawn only when stderr is a terminal
// (no Debian package offers one; docs/design.md, "Dependencies and pitfalls").
#pragma once

#include <unistd.h>

#include <cstdio>
#include <string>

namespace radargauss {

class ProgressBar {
 public:
  ProgressBar() : enabled_(::isatty(STDERR_FILENO) == 1) {}
  ~ProgressBar() { Finish(); }

  void Update(const std::string& stage, std::size_t done, std::size_t total) {
    if (!enabled_ || total == 0) return;
    const int width = 30;
    const int filled = static_cast<int>(width * std::min(done, total) / total);
    std::fprintf(stderr, "\r%-20s [%s%s] %zu/%zu", stage.c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), done, total);
    std::fflush(stderr);
    drawn_ = true;
  }

  void Finish() {
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
  }

 private:
  bool enabled_;
  bool drawn_ = false;
};

}  // namespace radargauss
