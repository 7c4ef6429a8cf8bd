// SPDX-License-Identifier: BSD-3-Clause
// The phase-3 loop: frames from a source through the Navigator to OpenIGTLink clients.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>

#include "tofnav/pipeline/navigator.hpp"
#include "tofnav/stream/frame_rate_monitor.hpp"
#include "tofnav/stream/frame_source.hpp"
#include "tofnav/stream/igtl_server.hpp"

namespace tofnav {

struct NavigationSessionStats {
  std::int64_t frames = 0;
  std::int64_t tracking = 0;        // NavigationStatus::kTracking
  std::int64_t holding = 0;         // kHolding
  std::int64_t reference_lost = 0;  // kReferenceLost
  std::int64_t no_world_pose = 0;   // kNoWorldPose
  /// Reference poses measured but left out because their world pose jumped (Navigator), and
  /// per tool (reference, then instrument) the marker observations by how they entered the pose
  /// (MarkerUse; frames where the tool was matched).
  std::int64_t reference_pose_jumps = 0;
  std::int64_t poses_refused_void = 0;  // NavigationState::poses_refused_void, summed
  std::map<MarkerUse, std::int64_t> reference_markers, instrument_markers;
  double first_timestamp_s = 0.0;
  double last_timestamp_s = 0.0;
  std::int64_t low_rate_frames = 0;        // frames processed with NavigationState::low_rate
  std::optional<double> first_low_rate_s;  // time stamp of the first of them
  std::int64_t settling_frames = 0;        // frames placed with NavigationState::reference_settling
  std::optional<double> settled_s;         // time stamp of the first frame placed and not settling
};

/// Runs every frame of `source` through `navigator`, publishes EncodeNavigationFrame's messages
/// on `server` (when given) and hands each state to `on_state` (when given), until the source
/// ends or `stop` (when given) becomes true. Frames are processed as they come: a slow client
/// never slows the loop (IgtlServer drops instead).
NavigationSessionStats RunNavigationSession(
    FrameSource& source, Navigator& navigator, IgtlServer* server,
    const std::function<void(const NavigationState&)>& on_state = {},
    const std::atomic<bool>* stop = nullptr);

/// Publishes EncodeNavigationFrame(state, plan) on `server`: the per-frame hook, also used for
/// the NO_STREAM states of a live link that is down (live_link.hpp).
void PublishNavigationState(IgtlServer& server, const NavigationState& state,
                            const Navigator& navigator);

/// Sets the greetings of a navigation stream on `server` (EncodeNavigationGreetings).
void SetNavigationGreetings(IgtlServer& server, const Navigator& navigator,
                            const std::optional<TriangleMesh>& skin_in_image = {},
                            const std::optional<TriangleMesh>& head_in_tool = {});

}  // namespace tofnav
