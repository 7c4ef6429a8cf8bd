// SPDX-License-Identifier: BSD-3-Clause
// Tool poses files of `tofnav track` (CSV or JSON, docs/tracking.md section 3): write and read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/tracking/tool_pose.hpp"

namespace tofnav {

/// One tool in one frame. Poses are present only when measured in that frame.
struct ToolPoseRecord {
  std::int64_t frame = 0;        // index in the recording
  std::uint64_t host_ticks = 0;  // frame timestamp (100 ns), as in the recording
  double time_s = 0.0;           // host_ticks * 1e-7
  std::string tool;              // tool name
  ToolStatus status = ToolStatus::kOutOfView;
  int markers_used = 0;  // tool markers matched to detections
  int marker_count = 0;  // markers of the tool
  double fre_mm = 0.0;   // RMS fit error of the raw pose (0 without a pose)
  bool gated = false;    // the pose filter rejected the raw pose as an outlier
  /// Per-axis sds of the raw pose under the tracker's noise model (0 without one; JSON only).
  double rotation_sd_deg = 0.0;
  double position_sd_mm = 0.0;
  /// The filtered orientation's expected RMS angle error (TrackedTool::filtered_rotation_sd_rad;
  /// 0 without one; JSON only).
  double filtered_rotation_sd_deg = 0.0;
  std::optional<Rigid3d> ahat_from_tool;           // raw measured pose
  std::optional<Rigid3d> filtered_ahat_from_tool;  // pose filter output (filter on, not gated)
  /// world_from_rig * rig_from_ahat * (filtered, else raw) ahat_from_tool, when the frame has a
  /// rig pose.
  std::optional<Rigid3d> world_from_tool;
  /// The pose to use downstream: filtered when present, else raw.
  const std::optional<Rigid3d>& best_ahat_from_tool() const {
    return filtered_ahat_from_tool ? filtered_ahat_from_tool : ahat_from_tool;
  }
};

/// Parses a ToolStatus name as ToString writes it ("ok", "partially_occluded", ...).
std::optional<ToolStatus> ParseToolStatus(std::string_view name);

/// CSV: a header line, then one row per record (columns in docs/tracking.md; empty cells for
/// absent poses). Numbers are written with round-trip precision.
std::string EncodeToolPosesCsv(std::span<const ToolPoseRecord> records);
/// JSON: {"format": "tofnav-tool-poses", "version": 1, "records": [{...}, ...]}.
std::string EncodeToolPosesJson(std::span<const ToolPoseRecord> records);

/// Decodes either encoding (JSON when the first non-blank byte is '{'). Throws IoError naming
/// `path`, the byte offset and what was expected on malformed input (unknown column, bad number,
/// non-unit quaternion, unknown status, missing field).
std::vector<ToolPoseRecord> DecodeToolPoses(std::string_view text,
                                            const std::filesystem::path& path = "<poses>");

/// Reads a poses file (either encoding).
std::vector<ToolPoseRecord> ReadToolPoses(const std::filesystem::path& path);
/// Writes JSON when `path` ends in .json, else CSV; atomically.
void WriteToolPoses(const std::filesystem::path& path, std::span<const ToolPoseRecord> records);

}  // namespace tofnav
