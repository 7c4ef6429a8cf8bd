// SPDX-License-Identifier: BSD-3-Clause
// A one-line progress bar with rate and time left, drawn only on a terminal (quiet on pipes).
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace tofnav {

class ProgressBar {
 public:
  /// Draws on stderr when it is a terminal and `quiet` is false.
  ProgressBar(std::string label, bool quiet = false);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// Redraws at most ten times a second, and always at done == total.
  void Update(std::size_t done, std::size_t total);
  /// Ends the bar's line (the destructor does it too): call before printing the results, so they
  /// do not continue the bar's line on a terminal.
  void Finish();

 private:
  std::string label_;
  bool enabled_ = false;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace tofnav
