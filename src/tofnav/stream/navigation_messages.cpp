// SPDX-License-Identifier: BSD-3-Clause
// Wire names and frames of the navigation stream; `image` (LPS) becomes Slicer RAS here.
#include "tofnav/stream/navigation_messages.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "tofnav/stream/igtl_codec.hpp"

namespace tofnav {
namespace {

NamedMessage TransformMessage(const std::string& name, const Rigid3d& parent_from_child,
                              std::uint64_t timestamp) {
  return {name,
          EncodeIgtlMessage("TRANSFORM", name, timestamp, IgtlTransformContent(parent_from_child))};
}

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

}  // namespace

Rigid3d RasFromImage() {
  return Rigid3d(Eigen::Quaterniond(0.0, 0.0, 0.0, 1.0), Eigen::Vector3d::Zero());
}

std::vector<NamedMessage> EncodeNavigationFrame(const NavigationState& state,
                                                const std::vector<Trajectory>& plan) {
  const std::uint64_t ts = IgtlTimestamp(std::max(0.0, state.timestamp_s));
  std::vector<NamedMessage> out;
  if (state.ahat_from_tool)
    out.push_back(TransformMessage("ReferenceToAhat", *state.ahat_from_tool, ts));
  if (state.world_from_rig)
    out.push_back(TransformMessage("RigToWorld", *state.world_from_rig, ts));
  if (state.world_from_image) {
    out.push_back(
        TransformMessage("RasToWorld", *state.world_from_image * RasFromImage().Inverse(), ts));
  }
  if (state.tool_from_instrument) {
    out.push_back(TransformMessage("ToolToReference", *state.tool_from_instrument, ts));
  }
  const std::string line = NavigationStatusLine(state, plan);
  out.push_back({"NavigationStatus",
                 EncodeIgtlMessage("STRING", "NavigationStatus", ts, IgtlStringContent(line))});
  return out;
}

std::vector<NamedMessage> EncodeNavigationGreetings(
    const NavigationCase& c, const Rigid3d& rig_from_ahat,
    const std::optional<TriangleMesh>& skin_in_image,
    const std::optional<TriangleMesh>& head_in_tool) {
  std::vector<NamedMessage> out;
  out.push_back(TransformMessage("AhatToRig", rig_from_ahat, 0));
  out.push_back(
      TransformMessage("ReferenceToRas", RasFromImage() * c.tool_from_image.Inverse(), 0));
  if (c.instrument && c.instrument->tip_in_tool) {
    out.push_back(
        TransformMessage("ToolTipToTool", Rigid3d({1, 0, 0, 0}, *c.instrument->tip_in_tool), 0));
  }
  std::vector<IgtlPoint> points;
  for (const Trajectory& t : c.plan) {
    points.push_back(
        {t.name + " entry", "Entry", {0, 200, 0, 255}, RasFromImage() * t.entry_lps_mm, 3.0, ""});
    points.push_back({t.name + " target",
                      "Target",
                      {220, 0, 0, 255},
                      RasFromImage() * t.target_lps_mm,
                      3.0,
                      ""});
  }
  if (!points.empty())
    out.push_back({"Plan", EncodeIgtlMessage("POINT", "Plan", 0, IgtlPointContent(points))});
  if (skin_in_image) {
    out.push_back({"SkinRas", EncodeIgtlMessage(
                                  "POLYDATA", "SkinRas", 0,
                                  IgtlPolyDataContent(Transform(RasFromImage(), *skin_in_image)))});
  }
  if (head_in_tool) {
    out.push_back({"HeadSurface", EncodeIgtlMessage("POLYDATA", "HeadSurface", 0,
                                                    IgtlPolyDataContent(*head_in_tool))});
  }
  return out;
}

std::string NavigationStatusLine(const NavigationState& s, const std::vector<Trajectory>& plan) {
  std::string line = std::string(ToString(s.status)) + Format(" t=%.3fs", s.timestamp_s);
  if (s.status == NavigationStatus::kNoStream) line += Format(" down=%.1fs", s.stream_down_s);
  if (s.low_rate) line += Format(" LOW_RATE rate=%.1fHz", s.received_rate_hz);
  line += std::string(" ref=") + ToString(s.reference_status);
  line += std::isfinite(s.reference_age_s) ? Format(" age=%.0fms", s.reference_age_s * 1e3)
                                           : " age=never";
  if (s.reference_settling && s.reference_rotation_sd_rad) {
    line += Format(" SETTLING sd=%.2fdeg", *s.reference_rotation_sd_rad * 180.0 / std::numbers::pi);
  }
  line += " markers=" + std::to_string(s.detected_markers);
  if (s.guidance) {
    const std::size_t i = static_cast<std::size_t>(s.active_trajectory);
    line += " | " + (i < plan.size() ? plan[i].name : "trajectory " + std::to_string(i));
    line += Format(" tip->entry %.1fmm", s.guidance->tip_to_entry_mm);
    line += Format(" angle %.1fdeg", s.guidance->angle_to_axis_rad * 180.0 / std::numbers::pi);
    line += Format(" depth %.1fmm", s.guidance->remaining_depth_mm);
  } else if (s.instrument_status) {
    line += std::string(" tool=") + ToString(*s.instrument_status);
  }
  return line;
}

}  // namespace tofnav
