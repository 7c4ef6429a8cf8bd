// SPDX-License-Identifier: BSD-3-Clause
// depth_model.json (the identified surface depth model, docs/correction.md) and f_rf JSON.
#pragma once

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/marker_range_model.hpp"

namespace tofnav {

/// What depth_model.json holds: the surface model with its fit report, and optionally the
/// f_rf (Eq. 1) the identification used for marker pixels.
struct DepthModelFile {
  DepthErrorModel model;
  std::optional<MarkerRangeModel> marker_range;
};

/// Parses depth_model.json ({"format": "tofnav-depth-model", "version": 1, "model": {...},
/// "marker_range": {...}?, "fit": {...}?}; docs/correction.md). Throws IoError (path, byte offset
/// for syntax errors) on malformed JSON, missing or mistyped keys, or a model failing Check().
/// The fit report is optional and read leniently (unknown keys ignored).
DepthModelFile DecodeDepthModelJson(std::string_view text,
                                    const std::filesystem::path& path = "<depth model>");
/// `options`: the settings that produced the model (the CLI's effective options), written as
/// "options" and ignored by the reader.
std::string EncodeDepthModelJson(const DepthModelFile& file,
                                 const nlohmann::ordered_json* options = nullptr);
DepthModelFile ReadDepthModelJson(const std::filesystem::path& path);
void WriteDepthModelJson(const std::filesystem::path& path, const DepthModelFile& file,
                         const nlohmann::ordered_json* options = nullptr);

/// The sensor's cyclic error as every report writes it: {"amplitude_mm", "period_mm",
/// "phase_rad"} (docs/correction.md 2.2).
nlohmann::ordered_json CyclicErrorToJson(const CyclicRangeError& cyclic);
/// The inverse, `at` naming the object in errors: IoError on a missing or non-finite member or
/// an invalid error (CyclicRangeError::Check).
CyclicRangeError CyclicErrorFromJson(const nlohmann::ordered_json& json,
                                     const std::filesystem::path& path, const std::string& at);

/// What the identification left out (frames, foreground points, marker observations and each
/// sticker's counts), as depth_model.json's "fit" and `tofnav identify --json` write it.
nlohmann::ordered_json LeftOutToJson(const DepthModelFitReport& report);

}  // namespace tofnav
