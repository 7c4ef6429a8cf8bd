// SPDX-License-Identifier: BSD-3-Clause
// The synthetic head phantom: a radially displaced ellipsoid.
#include "tofnav/sim/head_phantom.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav::sim {
namespace {

struct Bump {
  double azimuth_rad;    // around z, 0 = straight out of the face (+y), positive towards +x
  double elevation_rad;  // above the equator
  double sigma_azimuth_rad;
  double sigma_elevation_rad;
  double height_mm;  // negative for a concavity
};

double BumpHeightMm(const Bump& bump, double azimuth_rad, double elevation_rad) {
  const double da = (azimuth_rad - bump.azimuth_rad) / bump.sigma_azimuth_rad;
  const double de = (elevation_rad - bump.elevation_rad) / bump.sigma_elevation_rad;
  return bump.height_mm * std::exp(-0.5 * (da * da + de * de));
}

}  // namespace

void HeadPhantomOptions::Check() const {
  Require((semi_axes_mm.array() > 0.0).all(), "HeadPhantomOptions.semi_axes_mm must be positive");
  Require(nose_height_mm >= 0.0 && brow_height_mm >= 0.0 && eye_socket_depth_mm >= 0.0,
          "HeadPhantomOptions: feature sizes must be >= 0");
  Require(neck_cut_fraction > 0.0 && neck_cut_fraction <= 1.0,
          "HeadPhantomOptions.neck_cut_fraction must lie in (0, 1]");
  Require(segments >= 16 && segments % 2 == 0,
          "HeadPhantomOptions.segments must be even and >= 16");
}

TriangleMesh HeadPhantomMesh(const HeadPhantomOptions& options) {
  options.Check();
  const Bump bumps[] = {
      {0.0, -0.12, 0.11, 0.22, options.nose_height_mm},        // nose
      {0.0, 0.22, 0.55, 0.07, options.brow_height_mm},         // brow ridge
      {0.36, 0.08, 0.13, 0.09, -options.eye_socket_depth_mm},  // eye sockets
      {-0.36, 0.08, 0.13, 0.09, -options.eye_socket_depth_mm},
  };
  TriangleMesh mesh = SphereMesh(1.0, options.segments);
  const double z_cut = -options.neck_cut_fraction * options.semi_axes_mm.z();
  for (Eigen::Vector3d& p : mesh.vertices) {
    const Eigen::Vector3d unit = p.normalized();
    const double azimuth = std::atan2(unit.x(), unit.y());
    const double elevation = std::asin(std::clamp(unit.z(), -1.0, 1.0));
    p = unit.cwiseProduct(options.semi_axes_mm);
    double height_mm = 0.0;
    for (const Bump& bump : bumps) height_mm += BumpHeightMm(bump, azimuth, elevation);
    p += height_mm * unit;
    p.z() = std::max(p.z(), z_cut);  // flat neck cut keeps the mesh closed
  }
  mesh.vertex_normals = mesh.ComputeVertexNormals();
  return mesh;
}

}  // namespace tofnav::sim
