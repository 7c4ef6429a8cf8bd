// SPDX-License-Identifier: BSD-3-Clause
// Signal handlers may only touch lock-free atomics with static storage: hence the two globals.
#include "stop_signal.hpp"

#include <csignal>

namespace tofnav {
namespace {

std::atomic<bool> stop_requested{false};
std::atomic<int> stop_signal_number{0};  // 0: no signal
struct sigaction previous_int {};
struct sigaction previous_term {};

void OnSignal(int signal) {
  stop_signal_number = signal;
  stop_requested = true;
}

}  // namespace

StopOnSignal::StopOnSignal() {
  stop_requested = false;
  stop_signal_number = 0;
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, &previous_int);
  sigaction(SIGTERM, &action, &previous_term);
}

StopOnSignal::~StopOnSignal() {
  sigaction(SIGINT, &previous_int, nullptr);
  sigaction(SIGTERM, &previous_term, nullptr);
}

std::atomic<bool>& StopOnSignal::stop() { return stop_requested; }

bool StopOnSignal::signalled() const { return stop_signal_number != 0; }

std::string StopOnSignal::Reason() const {
  return stop_signal_number == SIGINT    ? "stopped by the user (Ctrl-C)"
         : stop_signal_number == SIGTERM ? "stopped by SIGTERM"
                                         : "";
}

}  // namespace tofnav
