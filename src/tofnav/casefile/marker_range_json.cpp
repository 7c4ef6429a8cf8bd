// SPDX-License-Identifier: BSD-3-Clause
// f_rf curve JSON: the csaps spline of Eq. (1) by its knots (docs/tracking.md section 4).
#include "tofnav/casefile/marker_range_json.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/casefile/json_number.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/json_bytes.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;

constexpr const char* kFormat = "tofnav-marker-range-error";

std::vector<double> Numbers(const OrderedJson& json, const char* key,
                            const std::filesystem::path& path) {
  const auto it = json.find(key);
  if (it == json.end() || !it->is_array()) {
    throw IoError(path, std::nullopt, std::string("expected \"") + key + "\": [numbers]");
  }
  if (it->size() > kMaxJsonKnots) {
    throw IoError(path, std::nullopt, std::string("\"") + key + "\" has more than 100000 values");
  }
  std::vector<double> out;
  for (const OrderedJson& v : *it) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      throw IoError(path, std::nullopt, std::string("\"") + key + "\" must hold finite numbers");
    }
    out.push_back(v.get<double>());
  }
  return out;
}

double NumberOr(const OrderedJson& json, const char* key, double fallback,
                const std::filesystem::path& path) {
  const auto it = json.find(key);
  if (it == json.end()) return fallback;
  if (!it->is_number() || !std::isfinite(it->get<double>())) {
    throw IoError(path, std::nullopt, std::string("\"") + key + "\" must be a finite number");
  }
  return it->get<double>();
}

}  // namespace

OrderedJson StageCyclicErrorToJson(const StageCyclicErrorInfo& info) {
  OrderedJson j = CyclicErrorToJson(info.cyclic);
  j["amplitude_sd_mm"] = info.amplitude_sd_mm;
  j["phase_sd_rad"] = info.phase_sd_rad;
  j["plate_samples"] = info.plate_samples;
  j["span_mm"] = info.span_mm;
  j["source"] = "the stage's plate beside the tape (docs/correction.md 2.8)";
  return j;
}

std::string EncodeMarkerRangeJson(const MarkerRangeFile& file) {
  const CubicSpline& s = file.model.bias_mm;
  OrderedJson json{{"format", kFormat},
                   {"version", 1},
                   {"range_unit", "mm"},
                   {"description",
                    "f_rf(d): retro-reflector range error [mm] at measured surface range d [mm], a "
                    "natural cubic spline, linear outside the knots; corrected range d - f_rf(d)"},
                   {"smoothing_p", file.model.smoothing_p},
                   {"knots_mm", s.x},
                   {"bias_mm", s.value},
                   {"second_derivative_per_mm", s.second_derivative},
                   {"entrance_gain_mm_per_rad", file.model.entrance_gain_mm_per_rad},
                   {"fit",
                    {{"samples", file.fit.samples},
                     {"frames", file.fit.frames},
                     {"rms_residual_mm", file.fit.rms_residual_mm},
                     {"effective_dof", file.fit.effective_dof},
                     {"smoothing", file.fit.smoothing}}}};
  if (file.cyclic_error) json["cyclic_error"] = StageCyclicErrorToJson(*file.cyclic_error);
  return json.dump(2) + "\n";
}

MarkerRangeFile DecodeMarkerRangeJson(std::string_view text, const std::filesystem::path& path) {
  const OrderedJson json = ParseJsonText<OrderedJson>(text, path);
  if (!json.is_object() || json.value("format", OrderedJson()) != kFormat) {
    throw IoError(path, std::nullopt, std::string("expected {\"format\": \"") + kFormat + "\"}");
  }
  if (json.value("range_unit", OrderedJson("mm")) != "mm") {
    throw IoError(path, std::nullopt, "\"range_unit\" must be \"mm\"");
  }
  MarkerRangeFile file;
  CubicSpline& s = file.model.bias_mm;
  s.x = Numbers(json, "knots_mm", path);
  s.value = Numbers(json, "bias_mm", path);
  s.second_derivative = Numbers(json, "second_derivative_per_mm", path);
  if (s.value.size() != s.x.size() || s.second_derivative.size() != s.x.size()) {
    throw IoError(path, std::nullopt,
                  "knots_mm, bias_mm and second_derivative_per_mm must have equal lengths");
  }
  for (std::size_t i = 1; i < s.x.size(); ++i) {
    if (!(s.x[i] > s.x[i - 1])) {
      throw IoError(path, std::nullopt, "knots_mm must be strictly increasing");
    }
  }
  if (!s.x.empty() && (s.second_derivative.front() != 0.0 || s.second_derivative.back() != 0.0)) {
    throw IoError(path, std::nullopt, "a natural spline has second derivative 0 at both ends");
  }
  file.model.smoothing_p = NumberOr(json, "smoothing_p", 1.0, path);
  // Absent in files written before it (range only, Eq. 1): 0.
  file.model.entrance_gain_mm_per_rad = NumberOr(json, "entrance_gain_mm_per_rad", 0.0, path);
  if (const auto fit = json.find("fit"); fit != json.end() && fit->is_object()) {
    file.fit.samples = static_cast<int>(std::clamp(NumberOr(*fit, "samples", 0, path), 0.0, 1e9));
    file.fit.frames = static_cast<int>(std::clamp(NumberOr(*fit, "frames", 0, path), 0.0, 1e9));
    file.fit.rms_residual_mm = NumberOr(*fit, "rms_residual_mm", 0.0, path);
    file.fit.effective_dof = NumberOr(*fit, "effective_dof", 0.0, path);
    if (const auto m = fit->find("smoothing"); m != fit->end() && m->is_string()) {
      file.fit.smoothing = m->get<std::string>();
    }
  }
  if (const auto c = json.find("cyclic_error"); c != json.end() && !c->is_null()) {
    StageCyclicErrorInfo info;
    info.cyclic = CyclicErrorFromJson(*c, path, "cyclic_error");
    info.amplitude_sd_mm = NumberOr(*c, "amplitude_sd_mm", 0.0, path);
    info.phase_sd_rad = NumberOr(*c, "phase_sd_rad", 0.0, path);
    info.plate_samples =
        static_cast<int>(std::clamp(NumberOr(*c, "plate_samples", 0, path), 0.0, 1e9));
    info.span_mm = NumberOr(*c, "span_mm", 0.0, path);
    file.cyclic_error = info;
  }
  return file;
}

MarkerRangeFile ReadMarkerRangeJson(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  return DecodeMarkerRangeJson({reinterpret_cast<const char*>(bytes.data()), bytes.size()}, path);
}

void WriteMarkerRangeJson(const std::filesystem::path& path, const MarkerRangeFile& file) {
  WriteFileAtomically(path, EncodeMarkerRangeJson(file));
}

}  // namespace tofnav
