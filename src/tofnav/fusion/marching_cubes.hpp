// SPDX-License-Identifier: BSD-3-Clause
// Marching cubes (Lorensen & Cline 1987) over the TSDF's blocks or over a dense scalar grid.
#pragma once

#include "tofnav/core/grid3.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"

namespace tofnav {

struct TsdfMeshOptions {
  /// A cell is meshed only when all eight corner voxels weigh more than this (dimensionless;
  /// 0 keeps every observed voxel, higher values drop surfaces seen in few frames).
  double min_weight = 0.0;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// The zero level set of the TSDF in `tool` [mm], over allocated blocks only. Vertices are shared
/// between cells and blocks (none is duplicated), triangles are counter-clockwise seen from
/// outside (the positive, camera side), and the output is the same for any thread count.
TriangleMesh ExtractIsoSurface(const TsdfVolume& volume, const TsdfMeshOptions& options = {});

enum class IsoSurfaceOutside {
  kAbove,  // values above the iso value are outside (a signed distance field)
  kBelow,  // values below it are outside (CT: tissue is brighter than air)
};

struct GridIsoSurfaceOptions {
  float iso_value = 0.0f;  // in the grid's unit (mm for an SDF, HU for CT)
  IsoSurfaceOutside outside = IsoSurfaceOutside::kAbove;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// The iso-surface of a dense grid in the grid's frame [mm] (through frame_from_ijk), with the
/// same mesher as the TSDF: shared vertices, counter-clockwise seen from outside (a mirroring
/// frame_from_ijk is accounted for), deterministic. Non-finite values count as missing.
TriangleMesh ExtractIsoSurface(const Grid3<float>& grid, const GridIsoSurfaceOptions& options = {});

}  // namespace tofnav
