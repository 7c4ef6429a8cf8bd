// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate reconstruction: distance of a reconstructed surface to the simulation's truth.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "commands.hpp"
#include "config_json.hpp"
#include "evaluate.hpp"
#include "progress.hpp"
#include "tofnav/evaluation/reconstruct_evaluate.hpp"
#include "tofnav/mesh/mesh_io.hpp"

namespace tofnav {
namespace {

nlohmann::ordered_json SurfaceStatsJson(const SurfaceErrorStats& s) {
  return {{"count", s.abs_mm.count},
          {"median_mm", s.abs_mm.median},
          {"iqr_mm", s.abs_mm.iqr()},
          {"rms_mm", s.abs_mm.rms},
          {"mean_signed_mm", s.mean_signed_mm},
          {"p95_mm", s.abs_mm.p95},
          {"beyond_3mm_percent", 100.0 * s.beyond_3mm_fraction}};
}

// The paper's Table II: per material, rows H, TP, FP, HS, AVG (over TP, FP, HS), columns
// Size 1..4 with Med and IQR [mm].
void PrintTable(const ReconstructionEvaluation& e) {
  std::set<std::string> materials;
  for (const ObjectError& o : e.objects) {
    if (o.row != "other") materials.insert(o.material);
  }
  for (const std::string& material : materials) {
    std::printf("%-6s %-13s %-13s %-13s %-13s  (%s)\n", "", "Size 1", "Size 2", "Size 3", "Size 4",
                material.c_str());
    std::printf("%-6s", "");
    for (int k = 0; k < 4; ++k) std::printf(" %6s %6s", "Med", "IQR");
    std::printf("\n");
    double sum_med[4] = {}, sum_iqr[4] = {};
    int n[4] = {};
    for (const char* row : {"H", "TP", "FP", "HS"}) {
      std::map<int, const ObjectError*> cells;
      for (const ObjectError& o : e.objects) {
        if (o.material == material && o.row == row) cells[o.size] = &o;
      }
      if (cells.empty()) continue;
      std::printf("%-6s", row);
      for (int k = 1; k <= 4; ++k) {
        const auto it = cells.find(k);
        if (it == cells.end()) {
          std::printf(" %6s %6s", "", "");
          continue;
        }
        std::printf(" %6.2f %6.2f", it->second->stats.abs_mm.median,
                    it->second->stats.abs_mm.iqr());
        if (std::string(row) != "H") {
          sum_med[k - 1] += it->second->stats.abs_mm.median;
          sum_iqr[k - 1] += it->second->stats.abs_mm.iqr();
          ++n[k - 1];
        }
      }
      std::printf("\n");
    }
    if (n[0] + n[1] + n[2] + n[3] > 0) {
      std::printf("%-6s", "AVG");
      for (int k = 0; k < 4; ++k) {
        if (n[k] == 0) {
          std::printf(" %6s %6s", "", "");
        } else {
          std::printf(" %6.2f %6.2f", sum_med[k] / n[k], sum_iqr[k] / n[k]);
        }
      }
      std::printf("\n");
    }
  }
}

}  // namespace

int RunEvaluateReconstruction(int argc, char** argv) {
  CLI::App app{
      "Distance from a reconstructed surface (tool frame) to the true surfaces of a simulation "
      "(truth.json poses, scenario meshes): median and IQR per object in the layout of the "
      "paper's Table II (docs/reconstruction.md)",
      "tofnav evaluate reconstruction"};
  AddConfigOptions(app);
  std::filesystem::path surface_path, truth_dir, scenario_file, colored_path;
  std::string tool_name;
  bool json = false, quiet = false;
  EvaluateReconstructionOptions options;
  app.add_option("surface", surface_path, "reconstructed surface (.ply/.stl/.obj, tool frame)")
      ->required();
  app.add_option("--truth", truth_dir, "simulation output folder (truth.json)")->required();
  app.add_option("--tool-name", tool_name, "reference tool in truth.json (unset: the only one)");
  app.add_option("--scenario", scenario_file, "scenario file of a non-built-in simulation");
  app.add_option("--max-distance-mm", options.max_distance_mm,
                 "vertices farther from every true surface are outliers");
  app.add_option("--colored", colored_path, "write the surface coloured by |error| (PLY)");
  app.add_option("--color-scale-mm", options.color_scale_mm, "|error| shown red");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the result as one JSON object");
  TOFNAV_PARSE(app, argc, argv);

  // Three steps (read the surface, read the truth, evaluate): no finer progress is reported.
  ProgressBar progress("evaluate reconstruction", quiet || json);
  progress.Update(0, 3);
  const TriangleMesh surface = ReadMesh(surface_path);
  progress.Update(1, 3);
  const std::vector<TruthSurface> truth = ReadTruthSurfaces(truth_dir, tool_name, scenario_file);
  progress.Update(2, 3);
  const ReconstructionEvaluation e = EvaluateReconstruction(surface, truth, options);
  if (!colored_path.empty()) WriteMesh(colored_path, e.colored);
  progress.Update(3, 3);
  progress.Finish();
  if (json) {
    nlohmann::ordered_json objects = nlohmann::ordered_json::array();
    for (const ObjectError& o : e.objects) {
      objects.push_back({{"name", o.name},
                         {"material", o.material},
                         {"row", o.row},
                         {"size", o.size},
                         {"stats", SurfaceStatsJson(o.stats)}});
    }
    const nlohmann::ordered_json out{
        {"surface", surface_path.string()}, {"vertices", e.vertices},
        {"outliers", e.outliers},           {"max_distance_mm", options.max_distance_mm},
        {"all", SurfaceStatsJson(e.all)},   {"objects", objects}};
    std::cout << WithOptions(out, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::printf(
      "%zu vertices, %zu outliers (> %.1f mm): median %.3f mm, IQR %.3f mm, RMS %.3f mm, "
      "mean signed %+.3f mm\n\n",
      e.vertices, e.outliers, options.max_distance_mm, e.all.abs_mm.median, e.all.abs_mm.iqr(),
      e.all.abs_mm.rms, e.all.mean_signed_mm);
  PrintTable(e);
  std::printf("\n%-26s %-14s %8s %7s %7s %7s %8s\n", "object", "material", "vertices", "median",
              "IQR", "RMS", "signed");
  for (const ObjectError& o : e.objects) {
    std::printf("%-26s %-14s %8zu %7.3f %7.3f %7.3f %+8.3f\n", o.name.c_str(), o.material.c_str(),
                o.stats.abs_mm.count, o.stats.abs_mm.median, o.stats.abs_mm.iqr(),
                o.stats.abs_mm.rms, o.stats.mean_signed_mm);
  }
  return EXIT_SUCCESS;
}

namespace {
[[maybe_unused]] const bool kReconstructionRegistered = RegisterEvaluator(
    {"reconstruction", "surface error against a simulation's true objects (Table II)",
     RunEvaluateReconstruction});
}  // namespace

}  // namespace tofnav
