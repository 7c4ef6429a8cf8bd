// SPDX-License-Identifier: BSD-3-Clause
// Tool definition files: our JSON (docs/tracking.md 2) and NDI .rom marker import (section 8).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

/// Parses a tool JSON document:
///   {"name": "HeadRef", "markers": [[x, y, z], ...] (mm, tool frame),
///    "marker_type": "sphere" | "flat", "marker_diameter_mm": 11.5,
///    "min_visible": 3, "max_fre_mm": 1.0, "tip_mm": [x, y, z]}
/// name and markers are required; "disc" is accepted for "flat" and "marker_diameter" and "tip"
/// without the unit suffix; unknown keys are ignored. Throws IoError (path, byte offset for
/// syntax errors) on malformed JSON, wrong types, or a tool failing ToolGeometry::Check().
ToolGeometry DecodeToolJson(std::string_view text, const std::filesystem::path& path = "<tool>");
/// The JSON of `tool` (pretty-printed, the keys above).
std::string EncodeToolJson(const ToolGeometry& tool);

ToolGeometry ReadToolJson(const std::filesystem::path& path);
/// Writes atomically (temporary name, then rename).
void WriteToolJson(const std::filesystem::path& path, const ToolGeometry& tool);

/// NDI SROM (.rom): only the marker count (uint8 at byte 28) and the marker positions
/// (little-endian float32 x, y, z in mm from byte 72) are read (docs/tracking.md section 8; the
/// rest of the layout is unverified). Markers are taken as `diameter_mm` spheres; name = file stem.
/// Throws IoError when the file is short, or the tool fails ToolGeometry::Check().
ToolGeometry DecodeNdiRom(std::span<const std::uint8_t> bytes, const std::filesystem::path& path,
                          double diameter_mm = 11.5);
ToolGeometry ReadNdiRom(const std::filesystem::path& path, double diameter_mm = 11.5);

/// A tool file: NDI .rom (by extension, any case) or tool JSON.
ToolGeometry ReadToolFile(const std::filesystem::path& path);

}  // namespace tofnav
