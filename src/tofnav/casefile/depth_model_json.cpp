// SPDX-License-Identifier: BSD-3-Clause
// depth_model.json (the identified surface depth model, docs/correction.md) and f_rf JSON.
#include "tofnav/casefile/depth_model_json.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <type_traits>

#include "tofnav/casefile/json_number.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/json_bytes.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;
using Path = std::filesystem::path;

constexpr const char* kModelFormat = "tofnav-depth-model";
constexpr const char* kRangeFormat = "tofnav-marker-range";

const OrderedJson& Member(const OrderedJson& object, const char* key, const Path& path,
                          const std::string& at) {
  if (!object.is_object()) throw IoError(path, std::nullopt, at + " must be an object");
  const auto it = object.find(key);
  if (it == object.end()) throw IoError(path, std::nullopt, at + ": missing \"" + key + "\"");
  return *it;
}

std::string String(const OrderedJson& value, const Path& path, const std::string& what) {
  if (!value.is_string()) throw IoError(path, std::nullopt, what + " must be a string");
  return value.get<std::string>();
}

void CheckHeader(const OrderedJson& json, const char* format, const Path& path) {
  if (!json.is_object()) throw IoError(path, std::nullopt, "expected a JSON object");
  if (String(Member(json, "format", path, "$"), path, "format") != format) {
    throw IoError(path, std::nullopt, std::string("format must be \"") + format + "\"");
  }
  const OrderedJson& version = Member(json, "version", path, "$");
  if (!version.is_number_integer() || version.get<std::int64_t>() != 1) {
    throw IoError(path, std::nullopt, "unsupported version (expected 1)");
  }
}

std::vector<double> Numbers(const OrderedJson& value, const Path& path, const std::string& what) {
  if (!value.is_array() || value.size() > kMaxJsonKnots) {
    throw IoError(path, std::nullopt, what + " must be an array of numbers");
  }
  std::vector<double> out;
  out.reserve(value.size());
  for (const OrderedJson& x : value) out.push_back(FiniteJsonNumber(x, path, what));
  return out;
}

OrderedJson RangeToJson(const MarkerRangeModel& model) {
  return OrderedJson{{"format", kRangeFormat},
                     {"version", 1},
                     {"range_unit", "mm"},
                     {"smoothing_p", model.smoothing_p},
                     {"knots_mm", model.bias_mm.x},
                     {"bias_mm", model.bias_mm.value},
                     {"second_derivative_per_mm", model.bias_mm.second_derivative},
                     {"entrance_gain_mm_per_rad", model.entrance_gain_mm_per_rad}};
}

MarkerRangeModel RangeFromJson(const OrderedJson& json, const Path& path) {
  CheckHeader(json, kRangeFormat, path);
  if (String(Member(json, "range_unit", path, "$"), path, "range_unit") != "mm") {
    throw IoError(path, std::nullopt, "range_unit must be \"mm\"");
  }
  MarkerRangeModel model;
  model.smoothing_p = FiniteJsonNumber(Member(json, "smoothing_p", path, "$"), path, "smoothing_p");
  model.bias_mm.x = Numbers(Member(json, "knots_mm", path, "$"), path, "knots_mm");
  model.bias_mm.value = Numbers(Member(json, "bias_mm", path, "$"), path, "bias_mm");
  model.bias_mm.second_derivative = Numbers(Member(json, "second_derivative_per_mm", path, "$"),
                                            path, "second_derivative_per_mm");
  // f_rf's entrance-angle term (docs/tracking.md 4); absent in files written before it: 0.
  if (const auto gain = json.find("entrance_gain_mm_per_rad"); gain != json.end()) {
    model.entrance_gain_mm_per_rad = FiniteJsonNumber(*gain, path, "entrance_gain_mm_per_rad");
  }
  try {
    model.Check();
  } catch (const std::invalid_argument& e) {
    throw IoError(path, std::nullopt, std::string("invalid marker range model: ") + e.what());
  }
  return model;
}

OrderedJson ReportToJson(const DepthModelFitReport& r) {
  OrderedJson frames = OrderedJson::array();
  for (const FrameResidual& f : r.frames) {
    frames.push_back({{"frame", f.frame},
                      {"err_c_mm", f.err_c_mm},
                      {"err_s_mm", f.err_s_mm},
                      {"markers", f.markers}});
  }
  OrderedJson cv = OrderedJson::array();
  for (const auto& [name, cost] : r.cross_validation) {
    cv.push_back({{"model", name}, {"held_out_err_s2_mm2", cost}});
  }
  OrderedJson out{{"method", r.method}, {"costs", r.costs}, {"frames_used", r.frames_used}};
  out.update(LeftOutToJson(r));
  out.update(OrderedJson{{"evaluations", r.evaluations},
                         {"initial_cost_mm2", r.initial_cost},
                         {"final_cost_mm2", r.final_cost},
                         {"seconds", r.seconds},
                         {"standard_errors", r.standard_errors},
                         {"cross_validation", cv},
                         {"frames", frames}});
  return out;
}

// Lenient: a report is informative, so absent or mistyped entries keep their defaults.
DepthModelFitReport ReportFromJson(const OrderedJson& json) {
  DepthModelFitReport r;
  if (!json.is_object()) return r;
  auto str = [&](const char* k, std::string& out) {
    if (json.contains(k) && json[k].is_string()) out = json[k].get<std::string>();
  };
  auto num = [&](const OrderedJson& j, const char* k, auto& out) {
    using T = std::remove_reference_t<decltype(out)>;
    if (!j.contains(k)) return;
    const OrderedJson& v = j[k];
    if constexpr (std::is_integral_v<T>) {
      if (v.is_number_integer()) {
        const std::int64_t x = v.get<std::int64_t>();  // unsigned beyond int64 wraps: still safe
        if (x >= std::numeric_limits<T>::min() && x <= std::numeric_limits<T>::max()) {
          out = static_cast<T>(x);
        }
      }
    } else if (v.is_number()) {
      out = v.get<double>();
    }
  };
  str("method", r.method);
  str("costs", r.costs);
  num(json, "frames_used", r.frames_used);
  num(json, "frames_left_out", r.frames_left_out);
  num(json, "head_points_left_out", r.head_points_left_out);
  num(json, "marker_patches_screened_out", r.marker_patches_screened_out);
  num(json, "marker_observations_curved", r.marker_observations_curved);
  num(json, "marker_observations", r.marker_observations);
  num(json, "markers_rejected", r.marker_observations_rejected);  // written before 2026-11-26
  num(json, "marker_observations_rejected", r.marker_observations_rejected);
  if (json.contains("markers") && json["markers"].is_array()) {
    for (const OrderedJson& m : json["markers"]) {
      StickerUse use;
      if (m.contains("centre_mm") && m["centre_mm"].is_array() && m["centre_mm"].size() == 3) {
        for (std::size_t i = 0; i < 3; ++i) {
          if (m["centre_mm"][i].is_number()) use.centre_mm[i] = m["centre_mm"][i].get<double>();
        }
      }
      num(m, "observations", use.observations);
      num(m, "rejected", use.rejected);
      r.markers.push_back(use);
    }
  }
  num(json, "evaluations", r.evaluations);
  num(json, "initial_cost_mm2", r.initial_cost);
  num(json, "final_cost_mm2", r.final_cost);
  num(json, "seconds", r.seconds);
  if (json.contains("standard_errors") && json["standard_errors"].is_array()) {
    for (const OrderedJson& x : json["standard_errors"]) {
      r.standard_errors.push_back(x.is_number() ? x.get<double>() : std::nan(""));
    }
  }
  if (json.contains("cross_validation") && json["cross_validation"].is_array()) {
    for (const OrderedJson& c : json["cross_validation"]) {
      if (!c.is_object() || !c.contains("model") || !c["model"].is_string()) continue;
      double cost = 0.0;
      num(c, "held_out_err_s2_mm2", cost);
      r.cross_validation.emplace_back(c["model"].get<std::string>(), cost);
    }
  }
  if (json.contains("frames") && json["frames"].is_array()) {
    for (const OrderedJson& f : json["frames"]) {
      if (!f.is_object()) continue;
      FrameResidual fr;
      num(f, "frame", fr.frame);
      num(f, "err_c_mm", fr.err_c_mm);
      num(f, "err_s_mm", fr.err_s_mm);
      num(f, "markers", fr.markers);
      r.frames.push_back(fr);
    }
  }
  return r;
}

// The multipath removal the model was identified with (absent in files written before it: off).
MultipathCorrectionOptions MultipathFromJson(const OrderedJson& j, const Path& path) {
  MultipathCorrectionOptions o;
  const std::string at = "model.multipath";
  const OrderedJson& enabled = Member(j, "enabled", path, at);
  if (!enabled.is_boolean()) throw IoError(path, std::nullopt, at + ".enabled: boolean");
  o.enabled = enabled.get<bool>();
  o.ab_scale = FiniteJsonNumber(Member(j, "ab_scale", path, at), path, at + ".ab_scale");
  o.falloff_power =
      FiniteJsonNumber(Member(j, "falloff_power", path, at), path, at + ".falloff_power");
  o.max_albedo = FiniteJsonNumber(Member(j, "max_albedo", path, at), path, at + ".max_albedo");
  const auto integer = [&](const char* key) {
    const double v = FiniteJsonNumber(Member(j, key, path, at), path, at + "." + key);
    if (v != std::floor(v) || std::abs(v) > 1e6) {
      throw IoError(path, std::nullopt, at + "." + key + ": an integer");
    }
    return static_cast<int>(v);
  };
  o.source_stride_px = integer("source_stride_px");
  o.receiver_stride_px = integer("receiver_stride_px");
  o.min_cos_incidence =
      FiniteJsonNumber(Member(j, "min_cos_incidence", path, at), path, at + ".min_cos_incidence");
  o.max_indirect_ratio =
      FiniteJsonNumber(Member(j, "max_indirect_ratio", path, at), path, at + ".max_indirect_ratio");
  o.passes = integer("passes");
  o.alias_mm = FiniteJsonNumber(Member(j, "alias_mm", path, at), path, at + ".alias_mm");
  o.damped = false;  // absent: written before it existed, identified undamped
  if (const auto it = j.find("damped"); it != j.end()) {
    if (!it->is_boolean()) throw IoError(path, std::nullopt, at + ".damped: boolean");
    o.damped = it->get<bool>();
  }
  o.skin_delay_mm = 0.0;  // absent: written before it existed, identified without the delay
  if (const auto it = j.find("skin_delay_mm"); it != j.end()) {
    o.skin_delay_mm = FiniteJsonNumber(*it, path, at + ".skin_delay_mm");
  }
  try {
    o.Check();
  } catch (const std::invalid_argument& e) {
    throw IoError(path, std::nullopt, at + ": " + e.what());
  }
  return o;
}

OrderedJson MultipathToJson(const MultipathCorrectionOptions& o) {
  return OrderedJson{{"enabled", o.enabled},
                     {"ab_scale", o.ab_scale},
                     {"falloff_power", o.falloff_power},
                     {"max_albedo", o.max_albedo},
                     {"source_stride_px", o.source_stride_px},
                     {"receiver_stride_px", o.receiver_stride_px},
                     {"min_cos_incidence", o.min_cos_incidence},
                     {"max_indirect_ratio", o.max_indirect_ratio},
                     {"passes", o.passes},
                     {"alias_mm", o.alias_mm},
                     {"damped", o.damped},
                     {"skin_delay_mm", o.skin_delay_mm},
                     {"units",
                      "ab_scale: AB counts m^2 (AB = K rho cos(theta) cos^p(off-axis) / d^2); "
                      "strides: px; alias_mm, skin_delay_mm: mm; docs/correction.md 7"}};
}

}  // namespace

double FiniteJsonNumber(const OrderedJson& value, const Path& path, const std::string& what) {
  if (!value.is_number()) throw IoError(path, std::nullopt, what + " must be a number");
  const double x = value.get<double>();
  if (!std::isfinite(x)) throw IoError(path, std::nullopt, what + " must be finite");
  return x;
}

DepthModelFile DecodeDepthModelJson(std::string_view text, const Path& path) {
  const OrderedJson json = ParseJsonText<OrderedJson>(text, path);
  CheckHeader(json, kModelFormat, path);
  const OrderedJson& m = Member(json, "model", path, "$");
  DepthModelFile file;
  DepthErrorModel& model = file.model;
  try {
    model.angle_term =
        ParseAngleTerm(String(Member(m, "angle_term", path, "model"), path, "model.angle_term"));
  } catch (const std::invalid_argument& e) {
    throw IoError(path, std::nullopt, std::string("model.angle_term: ") + e.what());
  }
  const OrderedJson& intensity = Member(m, "use_intensity", path, "model");
  if (!intensity.is_boolean()) throw IoError(path, std::nullopt, "model.use_intensity: boolean");
  model.use_intensity = intensity.get<bool>();
  if (const auto it = m.find("use_range_term"); it != m.end()) {  // absent: written before it
    if (!it->is_boolean()) throw IoError(path, std::nullopt, "model.use_range_term: boolean");
    model.use_range_term = it->get<bool>();
  }
  const OrderedJson& c = Member(m, "coefficients", path, "model");
  model.c1_mm = FiniteJsonNumber(Member(c, "c1_mm", path, "model.coefficients"), path, "c1_mm");
  model.c2 = FiniteJsonNumber(Member(c, "c2", path, "model.coefficients"), path, "c2");
  model.c3_mm = FiniteJsonNumber(Member(c, "c3_mm", path, "model.coefficients"), path, "c3_mm");
  model.c4_mm = FiniteJsonNumber(Member(c, "c4_mm", path, "model.coefficients"), path, "c4_mm");
  model.ab_reference =
      FiniteJsonNumber(Member(c, "ab_reference", path, "model.coefficients"), path, "ab_reference");
  if (const auto it = c.find("theta_reference_rad"); it != c.end()) {  // absent: written before it
    model.theta_reference_rad = FiniteJsonNumber(*it, path, "theta_reference_rad");
  }
  if (const auto it = m.find("cyclic_error"); it != m.end() && !it->is_null()) {
    model.cyclic = CyclicErrorFromJson(*it, path, "model.cyclic_error");  // absent: off
  }
  try {
    model.Check();
  } catch (const std::invalid_argument& e) {
    throw IoError(path, std::nullopt, std::string("invalid model: ") + e.what());
  }
  if (const auto it = m.find("multipath"); it != m.end() && !it->is_null()) {
    model.multipath = MultipathFromJson(*it, path);
  }
  if (const auto it = json.find("marker_range"); it != json.end() && !it->is_null()) {
    file.marker_range = RangeFromJson(*it, path);
  }
  if (const auto it = json.find("fit"); it != json.end()) model.report = ReportFromJson(*it);
  return file;
}

std::string EncodeDepthModelJson(const DepthModelFile& file, const OrderedJson* options) {
  const DepthErrorModel& m = file.model;
  OrderedJson json{{"format", kModelFormat}, {"version", 1}};
  json["model"] = {
      {"kind", m.Name()},
      {"equation",
       "measured - true range = C1 + C2 d + C3 (g(theta) - g(theta_ref)) + C4 ln(AB_ref / AB)"},
      {"angle_term", AngleTermName(m.angle_term)},
      {"use_intensity", m.use_intensity},
      {"use_range_term", m.use_range_term},
      {"coefficients",
       {{"c1_mm", m.c1_mm},
        {"c2", m.c2},
        {"c3_mm", m.c3_mm},
        {"c4_mm", m.c4_mm},
        {"ab_reference", m.ab_reference},
        {"theta_reference_rad", m.theta_reference_rad}}},
      {"units",
       {{"c1_mm", "mm"},
        {"c2", "mm per mm of true range"},
        {"c3_mm", std::string("mm per unit of g(theta) = ") +
                      std::string(AngleTermName(m.angle_term)) + ", theta in rad"},
        {"c4_mm", "mm per unit of ln(AB_ref / AB)"},
        {"ab_reference", "AB counts"},
        {"theta_reference_rad", "rad: g(theta) enters as g(theta) - g(theta_reference_rad)"}}}};
  json["model"]["multipath"] = MultipathToJson(m.multipath);
  json["model"]["cyclic_error"] = CyclicErrorToJson(m.cyclic);
  json["model"]["cyclic_error"]["equation"] =
      "w(d) = A sin(2 pi d / P + phi), removed from the measured range first";
  json["marker_range"] = file.marker_range ? RangeToJson(*file.marker_range) : OrderedJson();
  json["fit"] = ReportToJson(m.report);
  if (options != nullptr) json["options"] = *options;
  return json.dump(2) + "\n";
}

DepthModelFile ReadDepthModelJson(const Path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  return DecodeDepthModelJson(
      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), path);
}

void WriteDepthModelJson(const Path& path, const DepthModelFile& file, const OrderedJson* options) {
  WriteFileAtomically(path, EncodeDepthModelJson(file, options));
}

OrderedJson CyclicErrorToJson(const CyclicRangeError& cyclic) {
  return {{"amplitude_mm", cyclic.amplitude_mm},
          {"period_mm", cyclic.period_mm},
          {"phase_rad", cyclic.phase_rad}};
}

CyclicRangeError CyclicErrorFromJson(const OrderedJson& json, const Path& path,
                                     const std::string& at) {
  CyclicRangeError cyclic;
  cyclic.amplitude_mm =
      FiniteJsonNumber(Member(json, "amplitude_mm", path, at), path, at + ".amplitude_mm");
  cyclic.period_mm = FiniteJsonNumber(Member(json, "period_mm", path, at), path, at + ".period_mm");
  cyclic.phase_rad = FiniteJsonNumber(Member(json, "phase_rad", path, at), path, at + ".phase_rad");
  try {
    cyclic.Check();
  } catch (const std::invalid_argument& e) {
    throw IoError(path, std::nullopt, at + ": " + e.what());
  }
  return cyclic;
}

OrderedJson LeftOutToJson(const DepthModelFitReport& r) {
  OrderedJson markers = OrderedJson::array();
  for (const StickerUse& m : r.markers) {
    markers.push_back(
        {{"centre_mm", m.centre_mm}, {"observations", m.observations}, {"rejected", m.rejected}});
  }
  return OrderedJson{{"frames_left_out", r.frames_left_out},
                     {"head_points_left_out", r.head_points_left_out},
                     {"marker_patches_screened_out", r.marker_patches_screened_out},
                     {"marker_observations_curved", r.marker_observations_curved},
                     {"marker_observations", r.marker_observations},
                     {"marker_observations_rejected", r.marker_observations_rejected},
                     {"markers", markers}};
}

}  // namespace tofnav
