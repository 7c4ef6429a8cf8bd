// SPDX-License-Identifier: BSD-3-Clause
// RunNavigationSession: source -> Navigator -> IgtlServer, with per-status counts.
#include "tofnav/stream/navigation_session.hpp"

#include "tofnav/stream/navigation_messages.hpp"

namespace tofnav {

NavigationSessionStats RunNavigationSession(
    FrameSource& source, Navigator& navigator, IgtlServer* server,
    const std::function<void(const NavigationState&)>& on_state, const std::atomic<bool>* stop) {
  NavigationSessionStats stats;
  FrameRateMonitor rate_monitor;
  while (stop == nullptr || !*stop) {
    const std::optional<AhatFrame> frame = source.Next();
    if (!frame) break;
    NavigationState state = navigator.Process(*frame);
    const FrameRateMonitor::Reading rate = rate_monitor.Update(state.timestamp_s);
    state.received_rate_hz = rate.rate_hz;
    state.low_rate = rate.low_rate;
    if (rate.low_rate) {
      ++stats.low_rate_frames;
      if (!stats.first_low_rate_s) stats.first_low_rate_s = state.timestamp_s;
    }
    if (server != nullptr) PublishNavigationState(*server, state, navigator);
    if (stats.frames == 0) stats.first_timestamp_s = state.timestamp_s;
    stats.last_timestamp_s = state.timestamp_s;
    ++stats.frames;
    switch (state.status) {
      case NavigationStatus::kTracking:
        ++stats.tracking;
        break;
      case NavigationStatus::kHolding:
        ++stats.holding;
        break;
      case NavigationStatus::kReferenceLost:
        ++stats.reference_lost;
        break;
      case NavigationStatus::kNoWorldPose:
        ++stats.no_world_pose;
        break;
      case NavigationStatus::kNoStream:  // between frames only (live_link.hpp)
        break;
    }
    if (state.reference_settling) ++stats.settling_frames;
    if (state.world_from_image && !state.reference_settling && !stats.settled_s) {
      stats.settled_s = state.timestamp_s;
    }
    stats.reference_pose_jumps += state.reference_pose_jump ? 1 : 0;
    stats.poses_refused_void += state.poses_refused_void;
    // A tool without a pose has all its markers kUnseen: only a posed tool's say something.
    const auto posed = [](ToolStatus s) {
      return s == ToolStatus::kOk || s == ToolStatus::kPartiallyOccluded;
    };
    if (posed(state.reference_status)) {
      for (const MarkerUse use : state.reference_marker_use) ++stats.reference_markers[use];
    }
    if (state.instrument_status && posed(*state.instrument_status)) {
      for (const MarkerUse use : state.instrument_marker_use) ++stats.instrument_markers[use];
    }
    if (on_state) on_state(state);
  }
  return stats;
}

void PublishNavigationState(IgtlServer& server, const NavigationState& state,
                            const Navigator& navigator) {
  for (NamedMessage& m : EncodeNavigationFrame(state, navigator.navigation_case().plan)) {
    server.Publish(std::move(m.bytes));
  }
}

void SetNavigationGreetings(IgtlServer& server, const Navigator& navigator,
                            const std::optional<TriangleMesh>& skin_in_image,
                            const std::optional<TriangleMesh>& head_in_tool) {
  for (NamedMessage& m :
       EncodeNavigationGreetings(navigator.navigation_case(), navigator.camera().rig_from_ahat(),
                                 skin_in_image, head_in_tool)) {
    server.SetGreeting(m.device_name, std::move(m.bytes));
  }
}

}  // namespace tofnav
