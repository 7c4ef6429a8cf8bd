// SPDX-License-Identifier: BSD-3-Clause
// truth.json writer.
#include "tofnav/scenario/truth_json.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/scenario/scenario_json_internal.hpp"

namespace tofnav {
namespace {

using internal::MatrixJson;
using internal::OrderedJson;

constexpr int kTruthVersion = 1;

OrderedJson Vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

const char* MotionKindName(sim::MotionKind kind) {
  switch (kind) {
    case sim::MotionKind::kStatic:
      return "static";
    case sim::MotionKind::kLinear:
      return "linear";
    case sim::MotionKind::kRotation:
      return "rotation";
    case sim::MotionKind::kHeadWorn:
      return "head_worn";
    case sim::MotionKind::kSequence:
      return "sequence";
    case sim::MotionKind::kPivot:
      return "pivot";
    case sim::MotionKind::kKeyframes:
      return "keyframes";
  }
  return "?";
}

std::string MountName(const sim::Scenario& s, int mount) {
  return mount < 0 ? "world" : s.mounts[static_cast<std::size_t>(mount)].name;
}

OrderedJson ToolJson(const sim::Scenario& s, std::size_t t, bool rigid_with_patient) {
  const sim::Tool& tool = s.scene.tools[t];
  OrderedJson markers = OrderedJson::array();
  for (const sim::Marker& m : tool.markers) {
    OrderedJson marker{{"shape", m.shape == sim::MarkerShape::kDisc ? "disc" : "sphere"},
                       {"diameter_mm", m.diameter_mm},
                       {"centre_in_tool", Vector(m.centre_in_tool)}};
    if (m.shape == sim::MarkerShape::kDisc) marker["normal_in_tool"] = Vector(m.normal_in_tool);
    marker["material"] = s.scene.materials[static_cast<std::size_t>(m.material)].name;
    if (m.conforms_to_object >= 0)  // tape drawn on this object's surface
      marker["conforms_to"] = s.scene.objects[static_cast<std::size_t>(m.conforms_to_object)].name;
    markers.push_back(marker);
  }
  OrderedJson j{{"mount", MountName(s, s.tool_mounts[t])},
                {"mount_from_tool", MatrixJson(tool.scene_from_tool)},
                {"rigid_with_patient", rigid_with_patient},
                {"markers", markers}};
  if (tool.tip_in_tool) j["tip_in_tool"] = Vector(*tool.tip_in_tool);
  return j;
}

OrderedJson PatientJson(const sim::Scenario& s) {
  const sim::Patient& p = *s.patient;
  const auto object = static_cast<std::size_t>(p.object);
  OrderedJson ventricles = OrderedJson::array();
  for (const sim::Ellipsoid& e : p.anatomy.Ventricles()) {
    ventricles.push_back(
        {{"centre_in_image", Vector(e.centre_in_image)}, {"semi_axes_mm", Vector(e.semi_axes_mm)}});
  }
  OrderedJson trajectories = OrderedJson::array();
  for (const sim::Trajectory& t : p.plan) {
    trajectories.push_back({{"name", t.name},
                            {"entry_in_image", Vector(t.entry_in_image)},
                            {"target_in_image", Vector(t.target_in_image)}});
  }
  OrderedJson landmarks = OrderedJson::array();
  for (const sim::PlannedLandmark& l : p.landmarks) {
    landmarks.push_back({{"name", l.name},
                         {"in_image", Vector(l.in_image)},
                         {"touch_first_slot", l.touch_first_slot},
                         {"touch_last_slot", l.touch_last_slot}});
  }
  return {{"head", p.head_source},
          {"object", s.scene.objects[object].name},
          {"mount", MountName(s, s.object_mounts[object])},
          {"mount_from_image", MatrixJson(s.scene.objects[object].scene_from_object)},
          {"anatomy",
           {{"centre_in_image", Vector(p.anatomy.centre_in_image)},
            {"semi_axes_mm", Vector(p.anatomy.semi_axes_mm)},
            {"nasion_elevation_rad", p.anatomy.nasion_elevation_rad}}},
          {"ventricles", ventricles},
          {"trajectories", trajectories},
          {"landmarks", landmarks}};
}

OrderedJson Header(const sim::Scenario& s, const TruthRunInfo& info) {
  OrderedJson h{{"format", "tofnav-simulation-truth"},
                {"version", kTruthVersion},
                {"conventions",
                 "mm, s, rad; matrices are 4x4 row-major nested lists in the column-vector "
                 "convention (p_target = M p_source); b_from_a maps frame a into frame b"},
                {"scenario", s.name},
                {"description", s.description},
                {"seed", s.seed},
                {"profile", info.profile},
                {"rate_hz", s.timing.rate_hz},
                {"timestamp_unit", "hl2ss host ticks (100 ns), as in the recording"}};
  OrderedJson files = OrderedJson::object();
  for (const auto& [role, name] : info.files) files[role] = name;
  h["files"] = files;
  h["rig_from_ahat"] = MatrixJson(s.camera.RigFromAhat());
  h["camera"] = {{"motion", MotionKindName(s.camera.motion.kind)},
                 {"calibration", internal::CalibrationJson(s.camera)},
                 {"slam_jitter",
                  {{"translation_sigma_mm", s.camera.slam.translation_sigma_mm},
                   {"rotation_sigma_rad", s.camera.slam.rotation_sigma_rad}}}};
  h["timing"] = {{"rate_hz", s.timing.rate_hz},
                 {"start_ticks", s.timing.start_ticks},
                 {"drop_probability", s.timing.drop_probability},
                 {"mean_drop_slots", s.timing.mean_drop_slots},
                 {"slot_stride", s.timing.slot_stride},
                 {"no_hand_rate_hz", s.timing.no_hand_rate_hz}};
  h["render"] = internal::RenderJson(s.render);
  OrderedJson materials = OrderedJson::array();
  for (const sim::Material& m : s.scene.materials) materials.push_back(internal::MaterialJson(m));
  h["materials"] = materials;
  OrderedJson mounts = OrderedJson::array();
  for (const sim::Mount& m : s.mounts) {
    mounts.push_back({{"name", m.name}, {"motion", MotionKindName(m.motion.kind)}});
  }
  h["mounts"] = mounts;
  OrderedJson objects = OrderedJson::object();
  for (std::size_t o = 0; o < s.scene.objects.size(); ++o) {
    const sim::SceneObject& object = s.scene.objects[o];
    objects[object.name] = {
        {"mount", MountName(s, s.object_mounts[o])},
        {"mount_from_object", MatrixJson(object.scene_from_object)},
        {"material", s.scene.materials[static_cast<std::size_t>(object.material)].name},
        {"vertices", object.mesh.vertices.size()},
        {"triangles", object.mesh.triangles.size()}};
  }
  h["objects"] = objects;
  const std::vector<int> rigid = s.ToolsRigidWithPatient();
  OrderedJson tools = OrderedJson::object();
  for (std::size_t t = 0; t < s.scene.tools.size(); ++t) {
    const bool with_patient =
        std::find(rigid.begin(), rigid.end(), static_cast<int>(t)) != rigid.end();
    tools[s.scene.tools[t].name] = ToolJson(s, t, with_patient);
  }
  h["tools"] = tools;
  if (s.patient) {
    h["patient"] = PatientJson(s);
    const Rigid3d& mount_from_image =
        s.scene.objects[static_cast<std::size_t>(s.patient->object)].scene_from_object;
    for (const int t : rigid) {
      const sim::Tool& tool = s.scene.tools[static_cast<std::size_t>(t)];
      h[tool.name + "_from_image"] = MatrixJson(tool.scene_from_tool.Inverse() * mount_from_image);
    }
    const std::vector<int> headframe = HeadframeTools(s);
    if (!headframe.empty()) {  // the joined tool lives in the frame of its first part
      const sim::Tool& first = s.scene.tools[static_cast<std::size_t>(headframe.front())];
      h[std::string(kHeadframeToolName) + "_from_image"] =
          MatrixJson(first.scene_from_tool.Inverse() * mount_from_image);
    }
  }
  return h;
}

// Indented objects, but arrays of numbers (vectors, matrix rows, matrices) on one line.
void Pretty(const OrderedJson& j, int indent, std::string& out) {
  const std::string pad(static_cast<std::size_t>(indent) + 2, ' ');
  const bool nested_objects =
      j.is_array() &&
      std::any_of(j.begin(), j.end(), [](const OrderedJson& e) { return e.is_object(); });
  if (j.is_object() && !j.empty()) {
    out += "{";
    bool first = true;
    for (const auto& [key, value] : j.items()) {
      out += (first ? "\n" : ",\n") + pad + OrderedJson(key).dump() + ": ";
      Pretty(value, indent + 2, out);
      first = false;
    }
    out += "\n" + std::string(static_cast<std::size_t>(indent), ' ') + "}";
  } else if (nested_objects) {
    out += "[";
    for (std::size_t i = 0; i < j.size(); ++i) {
      out += (i == 0 ? "\n" : ",\n") + pad;
      Pretty(j[i], indent + 2, out);
    }
    out += "\n" + std::string(static_cast<std::size_t>(indent), ' ') + "]";
  } else {
    out += j.dump();
  }
}

}  // namespace

std::vector<int> HeadframeTools(const sim::Scenario& scenario) {
  std::vector<int> tools;
  for (const int t : scenario.ToolsRigidWithPatient()) {
    const sim::Tool& tool = scenario.scene.tools[static_cast<std::size_t>(t)];
    if (tool.name.starts_with("reference") && !tool.markers.empty()) tools.push_back(t);
  }
  return tools;
}

SimulationTruthWriter::SimulationTruthWriter(const std::filesystem::path& path,
                                             const sim::Scenario& scenario,
                                             const TruthRunInfo& info)
    : scenario_(scenario), file_(path) {
  std::string text;
  Pretty(Header(scenario, info), 0, text);
  // Re-open the object to stream the frames: drop the closing "\n}".
  text.resize(text.size() - 2);
  file_.Write(text + ",\n  \"frames\": [");
}

void SimulationTruthWriter::Append(const sim::SimulatedFrame& frame) {
  Require(frame.slot > last_slot_, "SimulationTruthWriter: frames must come in slot order");
  last_slot_ = frame.slot;
  const sim::Scene& scene = scenario_.scene;
  const AhatFrame& f = frame.render.frame;
  OrderedJson j{{"index", frame.index},
                {"slot", frame.slot},
                {"timestamp", f.host_ticks},
                {"time_s", static_cast<double>(frame.slot) / scenario_.timing.rate_hz},
                {"world_from_rig", MatrixJson(f.world_from_rig.value_or(Rigid3d()))},
                {"world_from_rig_true", MatrixJson(frame.world_from_rig_true)},
                {"rig_from_ahat", MatrixJson(scenario_.camera.RigFromAhat())}};
  for (std::size_t t = 0; t < scene.tools.size(); ++t) {
    j["ahat_from_" + scene.tools[t].name] = MatrixJson(frame.ahat_from_tools[t]);
  }
  OrderedJson visible = OrderedJson::object();
  for (const sim::Tool& tool : scene.tools) visible[tool.name] = OrderedJson::array();
  for (std::size_t m = 0; m < frame.render.markers.size(); ++m) {
    const sim::MarkerTruth& marker = frame.render.markers[m];
    if (marker.pixel_count <= 0) continue;
    const sim::Marker& geometry = scene.tools[static_cast<std::size_t>(marker.tool)]
                                      .markers[static_cast<std::size_t>(marker.marker)];
    // Entrance angle: between the disc's normal and the direction back to the camera (0 for a
    // sphere); retro-reflection fades with it and stops at the material's cut-off.
    double entrance_rad = 0.0;
    if (geometry.shape == sim::MarkerShape::kDisc) {
      const Eigen::Vector3d normal_in_ahat =
          frame.ahat_from_tools[static_cast<std::size_t>(marker.tool)].rotation *
          geometry.normal_in_tool.normalized();
      entrance_rad =
          std::acos(std::clamp(-normal_in_ahat.dot(marker.centre_in_ahat.normalized()), -1.0, 1.0));
    }
    OrderedJson entry{{"marker", marker.marker},
                      {"centre_in_ahat", Vector(marker.centre_in_ahat)},
                      {"pixel_count", marker.pixel_count},
                      {"entrance_angle_rad", entrance_rad}};
    if (const auto& uv = frame.marker_pixels[m]) entry["pixel_uv"] = {uv->x(), uv->y()};
    visible[scene.tools[static_cast<std::size_t>(marker.tool)].name].push_back(entry);
  }
  j["visible_markers"] = visible;
  OrderedJson occluded = OrderedJson::object();
  for (std::size_t m = 0; m < frame.marker_occluders.size(); ++m) {
    const sim::MarkerOccluder& by = frame.marker_occluders[m];
    if (!by.hidden()) continue;
    const sim::MarkerTruth& marker = frame.render.markers[m];
    occluded[scene.tools[static_cast<std::size_t>(marker.tool)].name].push_back(
        {{"marker", marker.marker},
         {"by", by.object >= 0 ? scene.objects[static_cast<std::size_t>(by.object)].name
                               : scene.tools[static_cast<std::size_t>(by.tool)].name}});
  }
  j["occluded_markers"] = occluded;
  OrderedJson objects = OrderedJson::object();
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    objects[scene.objects[o].name] = MatrixJson(frame.ahat_from_objects[o]);
  }
  j["ahat_from_objects"] = objects;
  file_.Write(std::string(frames_ == 0 ? "\n    " : ",\n    ") + j.dump());
  ++frames_;
}

void SimulationTruthWriter::Close(std::int64_t dropped_slots) {
  const OrderedJson tail{
      {"frame_count", frames_}, {"slot_count", last_slot_ + 1}, {"dropped_slots", dropped_slots}};
  std::string text;
  Pretty(tail, 0, text);  // "{\n  ...\n}": reuse its body
  file_.Write("\n  ],\n" + text.substr(2));
  file_.Write(std::string("\n"));
  file_.Commit();
}

}  // namespace tofnav
