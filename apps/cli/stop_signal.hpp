// SPDX-License-Identifier: BSD-3-Clause
// Ctrl-C as a request: long-running commands (navigate, serve) stop cleanly and say why.
#pragma once

#include <atomic>
#include <string>

namespace tofnav {

/// While it lives, SIGINT (Ctrl-C) and SIGTERM set stop() instead of ending the process; the
/// previous handlers come back on destruction. One at a time.
class StopOnSignal {
 public:
  StopOnSignal();
  ~StopOnSignal();
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;

  /// Set by a signal; the command may set it too (a time limit).
  std::atomic<bool>& stop();
  /// True when a signal, not the command, asked to stop.
  bool signalled() const;
  /// "stopped by the user (Ctrl-C)" or "stopped by SIGTERM"; empty when no signal came.
  std::string Reason() const;
};

}  // namespace tofnav
