// SPDX-License-Identifier: BSD-3-Clause
// NavigationState -> OpenIGTLink messages with PLUS/SlicerIGT names (docs/navigation.md).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/pipeline/navigator.hpp"

namespace tofnav {

/// ras_from_image: LPS to 3D Slicer RAS, diag(-1, -1, 1), a half turn about z.
Rigid3d RasFromImage();

/// One encoded message and its device name.
struct NamedMessage {
  std::string device_name;
  std::vector<std::uint8_t> bytes;
};

/// The per-frame messages. Transforms are only sent while they are current: ReferenceToAhat
/// (ahat_from_tool) and ToolToReference (tool_from_instrument) only when measured in this frame,
/// RigToWorld when the frame has a head pose, RasToWorld (world_from_image * image_from_ras) while
/// the reference was seen within NavigatorOptions::stale_after_s; a stale pose is never re-sent.
/// Always a STRING "NavigationStatus" (the status line). Time stamps: the frame's, in seconds
/// since the device booted (hl2ss host ticks).
std::vector<NamedMessage> EncodeNavigationFrame(const NavigationState& state,
                                                const std::vector<Trajectory>& plan);

/// Constant content a client gets on connecting (IgtlServer::SetGreeting): AhatToRig,
/// ReferenceToRas (the registration, tool in RAS), ToolTipToTool (instrument tip), POINT "Plan"
/// (entries and targets in RAS), POLYDATA "SkinRas" (CT skin, given in `image`) and
/// "HeadSurface" (reconstruction, given in `tool`; drawn under ReferenceToRas).
std::vector<NamedMessage> EncodeNavigationGreetings(
    const NavigationCase& navigation_case, const Rigid3d& rig_from_ahat,
    const std::optional<TriangleMesh>& skin_in_image,
    const std::optional<TriangleMesh>& head_in_tool);

/// The one-line status: "TRACKING t=12.345s ref=ok age=0ms markers=7 | right-1 tip->entry 3.2mm
/// angle 1.4deg depth 55.0mm"; NO_STREAM adds how long the link has been down ("down=1.2s").
std::string NavigationStatusLine(const NavigationState& state, const std::vector<Trajectory>& plan);

}  // namespace tofnav
