// SPDX-License-Identifier: BSD-3-Clause
// SurfaceIndex: nanoflann KD-tree, PCA normals, radius-bounded nearest neighbour.
#include "tofnav/registration/surface_index.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <nanoflann.hpp>
#include <utility>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kLeafSize = 12;  // measured: 8-16 points per leaf are equally fast

/// nanoflann's view of a Points3d (the vector must outlive the tree).
struct PointsAdaptor {
  const Points3d* points;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return (*points)[i][static_cast<Eigen::Index>(dim)];
  }
  template <typename Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};

using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>,
                                        PointsAdaptor, 3, std::uint32_t>;

/// Keeps only the closest point seen, starting from a squared-distance bound: the tree prunes
/// every cell farther than the current best, which is the bound until a point is found.
class BoundedNearestResult {
 public:
  explicit BoundedNearestResult(double bound_sq) : best_sq_(bound_sq) {}
  std::size_t size() const { return found_ ? 1 : 0; }
  bool full() const { return found_; }
  bool addPoint(double distance_sq, std::uint32_t index) {
    if (distance_sq < best_sq_) {
      best_sq_ = distance_sq;
      index_ = index;
      found_ = true;
    }
    return true;
  }
  double worstDist() const { return best_sq_; }
  std::optional<Neighbour> Get() const {
    if (!found_) return std::nullopt;
    return Neighbour{index_, best_sq_};
  }

 private:
  double best_sq_;
  std::uint32_t index_ = 0;
  bool found_ = false;
};

/// Keeps the `capacity` closest points seen below a squared-distance bound, sorted (a later point
/// at an equal distance after the earlier); the tree prunes every cell farther than the last kept
/// (the bound until `capacity` are found).
class BoundedKNearestResult {
 public:
  static constexpr std::size_t kCapacity = SurfaceIndex::kMaxNearestSet + 1;
  BoundedKNearestResult(std::size_t capacity, double bound_sq)
      : capacity_(std::clamp<std::size_t>(capacity, 1, kCapacity)), bound_sq_(bound_sq) {}
  std::size_t size() const { return count_; }
  bool full() const { return count_ == capacity_; }
  bool addPoint(double distance_sq, std::uint32_t index) {
    if (distance_sq >= worstDist()) return true;
    std::size_t i = std::min(count_, capacity_ - 1);  // when full, the last one is dropped
    for (; i > 0 && distance_sq_[i - 1] > distance_sq; --i) {
      distance_sq_[i] = distance_sq_[i - 1];
      index_[i] = index_[i - 1];
    }
    distance_sq_[i] = distance_sq;
    index_[i] = index;
    count_ = std::min(count_ + 1, capacity_);
    return true;
  }
  double worstDist() const { return full() ? distance_sq_[capacity_ - 1] : bound_sq_; }
  double distance_sq(std::size_t i) const { return distance_sq_[i]; }
  std::uint32_t index(std::size_t i) const { return index_[i]; }

 private:
  std::size_t capacity_;
  double bound_sq_;
  std::array<double, kCapacity> distance_sq_{};
  std::array<std::uint32_t, kCapacity> index_{};
  std::size_t count_ = 0;
};

std::unique_ptr<KdTree> BuildTree(const PointsAdaptor& adaptor) {
  return std::make_unique<KdTree>(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
}

std::vector<Neighbour> KNearestIn(const KdTree& tree, std::size_t count,
                                  const Eigen::Vector3d& query, int k) {
  const std::size_t wanted = std::min(static_cast<std::size_t>(std::max(k, 0)), count);
  std::vector<std::uint32_t> indices(wanted);
  std::vector<double> distances_sq(wanted);
  const std::size_t found =
      wanted == 0 ? 0 : tree.knnSearch(query.data(), wanted, indices.data(), distances_sq.data());
  std::vector<Neighbour> result(found);
  for (std::size_t i = 0; i < found; ++i) result[i] = {indices[i], distances_sq[i]};
  return result;
}

/// Unit normal of the best-fit plane through the k nearest points, oriented by `outward`.
Points3d EstimateNormals(const Points3d& points, const SurfaceIndexOptions& options) {
  const PointsAdaptor adaptor{&points};
  const std::unique_ptr<KdTree> tree = BuildTree(adaptor);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Points3d normals(points.size(), Eigen::Vector3d::Zero());
  ParallelFor(
      0, static_cast<std::int64_t>(points.size()),
      [&](std::int64_t i) {
        const Eigen::Vector3d& p = points[static_cast<std::size_t>(i)];
        const std::vector<Neighbour> near =
            KNearestIn(*tree, points.size(), p, options.normal_neighbours);
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (const Neighbour& n : near) mean += points[n.index];
        mean /= static_cast<double>(near.size());
        Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
        for (const Neighbour& n : near) {
          const Eigen::Vector3d d = points[n.index] - mean;
          covariance += d * d.transpose();
        }
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
        solver.computeDirect(covariance);
        Eigen::Vector3d normal = solver.eigenvectors().col(0);  // smallest eigenvalue
        const Eigen::Vector3d outward = options.viewpoint ? Eigen::Vector3d(*options.viewpoint - p)
                                                          : Eigen::Vector3d(p - centroid);
        if (normal.dot(outward) < 0.0) normal = -normal;
        normals[static_cast<std::size_t>(i)] = normal;
      },
      256);
  return normals;
}

}  // namespace

struct SurfaceIndex::Impl {
  Points3d points;
  Points3d normals;
  PointsAdaptor adaptor{&points};
  std::unique_ptr<KdTree> tree;
  double spacing_mm = 0.0;
};

namespace {

constexpr std::size_t kSpacingSamples = 1000;

double MedianSpacingMm(const KdTree& tree, const Points3d& points) {
  const std::size_t stride = std::max<std::size_t>(1, points.size() / kSpacingSamples);
  std::vector<double> distances;
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const std::vector<Neighbour> near = KNearestIn(tree, points.size(), points[i], 2);
    distances.push_back(std::sqrt(near.back().distance_sq_mm2));
  }
  const auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return *middle;
}

}  // namespace

void SurfaceIndexOptions::Check() const {
  Require(normal_neighbours >= 3, "SurfaceIndexOptions.normal_neighbours must be >= 3");
  Require(!viewpoint || viewpoint->allFinite(), "SurfaceIndexOptions.viewpoint must be finite");
}

SurfaceIndex::SurfaceIndex(PointCloud surface, const SurfaceIndexOptions& options) {
  options.Check();
  Require(surface.normals.empty() || surface.normals.size() == surface.points.size(),
          "SurfaceIndex: one normal per point, or none");
  Require(surface.points.size() < std::numeric_limits<std::uint32_t>::max(),
          "SurfaceIndex: too many points");
  Require(surface.points.size() >= 3, "SurfaceIndex: needs at least 3 points");
  if (surface.normals.empty()) {
    surface.normals = EstimateNormals(surface.points, options);
  }
  auto impl = std::make_shared<Impl>();
  impl->points.reserve(surface.points.size());
  impl->normals.reserve(surface.points.size());
  for (std::size_t i = 0; i < surface.points.size(); ++i) {
    const double length = surface.normals[i].norm();
    if (!(length > 1e-12) || !std::isfinite(length) || !surface.points[i].allFinite()) continue;
    impl->points.push_back(surface.points[i]);
    impl->normals.push_back(surface.normals[i] / length);
  }
  Require(impl->points.size() >= 3, "SurfaceIndex: needs at least 3 points with normals");
  impl->tree = BuildTree(impl->adaptor);
  impl->spacing_mm = MedianSpacingMm(*impl->tree, impl->points);
  impl_ = std::move(impl);
}

namespace {
PointCloud WithNormals(Points3d points, Points3d normals) {
  PointCloud cloud;
  cloud.points = std::move(points);
  cloud.normals = std::move(normals);
  return cloud;
}
}  // namespace

SurfaceIndex::SurfaceIndex(Points3d points, Points3d normals, const SurfaceIndexOptions& options)
    : SurfaceIndex(WithNormals(std::move(points), std::move(normals)), options) {}

SurfaceIndex::SurfaceIndex(const TriangleMesh& mesh)
    : SurfaceIndex(mesh.vertices, mesh.vertex_normals.empty() ? mesh.ComputeVertexNormals()
                                                              : mesh.vertex_normals) {}

const Points3d& SurfaceIndex::points() const { return impl_->points; }
const Points3d& SurfaceIndex::normals() const { return impl_->normals; }
double SurfaceIndex::spacing_mm() const { return impl_->spacing_mm; }

std::optional<Neighbour> SurfaceIndex::Nearest(const Eigen::Vector3d& query,
                                               double max_distance_mm) const {
  BoundedNearestResult result(max_distance_mm * max_distance_mm);
  impl_->tree->findNeighbors(result, query.data(), nanoflann::SearchParams());
  return result.Get();
}

SurfaceIndex::NearestSet SurfaceIndex::NearestK(const Eigen::Vector3d& query, int k,
                                                double max_distance_mm) const {
  const auto wanted = static_cast<std::size_t>(std::clamp(k, 1, kMaxNearestSet));
  BoundedKNearestResult result(wanted + 1, max_distance_mm * max_distance_mm);
  impl_->tree->findNeighbors(result, query.data(), nanoflann::SearchParams());
  NearestSet out;
  out.count = static_cast<int>(std::min(result.size(), wanted));
  for (std::size_t i = 0; i < static_cast<std::size_t>(out.count); ++i) {
    out.nearest[i] = {result.index(i), result.distance_sq(i)};
  }
  out.others_from_mm = std::sqrt(result.worstDist());
  return out;
}

std::vector<Neighbour> SurfaceIndex::KNearest(const Eigen::Vector3d& query, int k) const {
  return KNearestIn(*impl_->tree, impl_->points.size(), query, k);
}

std::vector<Neighbour> SurfaceIndex::WithinRadius(const Eigen::Vector3d& query,
                                                  double radius_mm) const {
  std::vector<std::pair<std::uint32_t, double>> matches;
  impl_->tree->radiusSearch(query.data(), radius_mm * radius_mm, matches,
                            nanoflann::SearchParams(32, 0.0F, true));
  std::vector<Neighbour> result(matches.size());
  for (std::size_t i = 0; i < matches.size(); ++i)
    result[i] = {matches[i].first, matches[i].second};
  return result;
}

}  // namespace tofnav
