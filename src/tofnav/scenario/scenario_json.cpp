// SPDX-License-Identifier: BSD-3-Clause
// Scenario documents: the top level, objects, tools and the patient.
#include "tofnav/scenario/scenario_json.hpp"

#include <algorithm>
#include <optional>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/scenario/patient_head.hpp"
#include "tofnav/scenario/scenario_json_internal.hpp"
#include "tofnav/sim/occluders.hpp"
#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/scenario_builtins.hpp"
#include "tofnav/sim/shapes.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav {
namespace {

using internal::Fail;
using internal::Json;
using internal::JsonFields;

std::string Item(const std::string& where, std::size_t i) {
  return where + "[" + std::to_string(i) + "]";
}

class ScenarioBuilder {
 public:
  explicit ScenarioBuilder(std::filesystem::path base) : base_(std::move(base)) {}

  sim::Scenario Build(const Json& json) {
    JsonFields in(json, "$");
    s_.name = "custom";
    in.Read("name", s_.name);
    in.Read("description", s_.description);
    in.Read("seed", s_.seed);
    in.Read("frames", s_.frames);
    ForEach(in, "materials", [&](const Json& j, const std::string& at) {
      const sim::Material material = internal::ParseMaterial(j, at);
      if (s_.FindMaterial(material.name) >= 0) Fail(at, "material '" + material.name + "' twice");
      s_.scene.AddMaterial(material);
    });
    ForEach(in, "mounts", [&](const Json& j, const std::string& at) {
      JsonFields m(j, at);
      std::string name;
      m.Read("name", name);
      s_.AddMount(name, internal::ParseMotion(m.Get("motion"), m.At("motion")));
      m.Finish();
    });
    if (const Json* j = in.Find("patient")) Patient(*j, in.At("patient"));
    ForEach(in, "objects", [&](const Json& j, const std::string& at) { Object(j, at); });
    ForEach(in, "tools", [&](const Json& j, const std::string& at) { ToolEntry(j, at); });
    if (const Json* j = in.Find("camera"))
      internal::ParseCamera(*j, in.At("camera"), base_, s_.camera);
    if (const Json* j = in.Find("timing")) s_.timing = internal::ParseTiming(*j, in.At("timing"));
    if (const Json* j = in.Find("render")) s_.render = internal::ParseRender(*j, in.At("render"));
    in.Finish();
    try {
      s_.Check();
    } catch (const std::invalid_argument& e) {
      Fail("$", e.what());
    }
    return std::move(s_);
  }

 private:
  template <typename Visit>
  void ForEach(JsonFields& in, const char* key, Visit visit) {
    const Json* array = in.Find(key);
    if (array == nullptr) return;
    internal::ArrayAt(*array, in.At(key));
    for (std::size_t i = 0; i < array->size(); ++i) visit((*array)[i], Item(in.At(key), i));
  }

  // A material by name; a preset name not defined in "materials" is added on first use.
  int MaterialIndex(JsonFields& in, const char* key, const std::string& fallback) {
    std::string name = fallback;
    in.Read(key, name);
    const int index = s_.FindMaterial(name);
    if (index >= 0) return index;
    const std::optional<sim::Material> preset = internal::MaterialPreset(name);
    if (!preset) Fail(in.At(key), "no material or preset called '" + name + "'");
    return s_.scene.AddMaterial(*preset);
  }

  int MountIndex(JsonFields& in) {
    std::string name = "world";
    in.Read("mount", name);
    if (name == "world") return -1;
    const int index = s_.FindMount(name);
    if (index < 0) Fail(in.At("mount"), "no mount called '" + name + "'");
    return index;
  }

  Rigid3d PoseOf(JsonFields& in) {
    const Json* pose = in.Find("pose");
    return pose == nullptr ? Rigid3d::Identity() : internal::ParsePose(*pose, in.At("pose"));
  }

  void Object(const Json& json, const std::string& at) {
    JsonFields in(json, at);
    std::string name;
    in.Read("name", name);
    const Json& shape = in.Get("shape");
    TriangleMesh mesh = internal::ParseShape(shape, in.At("shape"), base_);
    const std::string kind = shape.value("kind", "");  // a string: ParseShape checked it
    const int material = MaterialIndex(in, "material",
                                       kind == "hand"    ? "skin"
                                       : kind == "drape" ? "drape"
                                                         : "diffuse");
    const int mount = MountIndex(in);
    s_.AddObject(name, std::move(mesh), material, mount, PoseOf(in));
    in.Finish();
  }

  sim::Marker MarkerEntry(const Json& json, const std::string& at) {
    JsonFields in(json, at);
    std::string shape = "disc";
    in.Read("shape", shape);
    if (shape != "disc" && shape != "sphere") Fail(in.At("shape"), "expected disc or sphere");
    sim::Marker marker;
    marker.shape = shape == "disc" ? sim::MarkerShape::kDisc : sim::MarkerShape::kSphere;
    in.Read("diameter_mm", marker.diameter_mm);
    in.Read("centre_mm", marker.centre_in_tool);
    in.Read("normal", marker.normal_in_tool);
    if (marker.normal_in_tool.norm() < 1e-9) Fail(in.At("normal"), "must be non-zero");
    marker.normal_in_tool.normalize();
    marker.material = MaterialIndex(in, "material", "retro_reflective");
    in.Finish();
    return marker;
  }

  void ToolEntry(const Json& json, const std::string& at) {
    JsonFields in(json, at);
    std::string name, preset;
    in.Read("name", name);
    in.Read("preset", preset);
    const Json* markers = in.Find("markers");
    const Json* stickers = in.Find("stickers");
    if (int(!preset.empty()) + int(markers != nullptr) + int(stickers != nullptr) != 1) {
      Fail(at, "a tool needs exactly one of 'preset', 'markers' or 'stickers'");
    }
    const int material = MaterialIndex(in, "material", "retro_reflective");
    if (stickers != nullptr) {
      if (!head_) Fail(in.At("stickers"), "stickers need a patient");
      JsonFields st(*stickers, in.At("stickers"));
      double diameter_mm = 10.0;
      bool conform = true;  // tape follows the skin; false: rigid flat discs (docs/simulator.md)
      st.Read("diameter_mm", diameter_mm);
      st.Read("conform", conform);
      const std::string list_at = st.At("azimuth_elevation_rad");
      const Json& list = internal::ArrayAt(st.Get("azimuth_elevation_rad"), list_at);
      std::vector<Eigen::Vector3d> directions;
      for (std::size_t i = 0; i < list.size(); ++i) {
        if (!list[i].is_array() || list[i].size() != 2) Fail(Item(list_at, i), "expected [az, el]");
        directions.push_back(sim::HeadDirection(internal::NumberAt(list[i][0], Item(list_at, i)),
                                                internal::NumberAt(list[i][1], Item(list_at, i))));
      }
      st.Finish();
      const int object = s_.patient->object;
      s_.AddTool(
          sim::SkinStickers(name, *head_, directions, diameter_mm, material, conform ? object : -1),
          s_.object_mounts[static_cast<std::size_t>(object)]);
      s_.scene.tools.back().scene_from_tool =
          s_.scene.objects[static_cast<std::size_t>(object)].scene_from_object;
      in.Finish();
      return;
    }
    const int mount = MountIndex(in);
    const Rigid3d mount_from_tool = PoseOf(in);
    sim::Tool tool;
    if (!preset.empty()) {
      try {
        tool = sim::ToolPreset(preset, name, material);
      } catch (const std::invalid_argument& e) {
        Fail(in.At("preset"), e.what());
      }
      const Eigen::Vector2d plate = sim::ToolPresetPlateMm(preset);
      if (in.Find("plate_material") != nullptr && plate.x() > 0.0) {
        s_.AddObject(name + "_plate", sim::PlaneMesh(plate.x(), plate.y()),
                     MaterialIndex(in, "plate_material", "diffuse"), mount, mount_from_tool);
      }
      if (const Json* rod = in.Find("instrument")) {
        JsonFields r(*rod, in.At("instrument"));
        sim::InstrumentOptions options;
        options.preset = preset;
        r.Read("rod_diameter_mm", options.rod_diameter_mm);
        r.Read("rod_length_mm", options.rod_length_mm);
        TriangleMesh mesh;
        internal::Checked(in.At("instrument"), [&] { mesh = sim::InstrumentRodMesh(options); });
        s_.AddObject(name + "_rod", std::move(mesh), MaterialIndex(r, "rod_material", "diffuse"),
                     mount, mount_from_tool);
        r.Finish();
      }
    } else {
      if (in.Find("instrument") != nullptr)
        Fail(in.At("instrument"), "an instrument needs a preset");
      tool.name = name;
      const Json& list = internal::ArrayAt(*markers, in.At("markers"));
      for (std::size_t i = 0; i < list.size(); ++i) {
        tool.markers.push_back(MarkerEntry(list[i], Item(in.At("markers"), i)));
      }
    }
    tool.scene_from_tool = mount_from_tool;
    s_.AddTool(std::move(tool), mount);
    in.Finish();
  }

  void Patient(const Json& json, const std::string& at) {
    JsonFields in(json, at);
    std::string head = "phantom";
    in.Read("head", head);
    sim::HeadPhantomOptions phantom_options;
    if (const Json* j = in.Find("phantom")) {
      JsonFields p(*j, in.At("phantom"));
      phantom_options = internal::ParsePhantomOptions(p);
      p.Finish();
    }
    try {
      head_ = LoadPatientHead(head, base_, phantom_options);
    } catch (const std::invalid_argument& e) {
      Fail(in.At(head == "phantom" ? "phantom" : "head"), e.what());
    }
    if (const Json* j = in.Find("anatomy")) {
      JsonFields a(*j, in.At("anatomy"));
      a.Read("centre_mm", head_->anatomy.centre_in_image);
      a.Read("semi_axes_mm", head_->anatomy.semi_axes_mm);
      a.Read("nasion_elevation_rad", head_->anatomy.nasion_elevation_rad);
      a.Finish();
    }
    const int material = MaterialIndex(in, "material", "skin");
    const int mount = MountIndex(in);
    sim::EvdPlanOptions plan;
    if (const Json* j = in.Find("plan")) plan = internal::ParsePlanOptions(*j, in.At("plan"));
    try {
      sim::AddPatient(s_, *head_, material, mount, PoseOf(in), plan);
    } catch (const std::invalid_argument& e) {
      Fail(at, e.what());
    }
    if (const Json* j = in.Find("ct")) {
      JsonFields c(*j, in.At("ct"));
      c.Read("write", s_.patient->write_ct);
      Json options = *j;
      options.erase("write");
      s_.patient->ct = internal::ParseCtOptions(options, in.At("ct"));
    }
    in.Finish();
  }

  std::filesystem::path base_;
  sim::Scenario s_;
  std::optional<sim::PatientHead> head_;
};

}  // namespace

sim::Scenario ParseScenarioJson(std::string_view text, const std::filesystem::path& source) {
  Json json;
  try {
    json = Json::parse(text.begin(), text.end());
  } catch (const Json::parse_error& e) {
    throw IoError(source, e.byte > 0 ? e.byte - 1 : 0, std::string("invalid JSON: ") + e.what());
  } catch (const Json::exception& e) {  // e.g. a number too large for a double
    throw IoError(source, std::nullopt, std::string("invalid JSON: ") + e.what());
  }
  try {
    return ScenarioBuilder(source.parent_path()).Build(json);
  } catch (const internal::SchemaError& e) {
    throw IoError(source, std::nullopt, e.what());
  } catch (const std::invalid_argument& e) {  // a value the simulator refuses
    throw IoError(source, std::nullopt, std::string("invalid scenario: ") + e.what());
  } catch (const Json::exception& e) {
    throw IoError(source, std::nullopt, std::string("unexpected JSON content: ") + e.what());
  }
}

sim::Scenario ReadScenarioFile(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  return ParseScenarioJson(
      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), path);
}

sim::Scenario LoadScenario(const std::string& name_or_path) {
  const std::vector<std::string> names = sim::BuiltinScenarioNames();
  if (std::find(names.begin(), names.end(), name_or_path) != names.end()) {
    return sim::BuiltinScenario(name_or_path);
  }
  if (!std::filesystem::is_regular_file(name_or_path)) {
    std::string known;
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw IoError(name_or_path, std::nullopt,
                  "neither a built-in scenario (" + known + ") nor a scenario file");
  }
  return ReadScenarioFile(name_or_path);
}

}  // namespace tofnav
