// SPDX-License-Identifier: BSD-3-Clause
// A rigid marker tool (docs/tracking.md section 2) and its distinctiveness report (section 9.7).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tofnav/core/point_cloud.hpp"

namespace tofnav {

enum class MarkerType {
  kSphere,  // retro-reflective ball: the centre lies one radius behind the seen surface
  kDisc,    // flat tape: the centre is on the seen surface (radius 0)
};

/// Markers in the tool's own frame `tool` [mm].
struct ToolGeometry {
  std::string name;  // also the OpenIGTLink device name stem (<= 20 characters there)
  Points3d markers_in_tool;
  MarkerType marker_type = MarkerType::kSphere;
  double marker_diameter_mm = 11.5;
  std::optional<Eigen::Vector3d> tip_in_tool;  // pivot-calibrated tip, when known
  int min_visible = 3;                         // markers needed for a pose (3 .. marker count)
  double max_fre_mm = 0.0;  // FRE acceptance for this tool; 0 = ToolPoseOptions::max_fre_mm

  /// Range from the seen surface to the marker centre [mm]: the radius for spheres, 0 for discs.
  double SurfaceToCentreMm() const;
  /// Throws std::invalid_argument: fewer than 3 markers, non-finite values, markers closer than
  /// one marker diameter (duplicates), collinear markers, min_visible outside [3, count], bad
  /// diameter or max_fre_mm.
  void Check() const;
};

/// The unit normal of the markers' least-squares plane in `tool` (the tape's normal for a flat
/// disc tool; its sign is arbitrary). Needs >= 3 non-collinear markers (ToolGeometry::Check).
Eigen::Vector3d MarkerPlaneNormal(const ToolGeometry& tool);

/// Each marker's own plane normal in `tool`: the least-squares plane of the marker and its three
/// nearest neighbours (a tool built from several flat plates, such as a headframe's two reference
/// plates tracked as one, has one plane per plate); the whole tool's plane where those four are
/// nearly collinear or the tool has at most four markers (then they are the whole tool). Signs are
/// arbitrary.
std::vector<Eigen::Vector3d> MarkerPlaneNormals(const ToolGeometry& tool);

/// A marker's plate as MarkerPlaneNormals finds it: the plane's unit normal in `tool` and the RMS
/// distance of the markers that define it (the marker and its three nearest, or the whole tool)
/// from that plane [mm]: about 0 on a flat plate.
struct MarkerPlate {
  Eigen::Vector3d normal_in_tool;
  double flatness_rms_mm = 0.0;
};
std::vector<MarkerPlate> MarkerPlates(const ToolGeometry& tool);

/// How distinct a tool is from itself under relabelling and from others (docs/tracking.md 9.7).
struct ToolGeometryReport {
  std::vector<double> distances_mm;  // |m_i - m_j| for i < j, in order (0,1), (0,2), ..
  double min_distance_mm = 0.0;
  double max_distance_mm = 0.0;
  double min_distance_difference_mm = 0.0;  // min |D_ij - D_kl| over distinct pairs
  /// Min FRE of a proper rigid fit of the tool onto a non-identity relabelling of itself: small
  /// means a symmetry, so orientation flips are undetectable (status kAmbiguous at runtime).
  double self_symmetry_fre_mm = 0.0;
  double planarity_rms_mm = 0.0;  // RMS distance of the markers from their best plane
  /// Per other tool: min over pairs of segments of |D^this_ij - D^other_kl| ...
  std::vector<double> min_segment_difference_mm;
  /// ... and min FRE of a proper rigid fit of any min_visible-subset of this tool onto any
  /// markers of the other tool: small means the two can be confused under occlusion. Mirror
  /// twins have equal distances but a large FRE here (unless planar).
  std::vector<double> confusion_fre_mm;
};

/// Report of `tool` against itself and each of `others`. Calls tool.Check() (throws).
ToolGeometryReport AnalyzeToolGeometry(const ToolGeometry& tool,
                                       std::span<const ToolGeometry> others = {});

}  // namespace tofnav
