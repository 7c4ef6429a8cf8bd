// SPDX-License-Identifier: BSD-3-Clause
#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace tofnav {

ProgressBar::ProgressBar(std::string label, bool quiet)
    : label_(std::move(label)),
      enabled_(!quiet && ::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Finish() {
  if (drawn_) std::fputc('\n', stderr);
  drawn_ = false;
  enabled_ = false;
}

void ProgressBar::Update(std::size_t done, std::size_t total) {
  if (!enabled_ || total == 0) return;
  done = std::min(done, total);  // a caller counting past its estimate must not wrap the ETA
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && done < total && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  drawn_ = true;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed_s > 0.0 ? static_cast<double>(done) / elapsed_s : 0.0;
  constexpr int kWidth = 30;
  const int filled =
      static_cast<int>(kWidth * static_cast<double>(done) / static_cast<double>(total));
  // Before the first step is done there is no rate to estimate the time left from.
  char left[32] = "? s left";
  if (rate > 0.0) {
    std::snprintf(left, sizeof left, "%.0f s left", static_cast<double>(total - done) / rate);
  }
  std::fprintf(stderr, "\r%s [%.*s%*s] %zu/%zu  %.1f/s  %s ", label_.c_str(), filled,
               "##############################", kWidth - filled, "", done, total, rate, left);
  std::fflush(stderr);
}

}  // namespace tofnav
