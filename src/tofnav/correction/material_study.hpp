// SPDX-License-Identifier: BSD-3-Clause
// Depth error per material against a retro-reflective reference plane (paper Sec. III-A.2).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tofnav/core/statistics.hpp"

namespace tofnav {

/// The plane n . x + offset_mm = 0 in `ahat` [mm], n unit and facing the camera (offset > 0).
struct ReferencePlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset_mm = 0.0;
  double rms_mm = 0.0;  // RMS point-to-plane distance of the inliers
  int inliers = 0;
};

struct ReferencePlaneOptions {
  int iterations = 4;               // least-squares fits, each dropping the outliers of the last
  double outlier_mad_factor = 3.0;  // outlier: |distance| > factor * 1.4826 MAD (dimensionless)
  double min_outlier_mm = 1.0;      // ... and > this [mm] (AHAT ranges come in 1 mm steps)
  int min_points = 30;              // fewer (inlier) points: no plane
  void Check() const;               // throws std::invalid_argument naming the bad field
};

/// Least-squares plane of `points_in_ahat` [mm] with iterative outlier rejection (the paper fits
/// Ax + By + Cz + D = 0 to the corrected retro-reflective points). nullopt with too few points.
std::optional<ReferencePlane> FitReferencePlane(std::span<const Eigen::Vector3d> points_in_ahat,
                                                const ReferencePlaneOptions& options = {});

/// The paper's depth error of a measured point X against the plane: X' = (1 - k) X lies on the
/// plane and delta = ||X|| - ||X'|| = k ||X|| [mm] (> 0: measured too far). nullopt when the ray
/// of X is (nearly) parallel to the plane.
std::optional<double> ReferenceDepthErrorMm(const ReferencePlane& plane,
                                            const Eigen::Vector3d& point_in_ahat);

/// Incidence angle of the ray through `point_in_ahat` on the plane, arccos(|n . X| / ||X||) [rad].
double PlaneIncidenceRad(const ReferencePlane& plane, const Eigen::Vector3d& point_in_ahat);

/// One surface pixel of a material sample.
struct MaterialPixel {
  int material = 0;                    // index into the study's material names
  float reference_range_mm = 0.0f;     // ||X'||: the range the reference plane gives (the bin)
  float incidence_rad = 0.0f;          // on the reference plane
  float error_vs_reference_mm = 0.0f;  // delta = k ||X||
  float error_vs_truth_mm = 0.0f;      // measured minus true range (NaN: no truth)
};

struct MaterialStudyOptions {
  double depth_bin_mm = 50.0;          // bins of reference range from 0 [mm]
  double angle_bin_rad = 0.174532925;  // bins of incidence from 0 [rad] (10 deg)
  void Check() const;                  // throws std::invalid_argument naming the bad field
};

/// One cell of the study: a material over a depth and an angle range (a whole axis: [0, inf)).
struct MaterialCell {
  int material = 0;
  double depth_min_mm = 0.0, depth_max_mm = 0.0;
  double angle_min_rad = 0.0, angle_max_rad = 0.0;
  Summary vs_reference_mm;  // depth errors against the reference plane [mm]
  Summary vs_truth_mm;      // against the truth [mm]; count 0 when no pixel had truth
};

struct MaterialStudyResult {
  std::vector<std::string> materials;
  std::vector<MaterialCell> overall;   // one per material that has pixels
  std::vector<MaterialCell> by_depth;  // per material and depth bin (all angles)
  std::vector<MaterialCell> by_angle;  // per material and angle bin (all depths)
  std::vector<MaterialCell> by_depth_and_angle;
};

/// Collects material pixels over frames and summarises them per material, depth and angle.
class MaterialStudy {
 public:
  explicit MaterialStudy(std::vector<std::string> materials, MaterialStudyOptions options = {});
  void Add(const MaterialPixel& pixel);  // throws on a material index out of range
  std::size_t size() const { return pixels_.size(); }
  MaterialStudyResult Summarise() const;

 private:
  std::vector<std::string> materials_;
  MaterialStudyOptions options_;
  std::vector<MaterialPixel> pixels_;
};

/// The Summary of the finite errors (NaNs, meaning "no truth", are skipped).
Summary SummariseDepthErrors(std::vector<float> errors_mm);

}  // namespace tofnav
