// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate suite: the suite file (docs/suite.md), parsed with the JSON path of every
// error and no unknown key accepted.
#include <set>
#include <string>

#include "tofnav/evaluation/suite_case.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/json_bytes.hpp"
#include "tofnav/scenario/scenario_json_internal.hpp"

namespace tofnav {
namespace {

using internal::Fail;
using internal::Json;
using internal::JsonFields;
using internal::ReadEnum;

constexpr std::pair<const char*, sim::ReferenceTools> kTools[] = {
    {"as_built", sim::ReferenceTools::kAsBuilt},
    {"spheres", sim::ReferenceTools::kSpheres},
    {"single", sim::ReferenceTools::kSingleTool}};
constexpr std::pair<const char*, sim::Surroundings> kSurroundings[] = {
    {"as_built", sim::Surroundings::kAsBuilt},
    {"pillow", sim::Surroundings::kPillow},
    {"bare", sim::Surroundings::kBare}};

// Keys of a case; the suite's "defaults" object uses the same ones (except "name").
void ReadCase(JsonFields& in, SuiteCase& c) {
  in.Read("head", c.head);
  in.Read("head_mirror", c.head_mirror);
  in.Read("head_scale", c.head_scale);
  in.Read("seed", c.seed);
  in.Read("device", c.device);
  in.Read("multipath_gain", c.multipath_gain);
  in.Read("multipath_stride_px", c.multipath_stride_px);
  in.Read("noise_floor_exponent", c.noise_floor_exponent);
  sim::ScenarioVariation& v = c.variation;
  v.tools = ReadEnum(in, "tools", v.tools, kTools);
  v.surroundings = ReadEnum(in, "surroundings", v.surroundings, kSurroundings);
  in.Read("occluders", v.occluders);
  in.Read("head_drift_mm_per_s", v.head_drift_mm_per_s);
  in.Read("drop_probability", v.drop_probability);
  in.Read("mean_drop_slots", v.mean_drop_slots);
  in.Read("no_hand_rate_hz", v.no_hand_rate_hz);
  in.Read("slam_translation_sigma_mm", v.slam_translation_sigma_mm);
  in.Read("slam_rotation_sigma_rad", v.slam_rotation_sigma_rad);
  in.Read("skin_albedo", v.skin_albedo);
  in.Read("headset_min_range_mm", v.headset_min_range_mm);
  in.Read("headset_max_range_mm", v.headset_max_range_mm);
}

// The suite's own checks beyond the schema: names, derived heads, devices, the variation.
void CheckCase(const SuiteCase& c, const std::string& at, std::set<std::string>& names) {
  if (c.name.empty() ||
      c.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos) {
    Fail(at + ".name", "a case needs a name of [a-z0-9_-] (it names its folder)");
  }
  if (!names.insert(c.name).second) Fail(at + ".name", "'" + c.name + "' twice");
  if ((c.head_mirror || c.head_scale != 1.0) && !c.head.starts_with("ct:")) {
    Fail(at + ".head", "head_mirror and head_scale derive a head from a volume (ct:<path>)");
  }
  if (!(c.head_scale > 0.5 && c.head_scale < 2.0)) Fail(at + ".head_scale", "must lie in (0.5, 2)");
  if (c.multipath_stride_px < 0 || c.multipath_stride_px > 128) {
    Fail(at + ".multipath_stride_px", "must lie in [1, 128] px (0: the simulator's default)");
  }
  if (!(c.noise_floor_exponent <= 4.0)) {
    Fail(at + ".noise_floor_exponent", "must be <= 4 (< 0: the simulator's default)");
  }
  if (c.device != "synthetic" && !c.device.starts_with("perturbed:") &&
      !c.device.starts_with("folder:")) {
    Fail(at + ".device", "expected synthetic, perturbed:<n> or folder:<path>");
  }
  try {
    c.variation.Check();
  } catch (const std::exception& e) {
    Fail(at, e.what());
  }
}

SuiteFile ParseSuite(const Json& json) {
  JsonFields top(json, "$");
  SuiteFile suite;
  std::string format;
  top.Read("format", format);
  if (format != "tofnav-suite") Fail("$.format", "expected \"tofnav-suite\"");
  top.Read("name", suite.name);
  top.Read("frames_scale", suite.frames_scale);
  if (!(suite.frames_scale >= 0.05 && suite.frames_scale <= 20.0)) {
    Fail("$.frames_scale", "must lie in [0.05, 20]");
  }
  std::string stage = "per_device";
  top.Read("stage", stage);
  if (stage != "per_device" && stage != "per_case") {
    Fail("$.stage", "expected \"per_device\" or \"per_case\"");
  }
  suite.stage_per_device = stage == "per_device";
  SuiteCase defaults;
  if (const Json* d = top.Find("defaults")) {
    JsonFields in(*d, "$.defaults");
    ReadCase(in, defaults);
    in.Finish();
  }
  const Json* cases = top.Find("cases");
  top.Finish();
  if (cases == nullptr || !cases->is_array() || cases->empty()) {
    Fail("$.cases", "expected a non-empty array");
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < cases->size(); ++i) {
    const std::string at = "$.cases[" + std::to_string(i) + "]";
    JsonFields in((*cases)[i], at);
    SuiteCase c = defaults;
    in.Read("name", c.name);
    ReadCase(in, c);
    in.Finish();
    CheckCase(c, at, names);
    suite.cases.push_back(std::move(c));
  }
  return suite;
}

}  // namespace

SuiteFile ReadSuiteFile(const std::filesystem::path& path) {
  const Json json = ParseJsonBytes<Json>(ReadFileBytes(path), path);  // offset of bad JSON
  try {
    return ParseSuite(json);
  } catch (const internal::SchemaError& e) {
    throw IoError(path, std::nullopt, e.what());
  }
}

}  // namespace tofnav
