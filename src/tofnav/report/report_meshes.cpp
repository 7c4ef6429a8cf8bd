// SPDX-License-Identifier: BSD-3-Clause
// Internal to report/: the sections with mesh renderings (reconstruction error, registration).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "tofnav/core/statistics.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/report/mesh_render.hpp"
#include "tofnav/report/report_internal.hpp"
#include "tofnav/report/svg_plot.hpp"

namespace tofnav::report_internal {
namespace {

constexpr double kErrorQuantile = 0.95;  // colour scale top when the options leave it automatic
// The registered reconstruction lies on the skin; drawing it this much nearer in the z-buffer
// shows it wherever the two agree to within about a millimetre.
constexpr double kOverlayDepthOffsetMm = 1.5;
const Rgb8 kSkinColour(225, 198, 165);
const Rgb8 kSurfaceColour(40, 110, 220);

struct View {
  const char* name;
  double azimuth_deg;
  double elevation_deg;
};
constexpr View kFront{"front", 0.0, 10.0};
constexpr View kSide{"left side", 90.0, 10.0};
constexpr View kTop{"top", 0.0, 80.0};

// The q-quantile of the finite |errors| (0 when there is none).
double AbsQuantile(const std::vector<float>& errors, double q) {
  std::vector<double> abs;
  for (const float e : errors) {
    if (std::isfinite(e)) abs.push_back(std::abs(e));
  }
  return abs.empty() ? 0.0 : Quantile(abs, q);
}

std::string Renders(std::span<const MeshLayer> layers, std::span<const View> views,
                    const ReportOptions& options, std::string_view what) {
  const RenderOptions render{.width_px = options.render_size_px,
                             .height_px = options.render_size_px};
  std::string s;
  for (const View& view : views) {
    const OrthoCamera camera =
        OrbitCamera(layers, view.azimuth_deg * kDegToRad, view.elevation_deg * kDegToRad, render);
    s += PngImage(RenderMeshes(layers, camera, render),
                  std::string(what) + ", " + view.name + " view");
  }
  return s;
}

// The reconstruction coloured by its per-vertex error, three views, and the colour bar.
std::string ErrorRenders(const Context& c, const Json& stage) {
  const TriangleMesh mesh = ReadMesh(Artefact(c, stage, "mesh_error_ply"));
  std::vector<Rgb8> colours;
  std::string scale;
  if (mesh.vertex_scalars.size() == mesh.vertices.size() && !mesh.vertices.empty()) {
    double top_mm = c.options.error_max_mm > 0.0 ? c.options.error_max_mm
                                                 : AbsQuantile(mesh.vertex_scalars, kErrorQuantile);
    if (!(top_mm > 0.0)) top_mm = 1.0;
    colours.reserve(mesh.vertices.size());
    for (float e : mesh.vertex_scalars) colours.push_back(ErrorColour(std::abs(e) / top_mm));
    scale = Figure("fig-colour-bar", "Colour scale of the renderings: distance to the true head.",
                   SvgColourBar(0.0, top_mm, "|error| [mm]"));
  } else {
    colours = mesh.vertex_colors;  // the file's own colouring (no per-vertex error_mm)
    scale = NotRun("no per-vertex error_mm in the mesh; colours as stored");
  }
  const MeshLayer layers[] = {{.mesh = &mesh, .vertex_colours = colours}};
  const View views[] = {kFront, kSide, kTop};
  return Figure("fig-reconstruction-render",
                "The reconstructed head coloured by its distance to the true surface.",
                Renders(layers, views, c.options, "reconstructed head")) +
         scale;
}

}  // namespace

std::string ReconstructionSection(const Context& c) {
  const Json& stage = c.Stage("reconstruction");
  if (const std::string reason = NotRunReason(stage); !reason.empty()) return NotRun(reason);
  const Json& paper = c.Paper("reconstruction");
  std::string s = Table({"figure", "ours", "paper"},
                        {CompareRow("frames fused", stage, paper, "frames_fused"),
                         CompareRow("frames skipped", stage, paper, "frames_skipped"),
                         CompareRow("voxel [mm]", stage, paper, "voxel_mm"),
                         CompareRow("median error [mm]", stage, paper, "median_mm"),
                         CompareRow("IQR [mm]", stage, paper, "iqr_mm"),
                         CompareRow("95th percentile [mm]", stage, paper, "p95_mm")});
  if (const Json& objects = Field(stage, "objects"); objects.is_array() && !objects.empty()) {
    std::vector<std::vector<std::string>> rows;
    for (const Json& object : objects) {
      const std::string name = Text(object, "name");
      const Json& theirs = PaperEntry(paper, "objects", name, false);
      rows.push_back({EscapeXml(name), Cell(Number(object, "vertices")),
                      Cell(Number(object, "median_mm")), Cell(Number(object, "iqr_mm")),
                      Cell(Number(theirs, "median_mm")), Cell(Number(theirs, "iqr_mm"))});
    }
    s += Table(
        {"object", "vertices", "median [mm]", "IQR [mm]", "paper median [mm]", "paper IQR [mm]"},
        rows);
  }
  s += OrNotRun([&] { return ErrorRenders(c, stage); });
  const Json& histogram = Field(stage, "histogram");
  const std::vector<double> edges = Numbers(histogram, "bin_edges_mm");
  if (edges.size() < 2) return s;
  const PlotSeries series[] = {
      {.name = "vertices", .y = Numbers(histogram, "counts"), .colour = std::string(kAfterColour)}};
  return s + Figure("fig-reconstruction-histogram", "Distance of the reconstruction to the truth.",
                    SvgHistogram(edges, series,
                                 {.title = "Reconstruction error",
                                  .x_label = "error [mm]",
                                  .y_label = "vertices"}));
}

std::string RegistrationSection(const Context& c) {
  const Json& stage = c.Stage("registration");
  if (const std::string reason = NotRunReason(stage); !reason.empty()) return NotRun(reason);
  const Json& paper = c.Paper("registration");
  std::string s =
      Table({"figure", "ours", "paper"},
            {CompareRow("ICP RMSE [mm]", stage, paper, "rmse_mm"),
             CompareRow("inlier fraction", stage, paper, "inlier_fraction"),
             CompareRow("TRE, mean over targets [mm]", stage, paper, "tre_mm"),
             CompareRow("TRE, max [mm]", stage, paper, "tre_max_mm"),
             CompareRow("rotation error [deg]", stage, paper, "rotation_error_deg"),
             CompareRow("translation error [mm]", stage, paper, "translation_error_mm")});
  if (const Json& targets = Field(stage, "targets"); targets.is_array() && !targets.empty()) {
    std::vector<std::vector<std::string>> rows;
    for (const Json& target : targets) {
      rows.push_back({EscapeXml(Text(target, "name")), Cell(Number(target, "tre_mm"))});
    }
    s += Table({"target", "TRE [mm]"}, rows);
  }
  return s + OrNotRun([&] {
           const TriangleMesh skin = ReadMesh(Artefact(c, stage, "skin_ply"));
           const TriangleMesh surface = ReadMesh(Artefact(c, stage, "surface_in_image_ply"));
           const MeshLayer layers[] = {{.mesh = &skin, .colour = kSkinColour},
                                       {.mesh = &surface,
                                        .colour = kSurfaceColour,
                                        .depth_offset_mm = kOverlayDepthOffsetMm}};
           const View views[] = {kFront, kSide};
           return Figure(
               "fig-registration-overlay",
               "CT skin (beige) with the registered reconstruction (blue) in the image frame.",
               Renders(layers, views, c.options, "registration overlay"));
         });
}

}  // namespace tofnav::report_internal
