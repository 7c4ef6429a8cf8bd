// SPDX-License-Identifier: BSD-3-Clause
// Damaged markers, the noise-model check and leave-one-out (docs/tracking.md section 6).
#include "tofnav/tracking/robust_pose.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rigid_fit.hpp"
#include "tofnav/tracking/ray_pose.hpp"

namespace tofnav {
namespace {

// Chi-square quantile for k degrees of freedom at the standard-normal quantile z
// (Wilson-Hilferty: (chi2 / k)^(1/3) is nearly normal with mean 1 - 2 / 9k, variance 2 / 9k).
double Chi2Quantile(int k, double z) {
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + z * std::sqrt(a), 3);
}

struct Sigmas {
  double lateral_mm = 1.0;  // as a whole blob's
  double range_mm = 1.0;
};

class Fitter {
 public:
  Fitter(std::span<const DetectedMarker> detections, std::span<const int> marker_detection,
         const ToolGeometry& tool, const Points3d& centres, const PoseRefinementOptions& refinement,
         const RobustPoseOptions& options)
      : detections_(detections),
        marker_detection_(marker_detection),
        tool_(tool),
        centres_(centres),
        refinement_(refinement),
        sigmas_(marker_detection.size()) {
    std::vector<double> ranges;
    for (std::size_t k = 0; k < marker_detection.size(); ++k) {
      if (marker_detection[k] < 0) continue;
      const DetectedMarker& d = Detection(k);
      Sigmas& s = sigmas_[k];
      if (!(d.pixel_pitch_rad > 0.0)) {
        s = {options.isotropic_sigma_mm, options.isotropic_sigma_mm};
        continue;
      }
      s.lateral_mm = refinement.lateral_sigma_px * d.pixel_pitch_rad * Centre(k).norm();
      ranges.clear();
      for (const CoreSample& c : d.core) ranges.push_back(c.range_mm);
      s.range_mm = MeanSigmaMm(ranges, options.range_sigma_floor_mm);
    }
  }

  // Kabsch on the markers in `in`, then the refinement (kept when it converges).
  Rigid3d Fit(const std::vector<bool>& in) const {
    Points3d source, target;
    std::vector<int> subset(marker_detection_.size(), -1);
    for (std::size_t k = 0; k < in.size(); ++k) {
      if (!in[k]) continue;
      source.push_back(tool_.markers_in_tool[k]);
      target.push_back(Centre(k));
      subset[k] = marker_detection_[k];
    }
    const Rigid3d kabsch = FitRigid(source, target).target_from_source;
    if (!refinement_.enabled) return kabsch;
    const std::optional<Rigid3d> refined =
        RefineToolPose(detections_, subset, tool_, centres_, kabsch, refinement_, truncation_mm_);
    return refined ? *refined : kabsch;
  }

  // Weighs each matched blob by its area against its siblings' at `pose`; true when any blob of
  // `in` counts as truncated (then the pose is worth refitting).
  bool SetTruncation(const std::vector<bool>& in, const Rigid3d& pose,
                     const BlobTruncationOptions& options) {
    truncation_mm_ =
        TruncationLateralSigmasMm(detections_, marker_detection_, tool_, centres_, pose, options);
    for (std::size_t k = 0; k < in.size(); ++k) {
      if (in[k] && truncation_mm_[k] > 0.0) return true;
    }
    return false;
  }

  // Marker k's variance across its ray: a whole blob's plus its truncation's.
  double Lateral2(std::size_t k) const {
    const double extra = truncation_mm_.empty() ? 0.0 : truncation_mm_[k];
    return sigmas_[k].lateral_mm * sigmas_[k].lateral_mm + extra * extra;
  }

  // Squared residual of marker k at `pose`, across and along its ray, in sigmas.
  double Chi2(std::size_t k, const Rigid3d& pose) const {
    const Eigen::Vector3d e = pose * tool_.markers_in_tool[k] - Centre(k);
    const Eigen::Vector3d ray = Detection(k).ray_in_ahat.normalized();
    const double along = ray.dot(e);
    const double across2 = (e - along * ray).squaredNorm();
    const double range_mm = sigmas_[k].range_mm;
    return across2 / Lateral2(k) + along * along / (range_mm * range_mm);
  }

  double Chi2(const std::vector<bool>& in, const Rigid3d& pose) const {
    double sum = 0.0;
    for (std::size_t k = 0; k < in.size(); ++k) {
      if (in[k]) sum += Chi2(k, pose);
    }
    return sum;
  }

  // Sets r's per-axis sds from the covariance of `pose` on the markers in `in`: lateral sigmas
  // as the check's, range sigmas from the one-pixel noise law over the blob's core pixels.
  void SetSds(const std::vector<bool>& in, const Rigid3d& pose, const RobustPoseOptions& options,
              RobustPose& r) const {
    Points3d markers;
    std::vector<RayRangeObservation> observations;
    for (std::size_t k = 0; k < in.size(); ++k) {
      if (!in[k]) continue;
      const DetectedMarker& d = Detection(k);
      const double range_mm = Centre(k).norm();
      const double pixel_sigma_mm =
          options.pixel_range_sigma_mm *
          std::pow(range_mm / options.pixel_range_sigma_at_mm, options.pixel_range_sigma_exponent);
      const double pixels = static_cast<double>(std::max<std::size_t>(1, d.core.size()));
      markers.push_back(tool_.markers_in_tool[k]);
      observations.push_back(
          {.ray_in_ahat = d.ray_in_ahat.norm() > 0.5 ? d.ray_in_ahat : Centre(k).normalized(),
           .range_mm = range_mm,
           .lateral_sigma_mm = std::sqrt(Lateral2(k)),
           .range_sigma_mm =
               d.pixel_pitch_rad > 0.0 ? pixel_sigma_mm / std::sqrt(pixels) : sigmas_[k].range_mm});
    }
    const Matrix6d covariance = RayRangePoseCovariance(markers, observations, pose);
    if (!covariance.allFinite()) return;
    const double rotation_var = covariance.topLeftCorner<3, 3>().trace() / 3.0;
    const double position_var = covariance.bottomRightCorner<3, 3>().trace() / 3.0;
    if (!(rotation_var > 0.0 && position_var > 0.0)) return;
    r.rotation_sd_rad = std::sqrt(rotation_var);
    r.position_sd_mm = std::sqrt(position_var);
  }

  double Residual(std::size_t k, const Rigid3d& pose) const {
    return (pose * tool_.markers_in_tool[k] - Centre(k)).norm();
  }

 private:
  const DetectedMarker& Detection(std::size_t k) const {
    return detections_[static_cast<std::size_t>(marker_detection_[k])];
  }
  const Eigen::Vector3d& Centre(std::size_t k) const {
    return centres_[static_cast<std::size_t>(marker_detection_[k])];
  }

  std::span<const DetectedMarker> detections_;
  std::span<const int> marker_detection_;
  const ToolGeometry& tool_;
  const Points3d& centres_;
  const PoseRefinementOptions& refinement_;
  std::vector<Sigmas> sigmas_;
  std::vector<double> truncation_mm_;  // per tool marker; empty: none
};

// Damaged markers out when max(3, min_visible) whole ones remain, else in as they are (the
// residual check may still drop one).
std::vector<MarkerUse> InitialUse(std::span<const DetectedMarker> detections,
                                  std::span<const int> marker_detection, int needed,
                                  bool drop_damaged) {
  std::vector<MarkerUse> use(marker_detection.size(), MarkerUse::kUnseen);
  int whole = 0;
  for (const int s : marker_detection) {
    if (s >= 0 && !detections[static_cast<std::size_t>(s)].damage.Any()) ++whole;
  }
  for (std::size_t k = 0; k < use.size(); ++k) {
    if (marker_detection[k] < 0) continue;
    const MarkerDamage& d = detections[static_cast<std::size_t>(marker_detection[k])].damage;
    if (!d.Any()) {
      use[k] = MarkerUse::kUsed;
    } else if (drop_damaged && whole >= needed) {
      use[k] = d.occluded ? MarkerUse::kDroppedOccluded : MarkerUse::kDroppedNearBlob;
    } else {
      use[k] = MarkerUse::kUsedDamaged;
    }
  }
  return use;
}

}  // namespace

const char* ToString(MarkerUse use) {
  switch (use) {
    case MarkerUse::kUsed:
      return "used";
    case MarkerUse::kUsedDamaged:
      return "used_damaged";
    case MarkerUse::kUnseen:
      return "unseen";
    case MarkerUse::kDroppedOccluded:
      return "occluded";
    case MarkerUse::kDroppedNearBlob:
      return "near_blob";
    case MarkerUse::kDroppedOutlier:
      return "outlier";
    case MarkerUse::kDroppedImageBorder:
      return "image_border";
    case MarkerUse::kDroppedMerged:
      return "merged";
  }
  return "unknown";
}

bool InPose(MarkerUse use) { return use == MarkerUse::kUsed || use == MarkerUse::kUsedDamaged; }

void RobustPoseOptions::Check() const {
  Require(range_sigma_floor_mm > 0.0 && isotropic_sigma_mm > 0.0,
          "RobustPoseOptions: range_sigma_floor_mm and isotropic_sigma_mm must be > 0");
  Require(check_quantile_z > 0.0, "RobustPoseOptions::check_quantile_z must be > 0");
  truncation.Check();
  Require(pixel_range_sigma_mm > 0.0 && pixel_range_sigma_at_mm > 0.0 &&
              std::isfinite(pixel_range_sigma_exponent),
          "RobustPoseOptions: pixel_range_sigma_mm and pixel_range_sigma_at_mm must be > 0 and "
          "pixel_range_sigma_exponent finite");
}

RobustPose FitToolMarkers(std::span<const DetectedMarker> detections,
                          std::span<const int> marker_detection, const ToolGeometry& tool,
                          const Points3d& centres, const PoseRefinementOptions& refinement,
                          const RobustPoseOptions& options) {
  const int needed = std::max(3, tool.min_visible);
  RobustPose r;
  r.use = InitialUse(detections, marker_detection, needed, options.drop_damaged);
  std::vector<bool> in(r.use.size());
  for (std::size_t k = 0; k < in.size(); ++k) in[k] = InPose(r.use[k]);
  int n = static_cast<int>(std::count(in.begin(), in.end(), true));
  Require(n >= 3, "FitToolMarkers: fewer than 3 matched markers");
  Fitter fitter(detections, marker_detection, tool, centres, refinement, options);
  r.ahat_from_tool = fitter.Fit(in);
  if (fitter.SetTruncation(in, r.ahat_from_tool, options.truncation)) {
    r.ahat_from_tool = fitter.Fit(in);
  }
  r.chi2 = fitter.Chi2(in, r.ahat_from_tool);
  const double z = options.check_quantile_z;
  r.outliers_checked = options.check_outliers && n >= 4 && n > needed;
  // Leave-one-out while the residuals exceed the noise model: the marker whose removal leaves the
  // most consistent rest goes, if that rest is consistent (else no single marker explains it).
  while (options.check_outliers && n >= 4 && n > needed && r.chi2 > Chi2Quantile(3 * n - 6, z)) {
    double best_ratio = 0.0, best_chi2 = 0.0;
    std::size_t best = in.size();
    Rigid3d best_pose;
    for (std::size_t k = 0; k < in.size(); ++k) {
      if (!in[k]) continue;
      std::vector<bool> rest = in;
      rest[k] = false;
      const Rigid3d pose = fitter.Fit(rest);
      const double chi2 = fitter.Chi2(rest, pose);
      const double ratio = chi2 / Chi2Quantile(3 * (n - 1) - 6, z);
      if (best == in.size() || ratio < best_ratio) {
        best = k;
        best_ratio = ratio;
        best_chi2 = chi2;
        best_pose = pose;
      }
    }
    if (best == in.size() || best_ratio > 1.0) break;
    in[best] = false;
    r.use[best] = MarkerUse::kDroppedOutlier;
    r.ahat_from_tool = best_pose;
    r.chi2 = best_chi2;
    --n;
  }
  r.chi2_limit = Chi2Quantile(3 * n - 6, z);
  double sum2 = 0.0;
  for (std::size_t k = 0; k < in.size(); ++k) {
    if (!in[k]) continue;
    const double e = fitter.Residual(k, r.ahat_from_tool);
    r.residuals_mm.push_back(e);
    sum2 += e * e;
  }
  r.fre_rms_mm = std::sqrt(sum2 / static_cast<double>(r.residuals_mm.size()));
  fitter.SetSds(in, r.ahat_from_tool, options, r);
  return r;
}

void ExplainUnseenMarkers(const Rigid3d& ahat_from_tool, const ToolGeometry& tool,
                          std::span<const DroppedBlob> dropped, std::vector<MarkerUse>& use) {
  for (std::size_t k = 0; k < use.size() && k < tool.markers_in_tool.size(); ++k) {
    if (use[k] != MarkerUse::kUnseen) continue;
    const Eigen::Vector3d c = ahat_from_tool * tool.markers_in_tool[k];
    const double marker_rad = 0.5 * tool.marker_diameter_mm / std::max(c.norm(), 1.0);
    for (const DroppedBlob& b : dropped) {
      if (b.ray_in_ahat.isZero()) continue;
      const double angle = std::atan2(c.cross(b.ray_in_ahat).norm(), c.dot(b.ray_in_ahat));
      if (angle > b.radius_rad + marker_rad) continue;
      use[k] = b.reason == BlobDropReason::kMerged ? MarkerUse::kDroppedMerged
                                                   : MarkerUse::kDroppedImageBorder;
      break;
    }
  }
}

}  // namespace tofnav
