// SPDX-License-Identifier: BSD-3-Clause
// RunAsSupervisedWorker and SharedHeadsetRecord (docs/navigation.md 6.6). POSIX fork, waitpid
// and a shared anonymous mapping: no library offers a process supervisor at this size.
#include "supervisor.hpp"

#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace tofnav {
namespace {

std::atomic<pid_t> supervised_worker{0};

void ForwardToWorker(int signal) {
  const pid_t worker = supervised_worker.load();
  if (worker > 0) ::kill(worker, signal);
}

constexpr std::array<int, 3> kForwarded{SIGINT, SIGTERM, SIGHUP};

}  // namespace

std::string WorkerEnd::Describe() const {
  if (signal == 0) return "exited with status " + std::to_string(exit_code);
  const char* abbrev = ::sigabbrev_np(signal);
  return "was killed by signal " + std::to_string(signal) + " (SIG" +
         (abbrev != nullptr ? abbrev : "?") + ")";
}

int WorkerEnd::ShellStatus() const { return signal == 0 ? exit_code : 128 + signal; }

std::optional<int> RunAsSupervisedWorker(const std::function<int(const WorkerEnd&)>& after) {
  std::fflush(stdout);  // nothing buffered is written twice
  std::fflush(stderr);
  const pid_t supervisor = ::getpid();
  const pid_t worker = ::fork();
  if (worker < 0) {
    std::fprintf(stderr,
                 "tofnav: warning: could not start the supervising process (fork: %s): if this "
                 "process is killed or crashes, the headset keeps its last holograms\n",
                 std::strerror(errno));
    return std::nullopt;
  }
  if (worker == 0) {
    // The supervisor gone (even by SIGKILL): stop as on Ctrl-C, which clears the headset.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != supervisor) ::raise(SIGTERM);  // it died before prctl
    return std::nullopt;
  }
  supervised_worker = worker;
  std::array<struct sigaction, kForwarded.size()> previous{};
  struct sigaction forward {};
  forward.sa_handler = ForwardToWorker;
  sigemptyset(&forward.sa_mask);
  forward.sa_flags = SA_RESTART;
  for (std::size_t i = 0; i < kForwarded.size(); ++i) {
    ::sigaction(kForwarded[i], &forward, &previous[i]);
  }
  int status = 0;
  pid_t waited = -1;
  do {
    waited = ::waitpid(worker, &status, 0);
  } while (waited < 0 && errno == EINTR);
  for (std::size_t i = 0; i < kForwarded.size(); ++i) {
    ::sigaction(kForwarded[i], &previous[i], nullptr);
  }
  supervised_worker = 0;
  WorkerEnd end;
  if (waited < 0) {
    end.exit_code = 1;  // cannot happen for our own child; treated as a failed worker
  } else if (WIFSIGNALED(status)) {
    end.signal = WTERMSIG(status);
  } else {
    end.exit_code = WEXITSTATUS(status);
  }
  return after(end);
}

// Two slots: the writer fills the one not current, then publishes it, so a worker killed in the
// middle of a write leaves the last complete record current.
struct SharedHeadsetRecord::Page {
  struct Slot {
    bool anything = false;
    bool panel_known = false;
    double at_in_world[3] = {0, 0, 0};
    double facing_in_world[3] = {0, 0, 0};
  };
  Slot slots[2];
  std::atomic<int> current{0};
};
static_assert(std::atomic<int>::is_always_lock_free, "shared between processes");

SharedHeadsetRecord::SharedHeadsetRecord() {
  void* p =
      ::mmap(nullptr, sizeof(Page), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) {
    throw std::runtime_error(std::string("cannot map memory shared with the supervisor: ") +
                             std::strerror(errno));
  }
  page_ = new (p) Page();
}

SharedHeadsetRecord::~SharedHeadsetRecord() {
  page_->~Page();
  ::munmap(page_, sizeof(Page));
}

void SharedHeadsetRecord::Write(const HeadsetShown& shown) {
  const int next = 1 - page_->current.load(std::memory_order_relaxed);
  Page::Slot& s = page_->slots[next];
  s.anything = shown.anything;
  s.panel_known = shown.panel.has_value();
  if (shown.panel) {
    for (int k = 0; k < 3; ++k) {
      s.at_in_world[k] = shown.panel->a_in_world[k];
      s.facing_in_world[k] = shown.panel->b_in_world[k];
    }
  }
  page_->current.store(next, std::memory_order_release);
}

HeadsetShown SharedHeadsetRecord::Read() const {
  const Page::Slot& s = page_->slots[page_->current.load(std::memory_order_acquire)];
  HeadsetShown shown;
  shown.anything = s.anything;
  if (s.panel_known) {
    Hologram panel;
    panel.shape = HologramShape::kText;
    panel.visible = true;
    panel.a_in_world = {s.at_in_world[0], s.at_in_world[1], s.at_in_world[2]};
    panel.b_in_world = {s.facing_in_world[0], s.facing_in_world[1], s.facing_in_world[2]};
    shown.panel = panel;
  }
  return shown;
}

}  // namespace tofnav
