// SPDX-License-Identifier: BSD-3-Clause
// `tofnav evaluate reconstruction`: surface error against a simulation's true objects (Table II).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/core/statistics.hpp"
#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

/// One true surface of a simulation, in the reference tool's frame.
struct TruthSurface {
  std::string name;      // object name in truth.json
  std::string material;  // material name
  bool patient = false;  // the patient's skin (Table II row H)
  TriangleMesh mesh_in_tool;
};

/// The objects of a simulation output folder that are rigid with `tool_name` (within 0.01 mm
/// over every frame), posed in that tool's frame from truth.json. Meshes come from the session's
/// meshes/<object>.ply files (truth.json files "mesh:<object>"; `scenario_file` is then unused).
/// A session written before those files rebuilds the scenario: the built-in named in truth.json,
/// or `scenario_file` when given; without either, only the patient's skin (skin_truth.ply).
/// `tool_name` empty: the only tool of the run. Throws IoError on a malformed truth.json or a
/// mesh file that is missing or whose vertex or triangle count differs from truth.json's, and
/// PreconditionError on an unknown tool or a scenario whose meshes do not match truth.json.
std::vector<TruthSurface> ReadTruthSurfaces(const std::filesystem::path& truth_dir,
                                            const std::string& tool_name = "",
                                            const std::filesystem::path& scenario_file = {});

/// Signed vertex-to-truth distances: the Summary of their absolute values, their signed mean.
struct SurfaceErrorStats {
  Summary abs_mm;  // of |distance| (count: the distances)
  double mean_signed_mm = 0.0;
  double beyond_3mm_fraction = 0.0;  // share of |distance| > 3 mm
};
SurfaceErrorStats ComputeSurfaceErrorStats(const std::vector<double>& signed_distances_mm);

/// Table II rows: "H" head, "TP", "FP", "HS" test shapes ("<shape>_size<k>" names), else "other".
struct ObjectError {
  std::string name;
  std::string material;
  std::string row;  // H, TP, FP, HS or other
  int size = 1;     // Table II size column 1..4
  SurfaceErrorStats stats;
};

struct EvaluateReconstructionOptions {
  /// Vertices farther than this from every true surface are outliers: counted, not in the stats.
  double max_distance_mm = 10.0;
  double color_scale_mm = 2.0;  // |error| at which the colour saturates (red)
  void Check() const;           // throws PreconditionError naming the bad field
};

struct ReconstructionEvaluation {
  SurfaceErrorStats all;             // every matched vertex
  std::vector<ObjectError> objects;  // objects with at least one vertex, in truth order
  std::size_t vertices = 0;
  std::size_t outliers = 0;  // farther than max_distance_mm from every surface
  TriangleMesh colored;      // the surface with colours and signed error_mm scalars
};

/// Assigns each vertex of `surface` (in the tool frame) to its nearest true surface and reports
/// the distance statistics per object and overall.
ReconstructionEvaluation EvaluateReconstruction(const TriangleMesh& surface,
                                                const std::vector<TruthSurface>& truth,
                                                const EvaluateReconstructionOptions& options = {});

}  // namespace tofnav
