// SPDX-License-Identifier: BSD-3-Clause
// f_rf curve files (`tofnav fit-marker-error` output, docs/tracking.md section 4): write and read.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/marker_range_model.hpp"

namespace tofnav {

/// Fit facts stored beside the curve (informative; the reader returns them but evaluation
/// ignores them).
struct MarkerRangeFitInfo {
  int samples = 0;                // (range, error) samples fitted
  int frames = 0;                 // stage frames that gave samples
  double rms_residual_mm = 0.0;   // of the samples about the curve
  double effective_dof = 0.0;     // trace of the spline's influence matrix
  std::string smoothing = "gcv";  // "gcv" or "given"
};

/// The sensor's cyclic error measured on the stage's plate beside the tape (docs/correction.md
/// 2.8): a property of the device, which `identify` holds when the file carries it.
struct StageCyclicErrorInfo {
  CyclicRangeError cyclic;
  double amplitude_sd_mm = 0.0;
  double phase_sd_rad = 0.0;
  int plate_samples = 0;
  double span_mm = 0.0;  // of the plate's ranges
};

struct MarkerRangeFile {
  MarkerRangeModel model;
  MarkerRangeFitInfo fit;
  std::optional<StageCyclicErrorInfo> cyclic_error;  // absent unless measured
};

/// The "cyclic_error" object of frf.json (EncodeMarkerRangeJson), as the fit's reports print it.
nlohmann::ordered_json StageCyclicErrorToJson(const StageCyclicErrorInfo& info);

/// JSON: {"format": "tofnav-marker-range-error", "version": 1, "range_unit": "mm",
/// "smoothing_p": p, "knots_mm": [...], "bias_mm": [...], "second_derivative_per_mm": [...],
/// "fit": {...}, optionally "cyclic_error": {"amplitude_mm", "period_mm", "phase_rad",
/// "amplitude_sd_mm", "phase_sd_rad", "plate_samples", "span_mm"}}. f_rf(d) is the natural cubic
/// spline through (knots_mm, bias_mm) with those second derivatives, linear outside the knots;
/// correction (Eq. 2) is d' = d - f_rf(d).
std::string EncodeMarkerRangeJson(const MarkerRangeFile& file);
/// Throws IoError (path, byte offset for syntax errors) on malformed JSON, a wrong format tag,
/// missing or non-finite values, sizes that differ, knots not strictly increasing, more than
/// 100000 knots, or second derivatives not 0 at the ends.
MarkerRangeFile DecodeMarkerRangeJson(std::string_view text,
                                      const std::filesystem::path& path = "<f_rf>");

MarkerRangeFile ReadMarkerRangeJson(const std::filesystem::path& path);
/// Writes atomically.
void WriteMarkerRangeJson(const std::filesystem::path& path, const MarkerRangeFile& file);

}  // namespace tofnav
