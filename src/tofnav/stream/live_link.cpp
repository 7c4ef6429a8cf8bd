// SPDX-License-Identifier: BSD-3-Clause
// LiveHl2ssSource: faults -> NO_STREAM reports -> bounded back-off -> reconnect (and same device).
#include "tofnav/stream/live_link.hpp"

#include <algorithm>
#include <cstdio>
#include <thread>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_format.hpp"

namespace tofnav {
namespace {

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", s);
  return text;
}

/// The message of an IoError without its "<path>: " prefix.
std::string Detail(const IoError& error) {
  const std::string what = error.what();
  const std::string prefix = error.path().string() + ": ";
  return what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what;
}

/// Why a reconnect attempt failed, for the user; `detail` for other failures.
std::string AttemptFailure(NetworkFailure failure, const std::string& detail,
                           double stall_timeout_s) {
  switch (failure) {
    case NetworkFailure::kRefused:
      return "the headset refuses connections: is the hl2ss app running?";
    case NetworkFailure::kUnreachable:
      return "the headset cannot be reached: Wi-Fi down, wrong address or headset off";
    case NetworkFailure::kTimeout:
      return "the headset accepted but sent nothing for " + Seconds(stall_timeout_s);
    case NetworkFailure::kClosed:
    case NetworkFailure::kReset:
    case NetworkFailure::kTruncated:
      return "the headset closed the new connection";
    case NetworkFailure::kOther:
      break;
  }
  return detail;
}

}  // namespace

void LiveLinkOptions::Check() const {
  Require(stall_timeout_s > 0.0, "LiveLinkOptions.stall_timeout_s must be > 0");
  Require(first_backoff_s > 0.0, "LiveLinkOptions.first_backoff_s must be > 0");
  Require(max_backoff_s >= first_backoff_s,
          "LiveLinkOptions.max_backoff_s must be >= first_backoff_s");
  Require(calibration_timeout_s > 0.0, "LiveLinkOptions.calibration_timeout_s must be > 0");
  Require(give_up_after_s >= 0.0, "LiveLinkOptions.give_up_after_s must be >= 0 (0: never)");
  Require(report_period_s > 0.0, "LiveLinkOptions.report_period_s must be > 0");
}

LiveHl2ssSource::LiveHl2ssSource(const Hl2ssEndpoint& endpoint, const Hl2ssAhatConfig& config,
                                 const LiveLinkOptions& options,
                                 std::optional<std::vector<std::uint8_t>> device_calibration,
                                 OnReport on_report, const std::atomic<bool>* stop)
    : endpoint_(endpoint),
      config_(config),
      options_(options),
      device_calibration_(std::move(device_calibration)),
      on_report_(std::move(on_report)),
      stop_(stop) {
  options_.Check();
  client_ = std::make_unique<Hl2ssAhatClient>(endpoint_, config_, options_.stall_timeout_s);
  last_frame_at_ = Clock::now();
}

LiveHl2ssSource::~LiveHl2ssSource() = default;

std::optional<AhatFrame> LiveHl2ssSource::Next() {
  while (stop_ == nullptr || !*stop_) {
    if (client_ == nullptr && !Reconnect()) return std::nullopt;
    std::string what;
    NetworkFailure failure = NetworkFailure::kClosed;
    try {
      std::optional<AhatFrame> frame = client_->Next();
      CountDroppedFrames();
      if (frame) {
        if (!up_) Back();
        last_frame_at_ = Clock::now();
        ++frames_on_connection_;
        return frame;
      }
      what = "the headset closed the stream";
    } catch (const NetworkError& e) {
      failure = e.failure();
      switch (failure) {
        case NetworkFailure::kTimeout:
          what = "no frame from the headset for " + Seconds(options_.stall_timeout_s);
          break;
        case NetworkFailure::kReset:
          what = "the headset reset the connection";
          break;
        case NetworkFailure::kTruncated:
          what = "the stream broke off inside a packet";
          break;
        default:
          what = "the connection failed (" + Detail(e) + ")";
      }
    } catch (const IoError& e) {
      failure = NetworkFailure::kOther;
      what = "the headset sent a damaged packet (" + Detail(e) + ")";
    }
    client_.reset();
    if (up_) {
      GoDown(what, failure == NetworkFailure::kTimeout);
    } else {
      AttemptFailed(failure, what);
    }
  }
  return std::nullopt;
}

void LiveHl2ssSource::Back() {
  const double down_s = DownS();
  up_ = true;
  ++stats_.reconnects;
  stats_.down_s += down_s;
  stats_.longest_down_s = std::max(stats_.longest_down_s, down_s);
  Report({.up = true,
          .changed = true,
          .down_s = down_s,
          .message = Hl2ssUri(endpoint_) + ": the stream is back after " + Seconds(down_s) +
                     " without frames; navigating again"});
}

void LiveHl2ssSource::GoDown(const std::string& what, bool stalled) {
  up_ = false;
  ++(stalled ? stats_.stalls : stats_.disconnects);
  backoff_s_ = options_.first_backoff_s;
  reported_failures_.clear();
  Report({.up = false,
          .changed = true,
          .down_s = DownS(),
          .message = Hl2ssUri(endpoint_) + ": " + what + " after " +
                     std::to_string(frames_on_connection_) + " frames; reconnecting"});
}

bool LiveHl2ssSource::Reconnect() {
  while (true) {
    if (!Wait(backoff_s_)) return false;
    backoff_s_ = std::min(2.0 * backoff_s_, options_.max_backoff_s);
    try {
      if (device_calibration_ &&
          DownloadHl2ssCalibrationBytes(endpoint_, options_.calibration_timeout_s) !=
              *device_calibration_) {
        failure_ = Hl2ssUri(endpoint_) +
                   ": the device that answered is not the one navigation started with (its "
                   "AHAT calibration differs); stopped: restart tofnav navigate to use it";
        return false;
      }
      client_ = std::make_unique<Hl2ssAhatClient>(endpoint_, config_, options_.stall_timeout_s);
      client_dropped_ = 0;
      frames_on_connection_ = 0;
      return true;
    } catch (const NetworkError& e) {
      AttemptFailed(e.failure(), Detail(e));
    }
  }
}

void LiveHl2ssSource::AttemptFailed(NetworkFailure failure, const std::string& detail) {
  ++stats_.failed_attempts;
  if (std::ranges::find(reported_failures_, failure) != reported_failures_.end()) return;
  reported_failures_.push_back(failure);
  Report({.up = false,
          .changed = false,
          .down_s = DownS(),
          .message = Hl2ssUri(endpoint_) + ": reconnecting failed (" +
                     AttemptFailure(failure, detail, options_.stall_timeout_s) +
                     "); trying again every " + Seconds(options_.max_backoff_s) + " at most"});
}

bool LiveHl2ssSource::Wait(double seconds) {
  const Clock::time_point until = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                     std::chrono::duration<double>(seconds));
  while (stop_ == nullptr || !*stop_) {
    const Clock::time_point now = Clock::now();
    if (options_.give_up_after_s > 0.0 && DownS() >= options_.give_up_after_s) {
      failure_ = Hl2ssUri(endpoint_) + ": gave up after " + Seconds(options_.give_up_after_s) +
                 " without frames";
      return false;
    }
    if (now - last_report_at_ >= std::chrono::duration<double>(options_.report_period_s)) {
      Report({.up = false, .changed = false, .down_s = DownS(), .message = {}});
    }
    if (now >= until) return true;
    std::this_thread::sleep_until(
        std::min(until, now + std::chrono::duration_cast<Clock::duration>(
                                  std::chrono::duration<double>(options_.report_period_s))));
  }
  return false;
}

double LiveHl2ssSource::DownS() const {
  return std::chrono::duration<double>(Clock::now() - last_frame_at_).count();
}

void LiveHl2ssSource::Report(const LinkReport& report) {
  last_report_at_ = Clock::now();
  if (on_report_) on_report_(report);
}

void LiveHl2ssSource::CountDroppedFrames() {
  const std::int64_t dropped = client_->dropped_frames();
  if (dropped == client_dropped_) return;
  stats_.dropped_frames += dropped - client_dropped_;
  client_dropped_ = dropped;
  Report({.up = up_,
          .message = "dropped a frame that did not decode (" +
                     std::to_string(stats_.dropped_frames) +
                     " so far): " + client_->last_drop_reason()});
}

LiveLinkStats LiveHl2ssSource::stats() const {
  LiveLinkStats stats = stats_;
  if (!up_) {
    stats.down_s += DownS();
    stats.longest_down_s = std::max(stats.longest_down_s, DownS());
  }
  return stats;
}

std::string LiveHl2ssSource::description() const {
  return Hl2ssUri(endpoint_) + " " + Hl2ssProfileName(config_) + " (live, reconnects)";
}

NavigationState NoStreamState(const NavigationState& last, double down_s) {
  NavigationState s;
  s.timestamp_s = last.timestamp_s + down_s;
  s.status = NavigationStatus::kNoStream;
  s.stream_down_s = down_s;
  s.reference_status = ToolStatus::kOutOfView;
  s.reference_age_s = last.reference_age_s + down_s;  // infinity (never seen) stays
  s.active_trajectory = last.active_trajectory;
  if (last.instrument_status) s.instrument_status = ToolStatus::kOutOfView;
  return s;
}

}  // namespace tofnav
