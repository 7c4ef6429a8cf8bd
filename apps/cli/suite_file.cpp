// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate suite: the suite file (docs/suite.md), parsed with the JSON path of every
// error and no unknown key accepted.
#include <set>
#include <string>

#include "suite_case.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/json_bytes.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;

class Fields {
 public:
  Fields(const std::filesystem::path& file, const Json& json, std::string where)
      : file_(file), json_(json), where_(std::move(where)) {
    if (!json.is_object()) Fail(where_, "expected an object");
  }
  [[noreturn]] void Fail(const std::string& at, const std::string& what) const {
    throw IoError(file_, std::nullopt, at + ": " + what);
  }
  template <typename T>
  void Read(const char* key, T& value) {
    const auto it = json_.find(key);
    if (it == json_.end()) return;
    read_.insert(key);
    try {
      value = it->get<T>();
    } catch (const Json::exception&) {
      Fail(where_ + "." + key, "wrong type");
    }
  }
  template <typename Enum, std::size_t N>
  void ReadEnum(const char* key, Enum& value, const std::pair<const char*, Enum> (&names)[N]) {
    std::string name;
    Read(key, name);
    if (name.empty()) return;
    std::string expected;
    for (const auto& [n, v] : names) {
      if (name == n) {
        value = v;
        return;
      }
      expected += std::string(expected.empty() ? "" : ", ") + n;
    }
    Fail(where_ + "." + key, "unknown value '" + name + "' (expected " + expected + ")");
  }
  void Finish() const {
    for (const auto& [key, value] : json_.items()) {
      if (!read_.count(key)) Fail(where_ + "." + key, "unknown key");
    }
  }

 private:
  const std::filesystem::path& file_;
  const Json& json_;
  std::string where_;
  std::set<std::string> read_;
};

constexpr std::pair<const char*, sim::ReferenceTools> kTools[] = {
    {"as_built", sim::ReferenceTools::kAsBuilt},
    {"spheres", sim::ReferenceTools::kSpheres},
    {"single", sim::ReferenceTools::kSingleTool}};
constexpr std::pair<const char*, sim::Surroundings> kSurroundings[] = {
    {"as_built", sim::Surroundings::kAsBuilt},
    {"pillow", sim::Surroundings::kPillow},
    {"bare", sim::Surroundings::kBare}};

// Keys of a case; the suite's "defaults" object uses the same ones (except "name").
void ReadCase(Fields& in, SuiteCase& c) {
  in.Read("head", c.head);
  in.Read("head_mirror", c.head_mirror);
  in.Read("head_scale", c.head_scale);
  in.Read("seed", c.seed);
  in.Read("device", c.device);
  in.Read("multipath_gain", c.multipath_gain);
  sim::ScenarioVariation& v = c.variation;
  in.ReadEnum("tools", v.tools, kTools);
  in.ReadEnum("surroundings", v.surroundings, kSurroundings);
  in.Read("occluders", v.occluders);
  in.Read("head_drift_mm_per_s", v.head_drift_mm_per_s);
  in.Read("drop_probability", v.drop_probability);
  in.Read("mean_drop_slots", v.mean_drop_slots);
  in.Read("slam_translation_sigma_mm", v.slam_translation_sigma_mm);
  in.Read("slam_rotation_sigma_rad", v.slam_rotation_sigma_rad);
}

}  // namespace

SuiteFile ReadSuiteFile(const std::filesystem::path& path) {
  const Json json = ParseJsonBytes<Json>(ReadFileBytes(path), path);  // offset of bad JSON
  Fields top(path, json, "$");
  SuiteFile suite;
  std::string format;
  top.Read("format", format);
  if (format != "tofnav-suite") top.Fail("$.format", "expected \"tofnav-suite\"");
  top.Read("name", suite.name);
  top.Read("frames_scale", suite.frames_scale);
  if (!(suite.frames_scale >= 0.05 && suite.frames_scale <= 20.0)) {
    top.Fail("$.frames_scale", "must lie in [0.05, 20]");
  }
  SuiteCase defaults;
  Json defaults_json = Json::object(), cases = Json::array();
  top.Read("defaults", defaults_json);
  top.Read("cases", cases);
  top.Finish();
  Fields d(path, defaults_json, "$.defaults");
  ReadCase(d, defaults);
  d.Finish();
  if (!cases.is_array() || cases.empty()) top.Fail("$.cases", "expected a non-empty array");
  std::set<std::string> names;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string at = "$.cases[" + std::to_string(i) + "]";
    Fields in(path, cases[i], at);
    SuiteCase c = defaults;
    in.Read("name", c.name);
    ReadCase(in, c);
    in.Finish();
    if (c.name.empty() ||
        c.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos) {
      in.Fail(at + ".name", "a case needs a name of [a-z0-9_-] (it names its folder)");
    }
    if (!names.insert(c.name).second) in.Fail(at + ".name", "'" + c.name + "' twice");
    if ((c.head_mirror || c.head_scale != 1.0) && !c.head.starts_with("ct:")) {
      in.Fail(at + ".head", "head_mirror and head_scale derive a head from a volume (ct:<path>)");
    }
    if (!(c.head_scale > 0.5 && c.head_scale < 2.0))
      in.Fail(at + ".head_scale", "must lie in (0.5, 2)");
    if (c.device != "synthetic" && !c.device.starts_with("perturbed:") &&
        !c.device.starts_with("folder:")) {
      in.Fail(at + ".device", "expected synthetic, perturbed:<n> or folder:<path>");
    }
    try {
      c.variation.Check();
    } catch (const std::exception& e) {
      in.Fail(at, e.what());
    }
    suite.cases.push_back(std::move(c));
  }
  return suite;
}

}  // namespace tofnav
