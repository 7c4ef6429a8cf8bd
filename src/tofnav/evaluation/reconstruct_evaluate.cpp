// SPDX-License-Identifier: BSD-3-Clause
// `tofnav evaluate reconstruction`: truth surfaces from truth.json + scenario, errors per object.
#include "tofnav/evaluation/reconstruct_evaluate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <string_view>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/fusion/surface_distance.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/scenario/scenario_json.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;   // objects in truth.json order (the scenario's)
constexpr double kRigidTranslationMm = 0.01;  // objects moving more relative to the tool: not rigid
constexpr double kRigidRotationRad = 1e-5;

OrderedJson ParseTruth(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  try {
    return OrderedJson::parse(bytes.begin(), bytes.end());
  } catch (const OrderedJson::parse_error& e) {
    throw IoError(path, e.byte > 0 ? e.byte - 1 : 0, "invalid JSON: " + std::string(e.what()));
  }
}

Rigid3d MatrixAt(const OrderedJson& j, const std::filesystem::path& path, const std::string& what) {
  if (!j.is_array() || j.size() != 4) throw IoError(path, std::nullopt, what + ": not a 4 x 4");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    const OrderedJson& row = j[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != 4) throw IoError(path, std::nullopt, what + ": bad row");
    for (int c = 0; c < 4; ++c) {
      const OrderedJson& v = row[static_cast<std::size_t>(c)];
      if (!v.is_number()) throw IoError(path, std::nullopt, what + ": not a number");
      m(r, c) = v.get<double>();
    }
  }
  try {
    return Rigid3d::FromMatrix(m);
  } catch (const std::exception& e) {
    throw IoError(path, std::nullopt, what + ": " + e.what());
  }
}

std::unique_ptr<sim::Scenario> LoadTruthScenario(const OrderedJson& truth,
                                                 const std::filesystem::path& scenario_file) {
  if (!scenario_file.empty())
    return std::make_unique<sim::Scenario>(ReadScenarioFile(scenario_file));
  const std::string name = truth.value("scenario", std::string());
  const std::vector<std::string> builtins = sim::BuiltinScenarioNames();
  if (std::find(builtins.begin(), builtins.end(), name) == builtins.end()) return nullptr;
  return std::make_unique<sim::Scenario>(sim::BuiltinScenario(name));
}

// The meshes simulate wrote (truth.json files "mesh:<object>"), each checked against the
// object's vertex and triangle counts; empty for a session written before them.
std::vector<std::pair<std::string, TriangleMesh>> MeshFiles(const OrderedJson& truth,
                                                            const std::filesystem::path& dir) {
  std::vector<std::pair<std::string, TriangleMesh>> meshes;
  const OrderedJson& files = truth.value("files", OrderedJson::object());
  const std::filesystem::path path = dir / "truth.json";
  constexpr std::string_view kRole = "mesh:";
  for (const auto& [role, value] : files.items()) {
    if (role.rfind(kRole, 0) != 0) continue;
    const std::string name = role.substr(kRole.size());
    const OrderedJson& objects = truth["objects"];
    if (!value.is_string() || !objects.contains(name) || !objects[name].is_object()) {
      throw IoError(path, std::nullopt,
                    "files." + role + ": expected a file name of an object in \"objects\"");
    }
    const std::filesystem::path relative = value.get<std::string>();
    const auto up = std::find(relative.begin(), relative.end(), "..");
    if (relative.empty() || relative.is_absolute() || up != relative.end()) {
      throw IoError(path, std::nullopt, "files." + role + ": expected a path inside the folder");
    }
    const std::size_t vertices = objects[name].value("vertices", std::size_t{0});
    const std::size_t triangles = objects[name].value("triangles", std::size_t{0});
    const std::string expected = "the mesh of object '" + name + "' (" + std::to_string(vertices) +
                                 " vertices, " + std::to_string(triangles) + " triangles, as " +
                                 path.string() + " says)";
    const std::filesystem::path file = dir / relative;
    if (!std::filesystem::is_regular_file(file)) {
      throw IoError(file, std::nullopt, "missing: expected " + expected);
    }
    TriangleMesh mesh = ReadMesh(file);
    if (mesh.vertices.size() != vertices || mesh.triangles.size() != triangles) {
      throw IoError(file, std::nullopt,
                    "has " + std::to_string(mesh.vertices.size()) + " vertices, " +
                        std::to_string(mesh.triangles.size()) + " triangles; expected " + expected);
    }
    meshes.emplace_back(name, std::move(mesh));
  }
  return meshes;
}

// The object meshes by name: the session's mesh files when truth.json names them; else (a
// session written before them) from the scenario, or only the skin file without one.
std::vector<std::pair<std::string, TriangleMesh>> ObjectMeshes(
    const OrderedJson& truth, const std::filesystem::path& dir,
    const std::filesystem::path& scenario_file) {
  std::vector<std::pair<std::string, TriangleMesh>> meshes = MeshFiles(truth, dir);
  if (!meshes.empty()) return meshes;
  const std::filesystem::path path = dir / "truth.json";
  const std::unique_ptr<sim::Scenario> scenario = LoadTruthScenario(truth, scenario_file);
  if (scenario) {
    for (const sim::SceneObject& o : scenario->scene.objects) {
      if (!truth["objects"].contains(o.name)) continue;
      const OrderedJson& info = truth["objects"][o.name];
      Require(info.value("vertices", std::size_t{0}) == o.mesh.vertices.size() &&
                  info.value("triangles", std::size_t{0}) == o.mesh.triangles.size(),
              "the scenario's mesh of '" + o.name + "' does not match " + path.string() +
                  " (give the scenario file with --scenario)");
      meshes.emplace_back(o.name, o.mesh);
    }
    return meshes;
  }
  const OrderedJson& files = truth.value("files", OrderedJson::object());
  const OrderedJson& patient = truth.value("patient", OrderedJson::object());
  if (files.contains("skin") && patient.contains("object")) {
    meshes.emplace_back(patient["object"].get<std::string>(),
                        ReadMesh(dir / files["skin"].get<std::string>()));
  }
  return meshes;
}

// Table II row and size column of an object name.
std::pair<std::string, int> TableCell(const std::string& name, bool is_patient) {
  if (is_patient) return {"H", 1};
  const std::pair<const char*, const char*> rows[] = {
      {"triangular_pyramid", "TP"}, {"frustum_pyramid", "FP"}, {"hemisphere", "HS"}};
  for (const auto& [prefix, row] : rows) {
    if (name.rfind(prefix, 0) != 0) continue;
    const std::size_t at = name.rfind("_size");
    const int size = at == std::string::npos ? 1 : std::atoi(name.c_str() + at + 5);
    return {row, std::clamp(size, 1, 4)};
  }
  return {"other", 1};
}

Rgb8 ErrorColor(double error_mm, double scale_mm) {  // blue (0) -> green -> red (scale)
  const double t = std::clamp(std::abs(error_mm) / scale_mm, 0.0, 1.0);
  const auto c = [](double x) { return static_cast<std::uint8_t>(std::lround(255.0 * x)); };
  return t < 0.5 ? Rgb8(0, c(2.0 * t), c(1.0 - 2.0 * t))
                 : Rgb8(c(2.0 * t - 1.0), c(2.0 - 2.0 * t), 0);
}

}  // namespace

std::vector<TruthSurface> ReadTruthSurfaces(const std::filesystem::path& truth_dir,
                                            const std::string& tool_name,
                                            const std::filesystem::path& scenario_file) {
  const std::filesystem::path path = truth_dir / "truth.json";
  const OrderedJson truth = ParseTruth(path);
  if (!truth.is_object() || !truth.contains("tools") || !truth.contains("frames") ||
      !truth.contains("objects") || !truth["frames"].is_array() || truth["frames"].empty()) {
    throw IoError(path, std::nullopt, "expected a simulation truth with tools, objects, frames");
  }
  std::string tool = tool_name;
  if (tool.empty()) {
    Require(truth["tools"].size() == 1,
            path.string() + " has several tools: name the reference with --tool-name");
    tool = truth["tools"].begin().key();
  }
  Require(truth["tools"].contains(tool), "no tool '" + tool + "' in " + path.string());
  const std::string patient_object =
      truth.contains("patient") ? truth["patient"].value("object", std::string()) : "";
  std::vector<TruthSurface> surfaces;
  for (auto& [name, mesh] : ObjectMeshes(truth, truth_dir, scenario_file)) {
    std::optional<Rigid3d> first;
    bool rigid = true;
    for (const OrderedJson& frame : truth["frames"]) {
      Require(frame.contains("ahat_from_objects") && frame["ahat_from_objects"].contains(name),
              path.string() + ": a frame has no pose of object '" + name +
                  "': the recorded scene differs from the scenario it names (a suite "
                  "variation?); give the scenario file with --scenario");
      const Rigid3d ahat_from_tool =
          MatrixAt(frame.at("ahat_from_" + tool), path, "ahat_from_" + tool);
      const Rigid3d ahat_from_object =
          MatrixAt(frame.at("ahat_from_objects").at(name), path, "ahat_from_objects." + name);
      const Rigid3d tool_from_object = ahat_from_tool.Inverse() * ahat_from_object;
      if (!first) first = tool_from_object;
      rigid = rigid && TranslationDistanceMm(*first, tool_from_object) <= kRigidTranslationMm &&
              RotationDistanceRad(*first, tool_from_object) <= kRigidRotationRad;
    }
    if (!rigid) continue;
    const std::string material = truth["objects"].contains(name)
                                     ? truth["objects"][name].value("material", std::string())
                                     : std::string();
    surfaces.push_back({name, material, name == patient_object, Transform(*first, mesh)});
  }
  return surfaces;
}

SurfaceErrorStats ComputeSurfaceErrorStats(const std::vector<double>& signed_distances_mm) {
  constexpr double kFarErrorMm = 3.0;  // the outlier line of the robustness suite (docs/suite.md)
  SurfaceErrorStats s;
  std::vector<double> abs;
  abs.reserve(signed_distances_mm.size());
  for (const double d : signed_distances_mm) abs.push_back(std::abs(d));
  s.abs_mm = Summarise(abs);
  if (abs.empty()) return s;
  const auto n = static_cast<double>(abs.size());
  s.mean_signed_mm =
      std::accumulate(signed_distances_mm.begin(), signed_distances_mm.end(), 0.0) / n;
  const auto beyond =
      std::count_if(abs.begin(), abs.end(), [](double a) { return a > kFarErrorMm; });
  s.beyond_3mm_fraction = static_cast<double>(beyond) / n;
  return s;
}

void EvaluateReconstructionOptions::Check() const {
  Require(std::isfinite(max_distance_mm) && max_distance_mm > 0.0,
          "EvaluateReconstructionOptions::max_distance_mm must be > 0");
  Require(std::isfinite(color_scale_mm) && color_scale_mm > 0.0,
          "EvaluateReconstructionOptions::color_scale_mm must be > 0");
}

ReconstructionEvaluation EvaluateReconstruction(const TriangleMesh& surface,
                                                const std::vector<TruthSurface>& truth,
                                                const EvaluateReconstructionOptions& options) {
  options.Check();
  surface.CheckConsistent();
  std::vector<std::unique_ptr<SurfaceDistance>> indices;
  for (const TruthSurface& t : truth) {
    indices.push_back(std::make_unique<SurfaceDistance>(t.mesh_in_tool));
  }
  const std::size_t n = surface.vertices.size();
  std::vector<double> signed_mm(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<int> owner(n, -1);
  ParallelFor(
      0, static_cast<std::int64_t>(n),
      [&](std::int64_t i) {
        const Eigen::Vector3d& v = surface.vertices[static_cast<std::size_t>(i)];
        double best = options.max_distance_mm;
        for (std::size_t o = 0; o < indices.size(); ++o) {
          const std::optional<SurfacePoint> p = indices[o]->Closest(v, best);
          if (!p || (owner[static_cast<std::size_t>(i)] >= 0 && p->distance_mm >= best)) continue;
          best = p->distance_mm;
          owner[static_cast<std::size_t>(i)] = static_cast<int>(o);
          signed_mm[static_cast<std::size_t>(i)] = p->signed_distance_mm;
        }
      },
      256);
  ReconstructionEvaluation e;
  e.vertices = n;
  std::vector<std::vector<double>> per_object(truth.size());
  std::vector<double> all;
  e.colored = surface;
  e.colored.vertex_colors.assign(n, Rgb8(128, 128, 128));
  e.colored.vertex_scalars.assign(n, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t i = 0; i < n; ++i) {
    if (owner[i] < 0) {
      ++e.outliers;
      continue;
    }
    per_object[static_cast<std::size_t>(owner[i])].push_back(signed_mm[i]);
    all.push_back(signed_mm[i]);
    e.colored.vertex_colors[i] = ErrorColor(signed_mm[i], options.color_scale_mm);
    e.colored.vertex_scalars[i] = static_cast<float>(signed_mm[i]);
  }
  e.all = ComputeSurfaceErrorStats(all);
  for (std::size_t o = 0; o < truth.size(); ++o) {
    if (per_object[o].empty()) continue;
    const auto [row, size] = TableCell(truth[o].name, truth[o].patient);
    e.objects.push_back(
        {truth[o].name, truth[o].material, row, size, ComputeSurfaceErrorStats(per_object[o])});
  }
  return e;
}

}  // namespace tofnav
