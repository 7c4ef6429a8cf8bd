// SPDX-License-Identifier: BSD-3-Clause
// The patient's physical skin: a moving least-squares surface through an image's iso-surface.
#include "tofnav/scenario/physical_skin.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {
namespace {

constexpr double kReachSigmas = 3.0;  // Gaussian weights below 1.1 % beyond it
constexpr int kMinNeighbours = 12;    // twice the quadric's six coefficients

// Vertex `i`'s projection onto the weighted quadric over its tangent plane: the move along the
// plane's normal and the fit's weighted RMS residual. No fit (a zero move, NaN residual) where too
// few neighbours face its way (a thin rim, a lone vertex).
struct Fit {
  double move_mm = 0.0;
  double residual_mm = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

Fit FitQuadric(const SurfaceIndex& index, std::size_t i, double sigma_mm) {
  const Eigen::Vector3d& p = index.points()[i];
  const std::vector<Neighbour> near = index.WithinRadius(p, kReachSigmas * sigma_mm);
  const double inv_two_sigma_sq = 0.5 / (sigma_mm * sigma_mm);
  // The plane's normal: the Gaussian mean of the neighbours' normals that face this vertex's way.
  Fit fit;
  for (const Neighbour& n : near) {
    const Eigen::Vector3d& nj = index.normals()[n.index];
    if (nj.dot(index.normals()[i]) > 0.0) {
      fit.normal += std::exp(-n.distance_sq_mm2 * inv_two_sigma_sq) * nj;
    }
  }
  if (fit.normal.norm() < 1e-9) return {};
  fit.normal.normalize();
  const Eigen::Vector3d u = fit.normal.unitOrthogonal(), v = fit.normal.cross(u);
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  double sum_w = 0.0, sum_wzz = 0.0;
  int used = 0;
  for (const Neighbour& n : near) {
    if (index.normals()[n.index].dot(fit.normal) <= 0.0) continue;  // a thin part's far side
    const Eigen::Vector3d d = index.points()[n.index] - p;
    const double x = d.dot(u), y = d.dot(v), z = d.dot(fit.normal);
    const double w = std::exp(-n.distance_sq_mm2 * inv_two_sigma_sq);
    Eigen::Matrix<double, 6, 1> row;
    row << 1.0, x, y, x * x, x * y, y * y;
    ata.noalias() += w * row * row.transpose();
    atb.noalias() += w * z * row;
    sum_w += w;
    sum_wzz += w * z * z;
    ++used;
  }
  if (used < kMinNeighbours) return {};
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solve(ata);
  if (solve.info() != Eigen::Success) return {};
  const Eigen::Matrix<double, 6, 1> c = solve.solve(atb);
  if (!c.allFinite()) return {};
  // Weighted least squares: sum w r^2 = sum w z^2 - c . (A^T W z).
  fit.move_mm = c(0);  // the quadric's height over p's foot on the plane
  fit.residual_mm = std::sqrt(std::max(0.0, sum_wzz - c.dot(atb)) / sum_w);
  return fit;
}

}  // namespace

void PhysicalSkinOptions::Check() const {
  Require(std::isfinite(sigma_mm) && sigma_mm >= 0.0,
          "PhysicalSkinOptions::sigma_mm must be finite and >= 0");
  Require(!max_move_mm || std::isfinite(*max_move_mm),
          "PhysicalSkinOptions::max_move_mm must be finite");
  Require(std::isfinite(noise_sigmas) && noise_sigmas > 0.0,
          "PhysicalSkinOptions::noise_sigmas must be finite and > 0");
}

TriangleMesh SmoothPhysicalSkin(const TriangleMesh& iso_surface,
                                const PhysicalSkinOptions& options) {
  options.Check();
  iso_surface.CheckConsistent();
  if (options.sigma_mm == 0.0 || iso_surface.vertices.empty()) return iso_surface;
  TriangleMesh smoothed = iso_surface;  // its vertices move only once every fit is made
  if (smoothed.vertex_normals.size() != smoothed.vertices.size()) {
    smoothed.vertex_normals = smoothed.ComputeVertexNormals();
  }
  // The index keeps every vertex with a normal, in order: a vertex without one (used by no
  // triangle, or degenerate) is not smoothed and not counted as a neighbour.
  Points3d points, normals;
  std::vector<std::size_t> indexed;  // mesh vertex of each index point
  for (std::size_t i = 0; i < smoothed.vertices.size(); ++i) {
    const Eigen::Vector3d& n = smoothed.vertex_normals[i];
    if (!n.allFinite() || n.norm() < 0.5) continue;
    points.push_back(smoothed.vertices[i]);
    normals.push_back(n.normalized());
    indexed.push_back(i);
  }
  if (points.size() < static_cast<std::size_t>(kMinNeighbours)) return smoothed;
  const SurfaceIndex index(std::move(points), std::move(normals));
  Require(index.size() == indexed.size(), "SmoothPhysicalSkin: the index dropped vertices");
  std::vector<Fit> fits(indexed.size());
  ParallelFor(
      0, static_cast<std::int64_t>(indexed.size()),
      [&](std::int64_t k) {
        fits[static_cast<std::size_t>(k)] =
            FitQuadric(index, static_cast<std::size_t>(k), options.sigma_mm);
      },
      256);
  double cap_mm = options.max_move_mm.value_or(0.0);
  if (!options.max_move_mm) {  // the surface's own noise: the median residual of its fits
    std::vector<double> residuals;
    for (const Fit& f : fits) {
      if (std::isfinite(f.residual_mm)) residuals.push_back(f.residual_mm);
    }
    if (residuals.empty()) return smoothed;
    auto middle = residuals.begin() + static_cast<std::ptrdiff_t>(residuals.size() / 2);
    std::nth_element(residuals.begin(), middle, residuals.end());
    cap_mm = options.noise_sigmas * *middle;
  }
  for (std::size_t k = 0; k < fits.size(); ++k) {
    const double move_mm =
        cap_mm > 0.0 ? std::clamp(fits[k].move_mm, -cap_mm, cap_mm) : fits[k].move_mm;
    smoothed.vertices[indexed[k]] += move_mm * fits[k].normal;
  }
  smoothed.vertex_normals = smoothed.ComputeVertexNormals();
  return smoothed;
}

}  // namespace tofnav
