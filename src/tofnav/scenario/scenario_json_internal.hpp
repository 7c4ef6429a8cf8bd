// SPDX-License-Identifier: BSD-3-Clause
// Internal to scenario_json*.cpp, truth_json.cpp and the suite file reader (apps/cli): strict
// JSON field reading and the encoders that share their key names.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/sim/head_phantom.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav::internal {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

/// A scenario document that breaks the schema; the message starts with the JSON path.
class SchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads one JSON object strictly: missing keys keep their defaults, wrong types are errors, and
/// Finish() rejects every key that was never read (a typo must not fall back silently).
class JsonFields {
 public:
  JsonFields(const Json& json, std::string where);
  std::string At(const std::string& key) const { return where_ + "." + key; }
  /// The value of `key`, marked as read; nullptr when absent.
  const Json* Find(const std::string& key);
  /// The value of `key`; SchemaError when absent.
  const Json& Get(const std::string& key);
  void Read(const std::string& key, double& value);
  void Read(const std::string& key, int& value);
  void Read(const std::string& key, std::int64_t& value);
  void Read(const std::string& key, std::uint64_t& value);
  void Read(const std::string& key, bool& value);
  void Read(const std::string& key, std::string& value);
  void Read(const std::string& key, Eigen::Vector3d& value);
  void Read(const std::string& key, Eigen::Vector2d& value);
  void Finish() const;

 private:
  const Json& json_;
  std::string where_;
  std::set<std::string> read_;
};

[[noreturn]] void Fail(const std::string& where, const std::string& message);
double NumberAt(const Json& json, const std::string& where);
Eigen::Vector3d Vector3At(const Json& json, const std::string& where);
const Json& ArrayAt(const Json& json, const std::string& where);

// Field tables: one per struct, shared by the parser and the encoder.
template <typename T>
struct Field {
  const char* key;
  double T::*member;
};

template <typename T, std::size_t N>
void ReadFields(JsonFields& in, T& out, const Field<T> (&fields)[N]) {
  for (const Field<T>& f : fields) in.Read(f.key, out.*(f.member));
}

template <typename T, std::size_t N>
void WriteFields(OrderedJson& out, const T& in, const Field<T> (&fields)[N]) {
  for (const Field<T>& f : fields) out[f.key] = in.*(f.member);
}

// Enums by name.
template <typename E, std::size_t N>
E ReadEnum(JsonFields& in, const std::string& key, E value,
           const std::pair<const char*, E> (&names)[N]) {
  std::string text;
  in.Read(key, text);
  if (text.empty()) return value;
  std::string known;
  for (const auto& [name, e] : names) {
    if (text == name) return e;
    known += (known.empty() ? "" : ", ") + std::string(name);
  }
  Fail(in.At(key), "unknown value '" + text + "' (" + known + ")");
}

template <typename E, std::size_t N>
const char* EnumName(E value, const std::pair<const char*, E> (&names)[N]) {
  for (const auto& [name, e] : names) {
    if (e == value) return name;
  }
  return "?";
}

// Runs a struct's Check() and reports its message at `where`.
inline void Checked(const std::string& where, const std::function<void()>& check) {
  try {
    check();
  } catch (const std::invalid_argument& e) {
    Fail(where, e.what());
  }
}

// Parsers of the schema's parts (docs/simulator.md). `base` resolves relative file paths.
Rigid3d ParsePose(const Json& json, const std::string& where);
sim::Motion ParseMotion(const Json& json, const std::string& where);
/// A material by preset name ("skin", "nylon", "photopolymer", "pla", "pc_abs",
/// "retro_reflective", "diffuse", "drape"), or nullopt.
std::optional<sim::Material> MaterialPreset(const std::string& name);
sim::Material ParseMaterial(const Json& json, const std::string& where);
sim::RenderOptions ParseRender(const Json& json, const std::string& where);
void ParseCamera(const Json& json, const std::string& where, const std::filesystem::path& base,
                 sim::CameraSetup& camera);
sim::FrameTimingOptions ParseTiming(const Json& json, const std::string& where);
sim::SyntheticCtOptions ParseCtOptions(const Json& json, const std::string& where);
sim::EvdPlanOptions ParsePlanOptions(const Json& json, const std::string& where);
sim::HeadPhantomOptions ParsePhantomOptions(JsonFields& fields);
TriangleMesh ParseShape(const Json& json, const std::string& where,
                        const std::filesystem::path& base);

// Encoders with the same key names (truth.json).
OrderedJson MatrixJson(const Rigid3d& b_from_a);
OrderedJson MaterialJson(const sim::Material& material);
OrderedJson RenderJson(const sim::RenderOptions& options);
/// The camera's calibration as the schema writes it: the synthetic model's keys, or the folder.
OrderedJson CalibrationJson(const sim::CameraSetup& camera);

}  // namespace tofnav::internal
