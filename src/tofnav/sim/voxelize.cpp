// SPDX-License-Identifier: BSD-3-Clause
// Closed meshes on voxel grids: scanline coverage and the Euclidean distance transform.
#include "tofnav/sim/voxelize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tofnav/core/distance_transform.hpp"
#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Sub-rows are shifted by these fractions of a voxel so that they never run exactly through a
// mesh vertex, edge or plane placed on the grid (e.g. the phantom's flat neck cut).
constexpr double kRowShiftY = 0.0001234567;
constexpr double kRowShiftZ = 0.0000765432;

// Triangle indices per voxel row (j, k) that their y-z bounding box touches (compressed rows).
struct RowBins {
  std::vector<std::size_t> start;  // ny * nz + 1 offsets
  std::vector<int> triangles;
};

RowBins BinTriangles(const TriangleMesh& mesh, const VoxelGrid& grid) {
  const int ny = grid.dims[1], nz = grid.dims[2];
  const auto for_each_row = [&](const Eigen::Vector3i& t, auto&& visit) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& c = mesh.vertices[static_cast<std::size_t>(t[2])];
    const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
    const int j0 = std::max(0, grid.Cell(1, lo.y())), j1 = std::min(ny - 1, grid.Cell(1, hi.y()));
    const int k0 = std::max(0, grid.Cell(2, lo.z())), k1 = std::min(nz - 1, grid.Cell(2, hi.z()));
    for (int k = k0; k <= k1; ++k) {
      for (int j = j0; j <= j1; ++j) visit(static_cast<std::size_t>(j + ny * k));
    }
  };
  RowBins bins;
  bins.start.assign(static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz) + 1, 0);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for_each_row(t, [&](std::size_t row) { ++bins.start[row + 1]; });
  }
  for (std::size_t r = 1; r < bins.start.size(); ++r) bins.start[r] += bins.start[r - 1];
  bins.triangles.resize(bins.start.back());
  std::vector<std::size_t> fill(bins.start.begin(), bins.start.end() - 1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for_each_row(mesh.triangles[t],
                 [&](std::size_t row) { bins.triangles[fill[row]++] = static_cast<int>(t); });
  }
  return bins;
}

// A triangle projected on the y-z plane, ready for row crossings (plain doubles: this loop runs
// for every sub-row and triangle, also in unoptimised test builds).
struct ProjectedTriangle {
  double ay, az, by, bz, cy, cz;  // y-z corners
  double ax, bx, cx;              // x of the corners
  double inverse_area;            // 1 / (signed doubled area in y-z)
};

std::vector<ProjectedTriangle> ProjectTriangles(const TriangleMesh& mesh) {
  std::vector<ProjectedTriangle> out(mesh.triangles.size());
  for (std::size_t n = 0; n < mesh.triangles.size(); ++n) {
    const Eigen::Vector3i& t = mesh.triangles[n];
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& c = mesh.vertices[static_cast<std::size_t>(t[2])];
    const double area = (b.y() - a.y()) * (c.z() - a.z()) - (b.z() - a.z()) * (c.y() - a.y());
    // Edge-on triangles (zero area in y-z) cannot be crossed by a row: mark them with 0.
    out[n] = {a.y(), a.z(), b.y(), b.z(), c.y(),
              c.z(), a.x(), b.x(), c.x(), std::abs(area) < 1e-14 ? 0.0 : 1.0 / area};
  }
  return out;
}

}  // namespace

std::size_t VoxelGrid::size() const {
  return static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) *
         static_cast<std::size_t>(dims[2]);
}

std::size_t VoxelGrid::Index(int i, int j, int k) const {
  return static_cast<std::size_t>(i) +
         static_cast<std::size_t>(dims[0]) *
             (static_cast<std::size_t>(j) +
              static_cast<std::size_t>(dims[1]) * static_cast<std::size_t>(k));
}

int VoxelGrid::Cell(int axis, double x) const {
  return static_cast<int>(std::floor((x - origin[axis]) / spacing_mm + 0.5));
}

VoxelGrid GridAroundMesh(const TriangleMesh& mesh, double spacing_mm, double margin_mm,
                         std::int64_t max_voxels) {
  Require(!mesh.vertices.empty(), "GridAroundMesh: empty mesh");
  Require(spacing_mm > 0.0 && margin_mm >= 0.0, "GridAroundMesh: bad spacing or margin");
  Eigen::Vector3d lo = mesh.vertices.front(), hi = lo;
  for (const Eigen::Vector3d& p : mesh.vertices) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  VoxelGrid grid;
  grid.spacing_mm = spacing_mm;
  std::int64_t voxels = 1;
  for (int a = 0; a < 3; ++a) {
    grid.origin[a] = std::floor((lo[a] - margin_mm) / spacing_mm) * spacing_mm;
    const double cells = std::ceil((hi[a] + margin_mm - grid.origin[a]) / spacing_mm) + 1.0;
    Require(cells < 4096.0, "GridAroundMesh: the grid is too large (> 4096 voxels per axis)");
    grid.dims[static_cast<std::size_t>(a)] = static_cast<int>(cells);
    voxels *= static_cast<std::int64_t>(cells);
  }
  Require(voxels <= max_voxels, "GridAroundMesh: the grid has more voxels than allowed");
  return grid;
}

std::vector<float> MeshInsideFraction(const TriangleMesh& mesh, const VoxelGrid& grid,
                                      int subsamples) {
  Require(subsamples >= 1, "MeshInsideFraction: subsamples must be >= 1");
  const RowBins bins = BinTriangles(mesh, grid);
  const std::vector<ProjectedTriangle> triangles = ProjectTriangles(mesh);
  const int nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  std::vector<float> fraction(grid.size(), 0.0f);
  const double weight = 1.0 / (subsamples * subsamples * grid.spacing_mm);
  ParallelFor(0, static_cast<std::int64_t>(ny) * nz, [&](std::int64_t row) {
    const int j = static_cast<int>(row % ny), k = static_cast<int>(row / ny);
    std::vector<double> crossings, coverage(static_cast<std::size_t>(nx), 0.0);
    const std::size_t begin = bins.start[static_cast<std::size_t>(row)];
    const std::size_t end = bins.start[static_cast<std::size_t>(row) + 1];
    for (int sz = 0; sz < subsamples; ++sz) {
      for (int sy = 0; sy < subsamples; ++sy) {
        const double y =
            grid.origin.y() + grid.spacing_mm * (j + (sy + 0.5) / subsamples - 0.5 + kRowShiftY);
        const double z =
            grid.origin.z() + grid.spacing_mm * (k + (sz + 0.5) / subsamples - 0.5 + kRowShiftZ);
        crossings.clear();
        for (std::size_t n = begin; n < end; ++n) {
          const ProjectedTriangle& t = triangles[static_cast<std::size_t>(bins.triangles[n])];
          if (t.inverse_area == 0.0) continue;
          const double wa = ((t.by - y) * (t.cz - z) - (t.bz - z) * (t.cy - y)) * t.inverse_area;
          const double wb = ((t.cy - y) * (t.az - z) - (t.cz - z) * (t.ay - y)) * t.inverse_area;
          const double wc = 1.0 - wa - wb;
          if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
          crossings.push_back(wa * t.ax + wb * t.bx + wc * t.cx);
        }
        std::sort(crossings.begin(), crossings.end());
        for (std::size_t n = 0; n + 1 < crossings.size(); n += 2) {
          const double x0 = crossings[n], x1 = crossings[n + 1];
          for (int i = std::max(0, grid.Cell(0, x0)); i <= std::min(nx - 1, grid.Cell(0, x1));
               ++i) {
            const double cell_lo = grid.origin.x() + (i - 0.5) * grid.spacing_mm;
            const double overlap = std::min(x1, cell_lo + grid.spacing_mm) - std::max(x0, cell_lo);
            if (overlap > 0.0) coverage[static_cast<std::size_t>(i)] += overlap;
          }
        }
      }
    }
    for (int i = 0; i < nx; ++i) {
      fraction[grid.Index(i, j, k)] =
          static_cast<float>(std::min(1.0, coverage[static_cast<std::size_t>(i)] * weight));
    }
  });
  return fraction;
}

std::vector<double> SquaredDistanceToOutside(const std::vector<float>& fraction,
                                             const VoxelGrid& grid) {
  std::vector<double> d2(grid.size());
  for (std::size_t n = 0; n < d2.size(); ++n) d2[n] = fraction[n] >= 0.5f ? kInfinity : 0.0;
  SquaredDistanceTransform(d2, grid.dims, {grid.spacing_mm, grid.spacing_mm, grid.spacing_mm});
  return d2;
}

}  // namespace tofnav::sim
