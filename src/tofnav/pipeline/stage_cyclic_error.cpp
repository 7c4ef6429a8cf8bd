// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/pipeline/stage_cyclic_error.hpp"

#include <cmath>
#include <stdexcept>

#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

void PlateSampleOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("PlateSampleOptions: ") + what);
  };
  require(plate_radius_mm > 0.0, "plate_radius_mm must be > 0");
  require(edge_margin_mm >= 0.0 && marker_margin_mm >= 0.0, "margins must be >= 0");
  require(pixel_stride >= 1, "pixel_stride must be >= 1");
  require(split_jump_mm > 0.0, "split_jump_mm must be > 0");
}

std::vector<PlateRangeSample> CollectPlateSamples(const MarkerSource& source,
                                                  const std::vector<ToolPoseRecord>& poses,
                                                  const ToolGeometry& structure,
                                                  const PlateSampleOptions& options) {
  options.Check();
  structure.Check();
  Eigen::Vector3d centre_in_tool = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& m : structure.markers_in_tool) centre_in_tool += m;
  centre_in_tool /= static_cast<double>(structure.markers_in_tool.size());
  const Eigen::Vector3d normal_in_tool = MarkerPlaneNormal(structure);
  const double inner_radius_mm = options.plate_radius_mm - options.edge_margin_mm;
  const double marker_clear_mm = 0.5 * structure.marker_diameter_mm + options.marker_margin_mm;
  const AhatCamera& camera = *source.camera;

  std::vector<PlateRangeSample> samples;
  int run = -1;
  std::optional<Eigen::Vector3d> last_position;
  for (const ToolPoseRecord& record : poses) {
    if (!record.ahat_from_tool) continue;
    const Rigid3d& ahat_from_tool = *record.ahat_from_tool;
    if (!last_position ||
        (ahat_from_tool.translation - *last_position).norm() > options.split_jump_mm) {
      ++run;
    }
    last_position = ahat_from_tool.translation;
    const AhatFrame frame = source.recording->ReadFrame(static_cast<std::size_t>(record.frame));
    if (frame.depth_step_mm > 2.0) continue;  // SAME + H26x: 4 mm steps, lossy
    const Eigen::Vector3d normal = ahat_from_tool.rotation * normal_in_tool;
    const Eigen::Vector3d centre = ahat_from_tool * centre_in_tool;
    const Rigid3d tool_from_ahat = ahat_from_tool.Inverse();
    for (int v = 0; v < frame.range_mm.height(); v += options.pixel_stride) {
      for (int u = 0; u < frame.range_mm.width(); u += options.pixel_stride) {
        const double range_mm = frame.range_mm(u, v), ab = frame.ab(u, v);
        if (range_mm <= 0.0 || ab <= 0.0 || !camera.IsValid(u, v)) continue;
        const Eigen::Vector3d ray = camera.PixelRay(u, v).cast<double>();
        const double cosine = normal.dot(ray);
        if (std::abs(cosine) < 0.2) continue;  // grazing: 78 deg and more
        const double plane_range_mm = normal.dot(centre) / cosine;
        if (!(plane_range_mm > 0.0)) continue;
        const Eigen::Vector3d on_plate = tool_from_ahat * (plane_range_mm * ray);
        if ((on_plate - centre_in_tool).norm() > inner_radius_mm) continue;
        bool clear = true;
        for (const Eigen::Vector3d& m : structure.markers_in_tool) {
          clear = clear && (on_plate - m).norm() > marker_clear_mm;
        }
        if (!clear) continue;
        samples.push_back({.measured_range_mm = range_mm,
                           .plane_range_mm = plane_range_mm,
                           .incidence_rad = std::acos(std::min(1.0, std::abs(cosine))),
                           .ab = ab,
                           .run = run});
      }
    }
  }
  return samples;
}

StageCyclicErrorInfo StageCyclicErrorOf(const PlateCyclicFit& fit) {
  return {fit.cyclic, fit.amplitude_sd_mm, fit.phase_sd_rad, static_cast<int>(fit.samples),
          fit.span_mm};
}

}  // namespace tofnav
