// SPDX-License-Identifier: BSD-3-Clause
// A command run in a forked worker process watched by its parent, so that whatever ends the
// worker (an exception, a signal, SIGKILL, a crash) the parent can still clean up after it
// (docs/navigation.md 6.6).
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "tofnav/stream/headset_display.hpp"

namespace tofnav {

/// How the worker ended.
struct WorkerEnd {
  int exit_code = 0;  // when it exited
  int signal = 0;     // the signal that ended it; 0 when it exited
  /// "exited with status 1", "was killed by signal 9 (SIGKILL)".
  std::string Describe() const;
  /// What a shell reports for it: the exit code, or 128 + the signal.
  int ShellStatus() const;
};

/// Forks. In the child (the worker) returns nullopt at once: the caller goes on with the
/// command. In the parent it forwards SIGINT, SIGTERM and SIGHUP to the worker, waits for it to
/// end, and returns `after(end)`: the status the command ends with. The worker gets SIGTERM when
/// the parent dies. Call it before any thread exists. When fork fails, says so on stderr and
/// returns nullopt (the command runs unsupervised).
std::optional<int> RunAsSupervisedWorker(const std::function<int(const WorkerEnd&)>& after);

/// What the worker's headset shows, kept in memory shared with the supervisor: written by the
/// worker's display (HeadsetDisplayOptions::on_shown), read by the supervisor once the worker has
/// ended. A worker killed while writing leaves the previous complete record.
class SharedHeadsetRecord {
 public:
  SharedHeadsetRecord();  // maps the shared page; std::runtime_error when it cannot
  ~SharedHeadsetRecord();
  SharedHeadsetRecord(const SharedHeadsetRecord&) = delete;
  SharedHeadsetRecord& operator=(const SharedHeadsetRecord&) = delete;

  void Write(const HeadsetShown& shown);  // one writer thread
  HeadsetShown Read() const;              // the panel's place, without its text

 private:
  struct Page;
  Page* page_ = nullptr;
};

}  // namespace tofnav
