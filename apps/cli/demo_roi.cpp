// SPDX-License-Identifier: BSD-3-Clause
// tofnav demo: the head around the skin stickers, for identification and reconstruction.
// TODO(identify branch): the library's automatic head ROI (correction/, io/reconstruct.cpp)
// takes in the headframe board on evd-usecase; switch to it once it excludes the board.
#include <cmath>

#include "demo_stages.hpp"
#include "tofnav/markers/marker_centre.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/tracking/tool_pose.hpp"

namespace tofnav {
namespace {

// Identification's head ROI radius (IdentificationSampling: 130 mm), centred on the stickers
// alone: the headframe's plates and board lie farther from the forehead.
constexpr double kHeadRadiusMm = 130.0;
constexpr double kSameMarkerMm = 6.0;  // a detection this close to a posed headframe marker is it

template <typename T>
void KeepAround(Image<T>& range, const AhatCamera& camera,
                const std::optional<Eigen::Vector3d>& centre, Image<std::uint16_t>* ab) {
  for (int v = 0; v < range.height(); ++v) {
    for (int u = 0; u < range.width(); ++u) {
      const bool keep =
          centre && camera.IsValid(u, v) && range(u, v) > 0 &&
          (camera.PixelRay(u, v).cast<double>() * static_cast<double>(range(u, v)) - *centre)
                  .norm() <= kHeadRadiusMm;
      if (keep) continue;
      range(u, v) = 0;
      if (ab != nullptr) (*ab)(u, v) = 0;
    }
  }
}

}  // namespace

std::optional<Eigen::Vector3d> StickerCentreInAhat(const AhatFrame& frame, const AhatCamera& camera,
                                                   const ToolGeometry& headframe) {
  const std::vector<DetectedMarker> markers = LocateMarkers(frame, camera).markers;
  const ToolPoseResult pose =
      EstimateToolPose(MarkerCentres(markers, headframe.SurfaceToCentreMm()), headframe);
  if (!pose.ahat_from_tool) return std::nullopt;  // the stickers cannot be told apart
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (const DetectedMarker& m : markers) {
    const Eigen::Vector3d p = m.ray_in_ahat * m.surface_range_mm;
    bool on_headframe = false;
    for (const Eigen::Vector3d& h : headframe.markers_in_tool) {
      on_headframe |=
          (*pose.ahat_from_tool * h - p).norm() < kSameMarkerMm + headframe.SurfaceToCentreMm();
    }
    if (on_headframe) continue;
    sum += p;
    ++count;
  }
  if (count == 0) return std::nullopt;
  return sum / count;
}

void KeepHeadAroundStickers(AhatFrame& frame, const AhatCamera& camera,
                            const ToolGeometry& headframe) {
  const std::optional<Eigen::Vector3d> centre = StickerCentreInAhat(frame, camera, headframe);
  KeepAround(frame.range_mm, camera, centre, &frame.ab);
}

void KeepHeadAroundStickers(const AhatFrame& frame, const AhatCamera& camera,
                            const ToolGeometry& headframe, Image<float>& range_mm) {
  KeepAround(range_mm, camera, StickerCentreInAhat(frame, camera, headframe), nullptr);
}

}  // namespace tofnav
