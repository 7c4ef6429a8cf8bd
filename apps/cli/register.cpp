// SPDX-License-Identifier: BSD-3-Clause
// tofnav register: tool_from_image from the reconstructed head surface and the CT skin (or from
// paired fiducials), with quality figures and refusal (docs/registration.md).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.hpp"
#include "config_json.hpp"
#include "method_option.hpp"
#include "progress.hpp"
#include "tofnav/casefile/markups_read.hpp"
#include "tofnav/casefile/transform_io.hpp"
#include "tofnav/imaging/skin.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/registration/paired_points.hpp"
#include "tofnav/registration/register_surface.hpp"

namespace tofnav {
namespace {

constexpr int kExitRefused = 2;  // documented: the registration ran but failed a threshold

struct Report {
  std::string method;  // "surface" or "paired-points"
  bool accepted = false;
  std::string status = "ok";
  std::string message;
  Rigid3d tool_from_image;
  nlohmann::ordered_json figures = nlohmann::ordered_json::object();
  std::vector<std::pair<std::string, double>> target_tre_mm;
};

/// Paired-point registration of image fiducials onto tool fiducials (same order).
Report RegisterFiducials(const std::vector<Eigen::Vector3d>& tool_points,
                         const std::vector<Eigen::Vector3d>& image_points,
                         const std::vector<Trajectory>& plan, double max_fre_mm,
                         double max_tre_mm) {
  const PairedPointResult paired = RegisterPairedPoints(image_points, tool_points);
  Report report;
  report.method = "paired-points";
  report.tool_from_image = paired.target_from_source;
  report.figures["fre_rms_mm"] = paired.fre_rms_mm;
  report.figures["fiducials"] = image_points.size();
  const double fle_mm = EstimateFleFromFreMm(paired.fre_rms_mm, image_points.size());
  double max_tre = 0.0;
  for (const Trajectory& t : plan) {
    const double tre = PredictFiducialTreMm(image_points, fle_mm, t.target_lps_mm);
    report.target_tre_mm.emplace_back(t.name, tre);
    max_tre = std::max(max_tre, tre);
  }
  report.figures["max_predicted_tre_mm"] = max_tre;
  report.accepted = paired.fre_rms_mm <= max_fre_mm && max_tre <= max_tre_mm;
  report.status = paired.fre_rms_mm > max_fre_mm ? "high-fre"
                  : max_tre > max_tre_mm         ? "high-predicted-tre"
                                                 : "ok";
  report.message = "FRE " + std::to_string(paired.fre_rms_mm) + " mm over " +
                   std::to_string(image_points.size()) + " fiducials (max " +
                   std::to_string(max_fre_mm) + "), predicted TRE " + std::to_string(max_tre) +
                   " mm (max " + std::to_string(max_tre_mm) + ")";
  return report;
}

Report RegisterSurfaces(const std::filesystem::path& reconstruction_path,
                        const std::filesystem::path& skin_path, bool skin_ras,
                        const std::vector<Trajectory>& plan, const RegisterSurfaceOptions& options,
                        const std::optional<Rigid3d>& guess) {
  const PointCloud reconstruction = ReadPointCloud(reconstruction_path);
  TriangleMesh skin = ReadMesh(skin_path);
  if (skin_ras) skin = MeshLpsToRas(skin);  // the same flip takes RAS back to LPS
  const SurfaceIndex skin_index = skin.triangles.empty() && skin.vertex_normals.empty()
                                      ? SurfaceIndex(PointCloud{skin.vertices})
                                      : SurfaceIndex(skin);
  std::vector<Eigen::Vector3d> targets;
  for (const Trajectory& t : plan) targets.push_back(t.target_lps_mm);
  const RegisterSurfaceResult result =
      RegisterSurface(reconstruction, skin_index, targets, options, guess);
  const RegistrationQuality& q = result.quality;
  Report report;
  report.method = "surface";
  report.accepted = q.accepted();
  report.status = ToString(q.status);
  report.message = q.message;
  report.tool_from_image = result.tool_from_image;
  report.figures["rmse_mm"] = q.rmse_mm;
  report.figures["inlier_fraction"] = q.inlier_fraction;
  report.figures["residual_sigma_mm"] = q.residual_sigma_mm;
  report.figures["rotation_conditioning"] = q.conditioning.rotation;
  report.figures["translation_conditioning"] = q.conditioning.translation;
  report.figures["ambiguity"] = q.ambiguity;
  report.figures["ambiguity_shift_mm"] = q.ambiguity_shift_mm;
  report.figures["effective_samples"] = q.effective_samples;
  report.figures["max_predicted_tre_mm"] = q.max_predicted_tre_mm;
  report.figures["icp_iterations"] = result.icp.iterations;
  report.figures["icp_unsettled_mm"] = result.quality.unsettled_mm;
  report.figures["coarse_hypotheses"] = result.coarse.hypotheses;
  report.figures["reconstruction_points"] = reconstruction.size();
  report.figures["skin_points"] = skin_index.size();
  for (std::size_t i = 0; i < plan.size() && i < q.predicted_tre_mm.size(); ++i) {
    report.target_tre_mm.emplace_back(plan[i].name, q.predicted_tre_mm[i]);
  }
  return report;
}

}  // namespace

int RunRegister(int argc, char** argv) {
  CLI::App app{
      "Register the CT skin to the reconstructed head surface (automatic coarse "
      "alignment, robust point-to-plane ICP) or to paired fiducials: writes "
      "tool_from_image, refuses (exit 2) when the quality is below the thresholds "
      "(docs/registration.md)",
      "tofnav register"};
  AddConfigOptions(app);
  std::filesystem::path reconstruction_path, skin_path, out_path, plan_path, tfm_path, txt_path;
  std::vector<std::filesystem::path> fiducials;
  std::filesystem::path guess_path;
  bool skin_ras = false, force = false, quiet = false, json = false;
  double max_fre_mm = 2.0;
  RegisterSurfaceOptions options;
  Method method = Method::kTofnav;
  AddMethodOption(app, method);
  RegistrationThresholds& t = options.thresholds;
  app.add_option("reconstruction", reconstruction_path,
                 "reconstructed head surface in tool (.ply)");
  app.add_option("skin", skin_path, "CT skin surface in image, LPS (.ply/.stl/.obj; tofnav skin)");
  app.add_option("--out", out_path, "tool_from_image: .json (frames named), .tfm or .txt")
      ->required();
  app.add_option("--plan", plan_path, "planned trajectories (.mrk.json, .fcsv): TRE at targets");
  app.add_option("--tfm", tfm_path, "also write a 3D Slicer .tfm (ToParent = tool_from_image)");
  app.add_option("--txt", txt_path, "also write the plain-text 4x4 matrix");
  app.add_option("--fiducials", fiducials,
                 "TOOL IMAGE markups of paired fiducials (same order); with surfaces: the start")
      ->expected(2);
  app.add_option("--guess", guess_path, "a tool_from_image transform file to start from");
  app.add_flag("--skin-ras", skin_ras, "the skin file is in RAS (tofnav skin --ras)");
  app.add_option("--max-rmse", t.max_rmse_mm, "refuse above this RMSE [mm]");
  app.add_option("--min-inliers", t.min_inlier_fraction, "refuse below this inlier fraction");
  app.add_option("--min-conditioning", t.min_rotation_conditioning,
                 "refuse below this rotation conditioning");
  app.add_option("--max-tre", t.max_predicted_tre_mm, "refuse above this predicted TRE [mm]");
  app.add_option("--max-ambiguity", t.max_ambiguity,
                 "refuse above this cost ratio to the best distinct alternative pose (the floor: "
                 "raised for large surfaces by --ambiguity-z)");
  app.add_option("--ambiguity-z", t.ambiguity_z,
                 "an alternative is distinct when its cost exceeds the best's by more than this "
                 "many standard errors, z sqrt(2 / N_eff) (docs/registration.md)");
  app.add_option("--max-fre", max_fre_mm, "paired points: refuse above this FRE [mm]");
  app.add_option("--sample-spacing-mm", options.sample_spacing_mm,
                 "voxel subsampling of the reconstruction for the fine ICP [mm]")
      ->check(CLI::PositiveNumber);
  std::string loss = "huber";
  app.add_option("--loss", loss, "ICP robust loss: huber, tukey or squared")
      ->check(CLI::IsMember({"huber", "tukey", "squared"}));
  app.add_flag("--force", force, "write the transform even when refused (status in the JSON)");
  app.add_flag("-q,--quiet", quiet, "no progress bar, no report");
  app.add_flag("--json", json, "print the report as one JSON object");
  TOFNAV_PARSE(app, argc, argv);
  options.icp.loss = loss == "tukey"     ? RobustLoss::kTukey
                     : loss == "squared" ? RobustLoss::kSquared
                                         : RobustLoss::kHuber;

  const bool surfaces = !reconstruction_path.empty() && !skin_path.empty();
  if (method == Method::kPaper) {
    if (surfaces && guess_path.empty() && fiducials.empty()) {
      throw std::runtime_error(
          "--method paper: the paper's ICP starts from the user's coarse placement in 3D Slicer; "
          "give it as --guess T (a tool_from_image transform file)");
    }
    UsePaperRegistration(options);
  }
  if (!surfaces && fiducials.empty()) {
    throw std::runtime_error("give <reconstruction.ply> <skin.ply>, or --fiducials TOOL IMAGE");
  }
  const std::vector<Trajectory> plan =
      plan_path.empty() ? std::vector<Trajectory>{} : ReadTrajectories(plan_path);
  // One step per registration (fiducials, surfaces) and one for writing: the library calls
  // report no finer progress.
  const std::size_t steps = (fiducials.empty() ? 1u : 2u) + (surfaces ? 1u : 0u);
  std::size_t done = 0;
  ProgressBar progress("register", quiet || json);
  progress.Update(0, steps);
  const auto start = std::chrono::steady_clock::now();
  std::optional<Rigid3d> guess;
  if (!guess_path.empty()) guess = ReadTransform(guess_path).target_from_source;
  Report report;
  if (!fiducials.empty()) {
    report = RegisterFiducials(ReadMarkupPoints(fiducials[0]), ReadMarkupPoints(fiducials[1]), plan,
                               max_fre_mm, t.max_predicted_tre_mm);
    guess = report.tool_from_image;
    progress.Update(++done, steps);
  }
  if (surfaces) {
    const double fre_mm = report.figures.value("fre_rms_mm", -1.0);
    report = RegisterSurfaces(reconstruction_path, skin_path, skin_ras, plan, options, guess);
    if (fre_mm >= 0.0) report.figures["start_fiducial_fre_rms_mm"] = fre_mm;
    progress.Update(++done, steps);
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  NamedTransform transform{"tool", "image", report.tool_from_image, {}};
  for (const auto& [name, value] : report.figures.items()) {
    if (value.is_number()) transform.figures.emplace_back(name, value.get<double>());
  }
  transform.figures.emplace_back("accepted", report.accepted ? 1.0 : 0.0);
  const bool write = report.accepted || force;
  if (write) {
    WriteTransform(out_path, transform);
    if (!tfm_path.empty()) WriteTransform(tfm_path, transform);
    if (!txt_path.empty()) WriteTransform(txt_path, transform);
  }
  progress.Update(steps, steps);
  progress.Finish();
  if (json) {
    nlohmann::ordered_json out{{"method", report.method},
                               {"accepted", report.accepted},
                               {"status", report.status},
                               {"message", report.message},
                               {"written", write},
                               {"elapsed_s", elapsed_s},
                               {"figures", report.figures},
                               {"tool_from_image", nlohmann::ordered_json::array()},
                               {"targets", nlohmann::ordered_json::array()}};
    const Eigen::Matrix4d m = report.tool_from_image.ToMatrix();
    for (int r = 0; r < 4; ++r)
      out["tool_from_image"].push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
    for (const auto& [name, tre] : report.target_tre_mm) {
      out["targets"].push_back({{"name", name}, {"predicted_tre_mm", tre}});
    }
    std::cout << WithOptions(out, app).dump(2) << "\n";
  } else if (!quiet) {
    std::cout << report.method << " registration " << (report.accepted ? "accepted" : "REFUSED")
              << " (" << report.status << "): " << report.message << " [" << elapsed_s << " s]\n";
    for (const auto& [name, value] : report.figures.items()) {
      std::cout << "  " << name << " = " << value << "\n";
    }
    for (const auto& [name, tre] : report.target_tre_mm) {
      std::cout << "  predicted TRE at " << name << " = " << tre << " mm\n";
    }
    if (write) std::cout << "wrote tool_from_image to " << out_path.string() << "\n";
  }
  if (!report.accepted) {
    std::cerr << "tofnav register: refused (" << report.status << "): " << report.message
              << (write ? " (written anyway: --force)" : "; nothing written") << "\n";
    return kExitRefused;
  }
  return EXIT_SUCCESS;
}

}  // namespace tofnav
