// SPDX-License-Identifier: BSD-3-Clause
// A built-in synthetic head phantom: an ellipsoid with nose, brow and eye sockets, no external
// data.
#pragma once

#include <Eigen/Core>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav::sim {

struct HeadPhantomOptions {
  /// Ellipsoid semi-axes [mm]: x ear to ear, y back to front, z chin to crown. The defaults give a
  /// head of about 150 x 190 x 220 mm before the nose and the neck cut.
  Eigen::Vector3d semi_axes_mm = {75.0, 95.0, 110.0};
  double nose_height_mm = 22.0;      // how far the nose tip stands out of the ellipsoid
  double brow_height_mm = 5.0;       // brow ridge
  double eye_socket_depth_mm = 7.0;  // concavities around the eyes
  double neck_cut_fraction = 0.8;    // flat bottom at z = -fraction * semi_axes.z
  int segments = 192;                // around the head (rings = segments / 2)
  void Check() const;
};

/// Closed head mesh in the head frame: origin at the ellipsoid centre, +x to the head's left,
/// +y out through the face (anterior), +z up (superior). Smooth vertex normals.
TriangleMesh HeadPhantomMesh(const HeadPhantomOptions& options = {});

}  // namespace tofnav::sim
