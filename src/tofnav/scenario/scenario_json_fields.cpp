// SPDX-License-Identifier: BSD-3-Clause
// Strict JSON field reading, poses and motions of the scenario schema.
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <utility>

#include "tofnav/core/rotation_vector.hpp"
#include "tofnav/scenario/scenario_json_internal.hpp"

namespace tofnav::internal {
namespace {

const char* TypeName(const Json& json) { return json.type_name(); }

Rigid3d RotationVectorPose(const Eigen::Vector3d& rotation_vector_rad,
                           const Eigen::Vector3d& translation_mm) {
  return {FromRotationVector(rotation_vector_rad), translation_mm};
}

}  // namespace

void Fail(const std::string& where, const std::string& message) {
  throw SchemaError(where + ": " + message);
}

double NumberAt(const Json& json, const std::string& where) {
  if (!json.is_number()) Fail(where, std::string("expected a number, found ") + TypeName(json));
  const double value = json.get<double>();
  if (!std::isfinite(value)) Fail(where, "expected a finite number");
  return value;
}

const Json& ArrayAt(const Json& json, const std::string& where) {
  if (!json.is_array()) Fail(where, std::string("expected an array, found ") + TypeName(json));
  return json;
}

Eigen::Vector3d Vector3At(const Json& json, const std::string& where) {
  if (!json.is_array() || json.size() != 3) Fail(where, "expected an array of 3 numbers");
  return {NumberAt(json[0], where + "[0]"), NumberAt(json[1], where + "[1]"),
          NumberAt(json[2], where + "[2]")};
}

JsonFields::JsonFields(const Json& json, std::string where)
    : json_(json), where_(std::move(where)) {
  if (!json_.is_object()) Fail(where_, std::string("expected an object, found ") + TypeName(json_));
}

const Json* JsonFields::Find(const std::string& key) {
  const auto it = json_.find(key);
  if (it == json_.end()) return nullptr;
  read_.insert(key);
  return &*it;
}

const Json& JsonFields::Get(const std::string& key) {
  const Json* value = Find(key);
  if (value == nullptr) Fail(At(key), "required key is missing");
  return *value;
}

void JsonFields::Read(const std::string& key, double& value) {
  if (const Json* j = Find(key)) value = NumberAt(*j, At(key));
}

void JsonFields::Read(const std::string& key, int& value) {
  std::int64_t wide = value;
  Read(key, wide);
  if (wide < std::numeric_limits<int>::min() || wide > std::numeric_limits<int>::max()) {
    Fail(At(key), "integer out of range");
  }
  value = static_cast<int>(wide);
}

void JsonFields::Read(const std::string& key, std::int64_t& value) {
  const Json* j = Find(key);
  if (j == nullptr) return;
  if (!j->is_number_integer()) Fail(At(key), "expected an integer");
  if (j->is_number_unsigned() && j->get<std::uint64_t>() > std::uint64_t{1} << 62) {
    Fail(At(key), "integer out of range");
  }
  value = j->get<std::int64_t>();
}

void JsonFields::Read(const std::string& key, std::uint64_t& value) {
  const Json* j = Find(key);
  if (j == nullptr) return;
  if (!j->is_number_unsigned()) Fail(At(key), "expected a non-negative integer");
  value = j->get<std::uint64_t>();
}

void JsonFields::Read(const std::string& key, bool& value) {
  const Json* j = Find(key);
  if (j == nullptr) return;
  if (!j->is_boolean()) Fail(At(key), "expected true or false");
  value = j->get<bool>();
}

void JsonFields::Read(const std::string& key, std::string& value) {
  const Json* j = Find(key);
  if (j == nullptr) return;
  if (!j->is_string()) Fail(At(key), "expected a string");
  value = j->get<std::string>();
}

void JsonFields::Read(const std::string& key, Eigen::Vector3d& value) {
  if (const Json* j = Find(key)) value = Vector3At(*j, At(key));
}

void JsonFields::Read(const std::string& key, Eigen::Vector2d& value) {
  const Json* j = Find(key);
  if (j == nullptr) return;
  if (!j->is_array() || j->size() != 2) Fail(At(key), "expected an array of 2 numbers");
  value = {NumberAt((*j)[0], At(key) + "[0]"), NumberAt((*j)[1], At(key) + "[1]")};
}

void JsonFields::Finish() const {
  std::string unknown;
  for (const auto& [key, value] : json_.items()) {
    if (read_.count(key) == 0) unknown += (unknown.empty() ? "'" : ", '") + key + "'";
  }
  if (!unknown.empty()) Fail(where_, "unknown key(s) " + unknown + " (see docs/simulator.md)");
}

Rigid3d ParsePose(const Json& json, const std::string& where) {
  JsonFields in(json, where);
  Rigid3d pose;
  if (const Json* matrix = in.Find("matrix")) {
    const std::string at = in.At("matrix");
    if (!matrix->is_array() || matrix->size() != 4) Fail(at, "expected 4 rows of 4 numbers");
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r) {
      const Json& row = (*matrix)[static_cast<std::size_t>(r)];
      if (!row.is_array() || row.size() != 4) Fail(at, "expected 4 rows of 4 numbers");
      for (int c = 0; c < 4; ++c) {
        m(r, c) = NumberAt(row[static_cast<std::size_t>(c)],
                           at + "[" + std::to_string(r) + "][" + std::to_string(c) + "]");
      }
    }
    try {
      pose = Rigid3d::FromMatrix(m);
    } catch (const std::invalid_argument& e) {
      Fail(at, e.what());
    }
  } else if (const Json* look = in.Find("look_at")) {
    JsonFields l(*look, in.At("look_at"));
    Eigen::Vector3d eye = Eigen::Vector3d::Zero(), target = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    l.Read("eye_mm", eye);
    l.Read("target_mm", target);
    l.Read("up", up);
    l.Finish();
    if ((target - eye).norm() < 1e-9 || up.norm() < 1e-9) {
      Fail(in.At("look_at"), "eye and target must differ and up must be non-zero");
    }
    pose = sim::LookAt(eye, target, up);
  } else {
    Eigen::Vector3d translation = Eigen::Vector3d::Zero(), rotation = Eigen::Vector3d::Zero();
    in.Read("translation_mm", translation);
    in.Read("rotation_vector_rad", rotation);
    pose = RotationVectorPose(rotation, translation);
  }
  in.Finish();
  return pose;
}

sim::Motion ParseMotion(const Json& json, const std::string& where) {
  JsonFields in(json, where);
  sim::Motion motion;
  std::string kind = "static";
  in.Read("kind", kind);
  in.Read("slots", motion.segment_slots);
  if (const Json* start = in.Find(kind == "static" ? "pose" : "start")) {
    motion.start = ParsePose(*start, in.At(kind == "static" ? "pose" : "start"));
  }
  if (kind == "static") {
    motion.kind = sim::MotionKind::kStatic;
  } else if (kind == "linear") {
    motion.kind = sim::MotionKind::kLinear;
    sim::LinearMotion& m = motion.linear;
    in.Read("direction", m.direction_in_world);
    in.Read("speed_mm_per_s", m.speed_mm_per_s);
    in.Read("travel_mm", m.travel_mm);
    in.Read("back_and_forth", m.back_and_forth);
  } else if (kind == "rotation") {
    motion.kind = sim::MotionKind::kRotation;
    sim::RotationMotion& m = motion.rotation;
    in.Read("axis", m.axis_in_world);
    in.Read("centre_mm", m.centre_in_world);
    in.Read("speed_rad_per_s", m.speed_rad_per_s);
    in.Read("start_angle_rad", m.start_angle_rad);
    in.Read("sweep_rad", m.sweep_rad);
  } else if (kind == "head_worn") {
    motion.kind = sim::MotionKind::kHeadWorn;
    sim::HeadWornMotion& m = motion.head_worn;
    in.Read("target_mm", m.target_in_world);
    in.Read("up", m.up_in_world);
    in.Read("toward_wearer", m.toward_wearer_in_world);
    in.Read("min_range_mm", m.min_range_mm);
    in.Read("max_range_mm", m.max_range_mm);
    in.Read("azimuth_span_rad", m.azimuth_span_rad);
    in.Read("min_elevation_rad", m.min_elevation_rad);
    in.Read("max_elevation_rad", m.max_elevation_rad);
    in.Read("aim_radius_mm", m.aim_radius_mm);
    in.Read("roll_span_rad", m.roll_span_rad);
    in.Read("period_s", m.period_s);
  } else if (kind == "pivot") {
    motion.kind = sim::MotionKind::kPivot;
    in.Read("tilt_rad", motion.pivot.tilt_rad);
    in.Read("period_s", motion.pivot.period_s);
    in.Read("spin_rad", motion.pivot.spin_rad);
  } else if (kind == "sequence") {
    motion.kind = sim::MotionKind::kSequence;
    const std::string at = in.At("segments");
    const Json& segments = ArrayAt(in.Get("segments"), at);
    for (std::size_t i = 0; i < segments.size(); ++i) {
      motion.segments.push_back(ParseMotion(segments[i], at + "[" + std::to_string(i) + "]"));
    }
  } else if (kind == "keyframes") {
    motion.kind = sim::MotionKind::kKeyframes;
    const std::string at = in.At("keyframes");
    const Json& keyframes = ArrayAt(in.Get("keyframes"), at);
    for (std::size_t i = 0; i < keyframes.size(); ++i) {
      const std::string item = at + "[" + std::to_string(i) + "]";
      JsonFields k(keyframes[i], item);
      sim::Keyframe keyframe;
      k.Get("slot");  // required
      k.Read("slot", keyframe.slot);
      keyframe.pose = ParsePose(k.Get("pose"), k.At("pose"));
      k.Finish();
      motion.keyframes.push_back(keyframe);
    }
  } else {
    Fail(in.At("kind"), "unknown motion '" + kind +
                            "' (static, linear, rotation, head_worn, pivot, sequence, keyframes)");
  }
  in.Finish();
  try {
    motion.Check();
  } catch (const std::invalid_argument& e) {
    Fail(where, e.what());
  }
  return motion;
}

OrderedJson MatrixJson(const Rigid3d& b_from_a) {
  const Eigen::Matrix4d m = b_from_a.ToMatrix();
  OrderedJson rows = OrderedJson::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

}  // namespace tofnav::internal
