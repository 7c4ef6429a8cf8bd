// SPDX-License-Identifier: BSD-3-Clause
// The samples of one frame that the identification (Eq. 5-7) needs, extracted once per frame.
#include "tofnav/correction/identification_frame.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/frame_batches.hpp"
#include "tofnav/correction/correct_range.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/surface_costs.hpp"

namespace tofnav {
namespace {

constexpr auto kHead = static_cast<std::uint8_t>(PixelClass::kHead);

// `decoded_ab`: DecodedAb of the frame; the sample's AB is the intensity term's (IntensityAbAt).
std::optional<SurfaceSample> Sample(const Image<float>& surface_range, const AhatFrame& frame,
                                    const Image<float>& decoded_ab, const AhatCamera& camera, int u,
                                    int v, const IdentificationSampling& sampling) {
  const std::optional<PixelNormal> n =
      ComputePixelNormal(surface_range, camera, u, v, sampling.normals);
  if (!n) return std::nullopt;
  return SurfaceSample{camera.PixelRay(u, v), surface_range(u, v), n->incidence_rad,
                       static_cast<float>(IntensityAbAt(frame.ab, decoded_ab, surface_range, u, v,
                                                        sampling.intensity_ab))};
}

// Centroid and principal axes of the points (columns by ascending variance: column 0 is the
// normal of their best plane).
std::pair<Eigen::Vector3d, Eigen::Matrix3d> PrincipalAxes(const Points3d& points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) cov += (p - mean) * (p - mean).transpose();
  return {mean, DecomposeSymmetric(cov).vectors};
}

// Local frame of a patch from its measured points: centroid and PCA axes (z = least variance,
// turned towards the camera).
void SetLocalFrame(MarkerPatch& patch) {
  Points3d points;
  points.reserve(patch.neighbours.size());
  for (const SurfaceSample& s : patch.neighbours) {
    points.push_back((s.ray * s.range_mm).cast<double>());
  }
  const auto [mean, axes] = PrincipalAxes(points);
  Eigen::Vector3d z = axes.col(0);
  if (z.dot(mean) > 0.0) z = -z;
  const Eigen::Vector3d x = axes.col(2);
  patch.local_from_ahat.row(0) = x.transpose();
  patch.local_from_ahat.row(1) = z.cross(x).transpose();
  patch.local_from_ahat.row(2) = z.transpose();
  patch.origin_in_ahat = mean;
}

// Drops what does not belong to the smooth skin around the marker, judged on the measured points
// (no model: the bias moves the surface smoothly, it does not make outliers): neighbours off the
// cubic surface (flying pixels, a sticker seen beyond its retro-reflection cut-off, hair) and
// marker points off the marker's own offset (rim pixels mixed with the skin).
void DropOutliers(MarkerPatch& patch, const IdentificationSampling& sampling) {
  const DepthErrorModel measured;
  for (int pass = 0; pass < 2; ++pass) {
    MarkerPatch probe = patch;
    probe.marker_points.clear();
    for (const SurfaceSample& s : patch.neighbours) {
      probe.marker_points.push_back(CorrectedPoint(s, measured));
    }
    const std::vector<double> d = SmoothnessDistances(probe, measured);
    if (d.size() != patch.neighbours.size()) return;
    const auto [m, spread] = MedianSpread(d);
    const double limit = std::max(3.0 * spread, sampling.min_outlier_mm);
    std::vector<SurfaceSample> kept;
    for (std::size_t i = 0; i < d.size(); ++i) {
      if (std::abs(d[i] - m) <= limit) kept.push_back(patch.neighbours[i]);
    }
    patch.neighbours = std::move(kept);
    if (static_cast<int>(patch.neighbours.size()) < sampling.min_patch_points) return;
  }
  const std::vector<double> d = SmoothnessDistances(patch, measured);
  if (d.size() != patch.marker_points.size()) return;
  const auto [m, spread] = MedianSpread(d);
  const double limit = std::max(3.0 * spread, sampling.min_outlier_mm);
  Points3d kept;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (std::abs(d[i] - m) <= limit) kept.push_back(patch.marker_points[i]);
  }
  patch.marker_points = std::move(kept);
}

// Pixel bounding box (u0, v0, u1, v1) of a marker area (inclusive; never empty: areas have pixels).
std::array<int, 4> PixelBox(const MarkerArea& area) {
  std::array<int, 4> box{area.pixels.front().x(), area.pixels.front().y(), area.pixels.front().x(),
                         area.pixels.front().y()};
  for (const Eigen::Vector2i& px : area.pixels) {
    box[0] = std::min(box[0], px.x()), box[1] = std::min(box[1], px.y());
    box[2] = std::max(box[2], px.x()), box[3] = std::max(box[3], px.y());
  }
  return box;
}

// True when most pixels of a thin ring just outside the marker's transitional band are head
// pixels: a sticker on the skin. A tool's marker sits on its plate, which the head region leaves
// out; its surroundings are not skin, so it says nothing about the skin's smoothness (Eq. 6) nor
// lies on the CT skin (Eq. 5).
bool OnHead(const MarkerArea& area, const FrameSegmentation& seg, const IdentificationSampling& s) {
  const auto [u0, v0, u1, v1] = PixelBox(area);
  const int inner = s.segmentation.transition_dilation_px + 1;
  const int outer = inner + s.marker_ring_px - 1;
  int ring = 0, head = 0;
  for (int v = v0 - outer; v <= v1 + outer; ++v) {
    for (int u = u0 - outer; u <= u1 + outer; ++u) {
      const int du = std::max({u0 - u, u - u1, 0}), dv = std::max({v0 - v, v - v1, 0});
      if (std::max(du, dv) < inner || u < 0 || v < 0 || u >= seg.labels.width() ||
          v >= seg.labels.height()) {
        continue;
      }
      ++ring;
      if (seg.labels(u, v) == kHead) ++head;
    }
  }
  return ring > 0 && head >= s.min_marker_head_fraction * ring;
}

// k of z = c0 + c1 x + c2 y + k (x^2 + y^2) fitted to the points in their own principal plane
// [1/mm]: half the mean curvature of the marker's surface; 0 with fewer than 6 points.
double MarkerCurvaturePerMm(const Points3d& points) {
  if (points.size() < 6) return 0.0;
  const auto [mean, axes] = PrincipalAxes(points);  // column 0: the normal
  Eigen::MatrixXd a(static_cast<Eigen::Index>(points.size()), 4);
  Eigen::VectorXd z(a.rows());
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    const Eigen::Vector3d q = axes.transpose() * (points[static_cast<std::size_t>(i)] - mean);
    a.row(i) << 1.0, q.y(), q.z(), q.y() * q.y() + q.z() * q.z();
    z(i) = q.x();
  }
  return std::abs(a.colPivHouseholderQr().solve(z)(3));
}

// The marker's core pixels: AB at or above sampling.marker_core_ab_fraction of its peak, as the
// tracker's marker ranges and f_rf's stage take them; every pixel when fewer than 3 are.
std::vector<Eigen::Vector2i> CorePixels(const MarkerArea& area, const AhatFrame& frame,
                                        double fraction) {
  double peak = 0.0;
  for (const Eigen::Vector2i& px : area.pixels) {
    peak = std::max(peak, static_cast<double>(frame.ab(px.x(), px.y())));
  }
  std::vector<Eigen::Vector2i> core;
  for (const Eigen::Vector2i& px : area.pixels) {
    if (frame.ab(px.x(), px.y()) >= fraction * peak) core.push_back(px);
  }
  return core.size() >= 3 ? core : area.pixels;
}

// The marker's Eq. (2)-corrected points, at most max_marker_points of its core pixels.
Points3d MarkerPoints(const MarkerArea& area, const AhatFrame& frame, const AhatCamera& camera,
                      const MarkerRangeModel& marker_model,
                      const IdentificationSampling& sampling) {
  const std::vector<Eigen::Vector2i> core =
      CorePixels(area, frame, sampling.marker_core_ab_fraction);
  Points3d points;
  for (int i : EvenSubsample(static_cast<int>(core.size()), sampling.max_marker_points)) {
    const Eigen::Vector2i& px = core[static_cast<std::size_t>(i)];
    const Eigen::Vector3d ray = camera.PixelRay(px.x(), px.y()).cast<double>();
    points.push_back(ray * CorrectMarkerRange(frame.range_mm(px.x(), px.y()), marker_model));
  }
  return points;
}

// f_rf's entrance-angle term (docs/tracking.md 4) on a sticker, flat tape lying on the skin: each
// point's range shortened by gain x the angle between its ray and the skin's normal there. The
// normal is that of the patch's cubic surface below the sticker's centre (the skin within the
// patch radius, hundreds of points); the sticker's own thirty-odd points give a normal whose
// noise always adds to the angle (|beta| folds at 0), which over-corrected far stickers and
// lowered C2 by 6 % on a model-consistent session. The sticker's own plane serves only when the
// patch has too few neighbours for a surface.
void ShortenForEntranceAngle(MarkerPatch& patch, bool patch_has_frame, double gain_mm_per_rad) {
  if (gain_mm_per_rad == 0.0 || patch.marker_points.size() < 3) return;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : patch.marker_points) centre += p;
  centre /= static_cast<double>(patch.marker_points.size());
  const std::optional<Eigen::Vector3d> skin =
      patch_has_frame ? PatchSurfaceNormal(patch, centre, DepthErrorModel{}) : std::nullopt;
  ShortenTapePoints(patch.marker_points,
                    skin ? *skin : ComputePrincipalAxes(patch.marker_points).axes.col(2),
                    gain_mm_per_rad);
}

MarkerPatch MakePatch(const MarkerArea& area, Points3d marker_points,
                      const Image<float>& surface_range, const FrameSegmentation& seg,
                      const AhatFrame& frame, const Image<float>& decoded_ab,
                      const AhatCamera& camera, const IdentificationSampling& sampling) {
  MarkerPatch patch;
  patch.scale_mm = sampling.patch_radius_mm;
  patch.marker_points = std::move(marker_points);
  // Pixel box around the marker that covers the patch radius at the marker's range.
  const auto [u0, v0, u1, v1] = PixelBox(area);
  const double range = std::max(area.centroid_in_ahat.norm(), 100.0);
  const int margin = static_cast<int>(std::ceil(1.3 * 260.0 * sampling.patch_radius_mm / range));
  const double radius_sq = sampling.patch_radius_mm * sampling.patch_radius_mm;
  std::vector<Eigen::Vector2i> candidates;
  for (int v = std::max(0, v0 - margin); v <= std::min(camera.height() - 1, v1 + margin); ++v) {
    for (int u = std::max(0, u0 - margin); u <= std::min(camera.width() - 1, u1 + margin); ++u) {
      if (seg.labels(u, v) != kHead) continue;
      const Eigen::Vector3d p = camera.PixelRay(u, v).cast<double>() * surface_range(u, v);
      if ((p - area.centroid_in_ahat).squaredNorm() <= radius_sq) candidates.emplace_back(u, v);
    }
  }
  for (int i : EvenSubsample(static_cast<int>(candidates.size()), sampling.max_patch_points)) {
    const Eigen::Vector2i& px = candidates[static_cast<std::size_t>(i)];
    const auto s = Sample(surface_range, frame, decoded_ab, camera, px.x(), px.y(), sampling);
    if (s) patch.neighbours.push_back(*s);
  }
  if (static_cast<int>(patch.neighbours.size()) >= sampling.min_patch_points) {
    SetLocalFrame(patch);
    DropOutliers(patch, sampling);
    if (sampling.incidence_from_patch_surface &&
        static_cast<int>(patch.neighbours.size()) >= sampling.min_patch_points) {
      SetIncidenceFromPatchSurface(patch, DepthErrorModel{});
    }
  }
  return patch;
}

}  // namespace

void IdentificationSampling::Check() const {
  segmentation.Check();
  normals.Check();
  intensity_ab.Check();
  if (!(patch_radius_mm > 0.0) || min_patch_points < 10 || max_patch_points < min_patch_points ||
      max_marker_points < 1 || max_head_points < 10) {
    throw std::invalid_argument(
        "IdentificationSampling: need patch_radius_mm > 0, 10 <= min_patch_points <= "
        "max_patch_points, max_marker_points >= 1, max_head_points >= 10");
  }
  if (marker_ring_px < 1 || !(min_marker_head_fraction >= 0.0 && min_marker_head_fraction <= 1.0) ||
      !(max_sticker_curvature_per_mm > 0.0)) {
    throw std::invalid_argument(
        "IdentificationSampling: need marker_ring_px >= 1, min_marker_head_fraction in [0, 1] and "
        "max_sticker_curvature_per_mm > 0");
  }
  if (!(marker_core_ab_fraction >= 0.0 && marker_core_ab_fraction <= 1.0)) {
    throw std::invalid_argument("IdentificationSampling: need marker_core_ab_fraction in [0, 1]");
  }
}

std::pair<double, double> MedianSpread(std::vector<double> values) {
  if (values.empty()) return {0.0, 0.0};
  const auto median = [](std::vector<double>& x) {
    const auto mid = x.begin() + static_cast<std::ptrdiff_t>(x.size() / 2);
    std::nth_element(x.begin(), mid, x.end());
    return *mid;
  };
  const double m = median(values);
  for (double& x : values) x = std::abs(x - m);
  return {m, 1.4826 * median(values)};
}

std::vector<int> EvenSubsample(int count, int max_count) {
  std::vector<int> out;
  if (count <= 0 || max_count <= 0) return out;
  const int n = std::min(count, max_count);
  out.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    out.push_back(static_cast<int>((static_cast<std::int64_t>(i) * count) / n));
  }
  return out;
}

std::vector<IdentificationFrame> PrepareIdentificationFrames(
    std::span<const int> indices, const std::function<AhatFrame(int)>& read,
    const AhatCamera& camera, const MarkerRangeModel& marker_model,
    const IdentificationSampling& sampling,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  constexpr std::size_t kBatch = 16;
  std::vector<IdentificationFrame> frames(indices.size());
  ForEachInBatches<AhatFrame>(
      indices.size(), kBatch, [&](std::size_t i) { return read(indices[i]); },
      [&](AhatFrame& frame, std::size_t i) {
        frames[i] = PrepareIdentificationFrame(frame, camera, marker_model, indices[i], sampling);
      },
      [&](AhatFrame&, std::size_t i) {
        const bool batch_done = (i + 1) % kBatch == 0 || i + 1 == indices.size();
        if (progress && batch_done) progress(i + 1, indices.size());
      });
  return frames;
}

Eigen::Vector3d CorrectedPoint(const SurfaceSample& sample, const DepthErrorModel& model) {
  return sample.ray.cast<double>() *
         model.CorrectRangeMm(sample.range_mm, sample.incidence_rad, sample.ab);
}

IdentificationFrame PrepareIdentificationFrame(const AhatFrame& frame, const AhatCamera& camera,
                                               const MarkerRangeModel& marker_model, int index,
                                               const IdentificationSampling& sampling) {
  sampling.Check();
  IdentificationFrame out;
  out.index = index;
  if (frame.world_from_rig) out.world_from_ahat = *frame.world_from_rig * camera.rig_from_ahat();
  const FrameSegmentation seg = SegmentFrame(frame, camera, sampling.segmentation);
  Image<float> surface_range = SurfaceRange(RangeAsFloat(frame.range_mm), seg);
  if (sampling.multipath.enabled) {
    // Only head pixels are sampled (the patches' neighbours and the ICP's points).
    Image<std::uint8_t> wanted(surface_range.width(), surface_range.height(), 0);
    for (std::size_t i = 0; i < wanted.size(); ++i) {
      wanted.pixels()[i] = seg.labels.pixels()[i] == kHead;
    }
    const Image<float> delay = SkinScatterDelay(wanted, sampling.multipath.skin_delay_mm);
    surface_range =
        RemoveMultipath(surface_range, frame.ab, camera, sampling.multipath, sampling.normals,
                        {.wanted = &wanted,
                         .ab_square_code = frame.ab_lossy,
                         .scatter_delay_mm = delay.size() > 0 ? &delay : nullptr});
  }
  const Image<float> decoded_ab = sampling.intensity_ab.window_mean
                                      ? DecodedAb(frame.ab, frame.ab_lossy)
                                      : Image<float>();  // IntensityAbAt reads frame.ab then
  for (const MarkerArea& area : seg.markers) {
    if (!OnHead(area, seg, sampling)) continue;
    Points3d points = MarkerPoints(area, frame, camera, marker_model, sampling);
    if (MarkerCurvaturePerMm(points) > sampling.max_sticker_curvature_per_mm) {
      ++out.curved_markers;  // a tool's sphere against the skin, not a sticker
      continue;
    }
    MarkerPatch patch =
        MakePatch(area, std::move(points), surface_range, seg, frame, decoded_ab, camera, sampling);
    ShortenForEntranceAngle(patch,
                            static_cast<int>(patch.neighbours.size()) >= sampling.min_patch_points,
                            marker_model.entrance_gain_mm_per_rad);
    out.marker_points.insert(out.marker_points.end(), patch.marker_points.begin(),
                             patch.marker_points.end());
    if (static_cast<int>(patch.neighbours.size()) >= sampling.min_patch_points) {
      out.markers.push_back(std::move(patch));
    }
  }
  // Head samples on an even pixel grid, as many as max_head_points allows.
  if (seg.head_pixels > 0) {
    const int stride = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(seg.head_pixels) /
                                                              sampling.max_head_points)));
    for (int v = 0; v < camera.height(); v += stride) {
      for (int u = 0; u < camera.width(); u += stride) {
        if (seg.labels(u, v) != kHead) continue;
        const auto s = Sample(surface_range, frame, decoded_ab, camera, u, v, sampling);
        if (s) out.head.push_back(*s);
      }
    }
  }
  return out;
}

}  // namespace tofnav
