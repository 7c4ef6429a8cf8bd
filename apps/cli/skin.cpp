// SPDX-License-Identifier: BSD-3-Clause
// tofnav skin: the outer skin surface of a CT or MR volume as a mesh (docs/registration.md).
#include "tofnav/imaging/skin.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>

#include "commands.hpp"
#include "config_json.hpp"
#include "progress.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {

int RunSkin(int argc, char** argv) {
  CLI::App app{
      "Extract the outer skin surface of a head volume (NRRD, NIfTI, DICOM folder, "
      ".inv3) as a mesh in LPS mm (docs/registration.md)",
      "tofnav skin"};
  AddConfigOptions(app);
  std::filesystem::path volume_path, out_path;
  std::optional<double> threshold;
  bool ras = false, all_components = false, keep_cavities = false, quiet = false, json = false;
  SkinOptions options;
  app.add_option("volume", volume_path, "CT/MR volume: .nrrd, .nhdr, .nii[.gz], .inv3, DICOM dir")
      ->required();
  app.add_option("--out", out_path, "output mesh (.ply, .stl or .obj)")->required();
  app.add_option("--threshold", threshold,
                 "iso value in the volume's unit (unset: -300 HU for CT, Otsu for MR)");
  app.add_option("--smooth", options.smoothing_iterations, "Taubin smoothing passes")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--decimate", options.decimation_cell_mm, "vertex clustering cell [mm] (0: off)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--opening", options.opening_radius_mm,
                 "radius [mm] of the ball that must pass an opening for the air behind it to "
                 "count as outside (0: off)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--ras", ras, "write RAS coordinates (3D Slicer's world) instead of LPS");
  app.add_flag("--all-components", all_components,
               "mesh every component above the threshold (else the largest only)");
  app.add_flag("--keep-cavities", keep_cavities,
               "do not fill airways, sinuses and the air behind narrow openings (--opening)");
  app.add_flag("-q,--quiet", quiet, "no progress bar, no summary");
  app.add_flag("--json", json, "print the summary as one JSON object");
  TOFNAV_PARSE(app, argc, argv);

  options.threshold = threshold;
  options.keep_largest_component = !all_components;
  options.fill_cavities = !keep_cavities;
  // Three steps (read, extract, write): the library calls report no finer progress.
  ProgressBar progress("skin", quiet || json);
  const auto start = std::chrono::steady_clock::now();
  progress.Update(0, 3);
  const CtVolume volume = ReadVolume(volume_path);
  progress.Update(1, 3);
  const auto read = std::chrono::steady_clock::now();
  SkinResult skin;
  try {
    skin = ExtractSkin(volume, options);
  } catch (const PreconditionError& e) {  // no skin in this volume: say which file
    throw std::runtime_error(volume_path.string() + ": " + e.what());
  }
  progress.Update(2, 3);
  const auto extracted = std::chrono::steady_clock::now();
  if (ras) skin.mesh = MeshLpsToRas(skin.mesh);
  WriteMesh(out_path, skin.mesh);
  progress.Update(3, 3);
  progress.Finish();
  const double read_s = std::chrono::duration<double>(read - start).count();
  const double extract_s = std::chrono::duration<double>(extracted - read).count();
  if (json) {
    const nlohmann::ordered_json summary{{"volume", volume_path.string()},
                                         {"out", out_path.string()},
                                         {"frame", ras ? "RAS" : "LPS"},
                                         {"threshold", skin.threshold},
                                         {"threshold_source", skin.threshold_source},
                                         {"mask_components", skin.mask_components},
                                         {"kept_voxels", skin.kept_voxels},
                                         {"filled_voxels", skin.filled_voxels},
                                         {"dropped_triangles", skin.dropped_triangles},
                                         {"vertices", skin.mesh.vertices.size()},
                                         {"triangles", skin.mesh.triangles.size()},
                                         {"area_mm2", skin.mesh.SurfaceAreaMm2()},
                                         {"read_s", read_s},
                                         {"extract_s", extract_s}};
    std::cout << WithOptions(summary, app).dump(2) << "\n";
  } else if (!quiet) {
    std::cout << "skin of " << volume_path.string() << " at " << skin.threshold << " ("
              << skin.threshold_source << "): " << skin.mesh.vertices.size() << " vertices, "
              << skin.mesh.triangles.size() << " triangles, " << skin.mask_components
              << " mask components (largest kept), " << skin.filled_voxels
              << " cavity voxels filled; " << (ras ? "RAS" : "LPS") << " mm -> "
              << out_path.string() << " (read " << read_s << " s, extract " << extract_s << " s)\n";
  }
  return EXIT_SUCCESS;
}

}  // namespace tofnav
