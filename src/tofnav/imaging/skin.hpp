// SPDX-License-Identifier: BSD-3-Clause
// Skin surface of a CT or MR head (Sec. III-B): threshold, outer component, marching cubes.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/imaging/ct_volume.hpp"

namespace tofnav {

/// Air is about -1000 HU, fat -100, skin 0..60: -300 HU sits on the steep air/skin edge.
inline constexpr double kCtSkinThresholdHu = -300.0;

/// An adult ear canal is about 7 mm wide: a ball of 8 mm diameter does not enter it.
inline constexpr double kDefaultOpeningRadiusMm = 4.0;

struct SkinOptions {
  /// In the volume's unit. Default: kCtSkinThresholdHu for CT (modality "CT", or no modality and
  /// values down to air, <= -500), Otsu's threshold otherwise (MR).
  std::optional<double> threshold;
  /// Keep the largest 6-connected component of the mask seen from outside only (drops the head
  /// holder, table, tubes, noise, and an MR brain cut off from the scalp by the field of view).
  /// Off: every component is meshed.
  bool keep_largest_component = true;
  /// Fill cavities enclosed within each axial slice (airways, sinuses, ear and mouth interior)
  /// and the air a ball of `opening_radius_mm` rolled in from outside cannot sweep, so that only
  /// the outer surface the headset can see is meshed (docs/registration.md 1.).
  bool fill_cavities = true;
  /// Air behind openings narrower than this ball (diameter: twice it) counts as inside: ear
  /// canals, nostrils, and in MR the dark skull and CSF reached through them. 0: no ball fill.
  double opening_radius_mm = kDefaultOpeningRadiusMm;
  int smoothing_iterations = 0;     // Taubin lambda|mu passes (shrink-free)
  double decimation_cell_mm = 0.0;  // vertex clustering cell; 0 keeps every vertex
  void Check() const;               // throws PreconditionError naming the field
};

struct SkinResult {
  TriangleMesh mesh;  ///< `image` (LPS mm), counter-clockwise from outside, outward normals
  double threshold = 0.0;
  std::string threshold_source;   ///< "given", "CT default" or "Otsu"
  int mask_components = 0;        ///< 6-connected components of the thresholded mask
  std::size_t kept_voxels = 0;    ///< voxels of the meshed mask (after filling)
  std::size_t filled_voxels = 0;  ///< by both fills (slice cavities, unreachable air)
  /// Triangles of surface pieces other than the largest (dropped, e.g. bits cut by the border).
  std::size_t dropped_triangles = 0;
};

/// The outer skin surface of a head volume. PreconditionError when nothing exceeds the threshold
/// (an empty mask) or the volume is invalid.
SkinResult ExtractSkin(const CtVolume& volume, const SkinOptions& options = {});

/// Otsu's threshold (maximum between-class variance) over the finite values, 256 bins;
/// PreconditionError when fewer than two distinct finite values exist.
double OtsuThreshold(std::span<const float> values);

/// The mesh in RAS (3D Slicer's world): x and y negated, normals too, winding kept.
TriangleMesh MeshLpsToRas(const TriangleMesh& mesh_in_lps);

}  // namespace tofnav
