// SPDX-License-Identifier: BSD-3-Clause
// Tool validation and the symmetry / confusion report (docs/tracking.md 9.7).
#include "tofnav/tracking/tool_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rigid_fit.hpp"

namespace tofnav {
namespace {

constexpr double kCollinearMm = 1.0;  // second singular value / sqrt(n) below this: a line
// Relabellings whose distances differ by more than this cannot fit well (FRE >= mismatch / 2):
// pruning them keeps the search small; the reported FRE is then capped here.
constexpr double kPruneMm = 20.0;

std::vector<double> SingularValues(const Points3d& points) {
  const Eigen::Vector3d s = ComputePrincipalAxes(points).spreads;
  return {s.data(), s.data() + std::min<std::size_t>(points.size(), 3)};  // as many as an SVD
}

// Min FRE of proper rigid fits of `size`-subsets of a (in index order) onto distinct markers of
// b, optionally skipping the identity map (a == b); capped at kPruneMm.
class ConfusionSearch {
 public:
  ConfusionSearch(const Points3d& a, const Points3d& b, int size, bool skip_identity)
      : a_(a), b_(b), size_(size), skip_identity_(skip_identity), used_(b.size(), false) {}

  double Run() {
    Visit(0);
    return best_;
  }

 private:
  void Visit(std::size_t next) {
    if (static_cast<int>(source_.size()) == size_) {
      Evaluate();
      return;
    }
    if (next >= a_.size()) return;
    if (static_cast<int>(a_.size() - next) + static_cast<int>(source_.size()) > size_) {
      Visit(next + 1);  // leave marker `next` out
    }
    for (std::size_t j = 0; j < b_.size(); ++j) {
      if (used_[j] || !Consistent(next, j)) continue;
      used_[j] = true;
      source_.push_back(next);
      target_.push_back(j);
      Visit(next + 1);
      source_.pop_back();
      target_.pop_back();
      used_[j] = false;
    }
  }

  bool Consistent(std::size_t i, std::size_t j) const {
    for (std::size_t k = 0; k < source_.size(); ++k) {
      const double da = (a_[i] - a_[source_[k]]).norm(), db = (b_[j] - b_[target_[k]]).norm();
      if (std::abs(da - db) > kPruneMm) return false;
    }
    return true;
  }

  void Evaluate() {
    if (skip_identity_ && source_ == target_) return;
    Points3d s, t;
    for (std::size_t k = 0; k < source_.size(); ++k) {
      s.push_back(a_[source_[k]]);
      t.push_back(b_[target_[k]]);
    }
    best_ = std::min(best_, FitRigid(s, t).fre_rms_mm);
  }

  const Points3d& a_;
  const Points3d& b_;
  int size_;
  bool skip_identity_;
  std::vector<bool> used_;
  std::vector<std::size_t> source_, target_;
  double best_ = kPruneMm;
};

}  // namespace

double ToolGeometry::SurfaceToCentreMm() const {
  return marker_type == MarkerType::kSphere ? 0.5 * marker_diameter_mm : 0.0;
}

void ToolGeometry::Check() const {
  const int n = static_cast<int>(markers_in_tool.size());
  Require(n >= 3, "ToolGeometry '" + name + "': needs at least 3 markers");
  Require(std::isfinite(marker_diameter_mm) && marker_diameter_mm > 0.0,
          "ToolGeometry '" + name + "': marker_diameter_mm must be > 0");
  Require(min_visible >= 3 && min_visible <= n,
          "ToolGeometry '" + name + "': min_visible must be in [3, marker count]");
  Require(std::isfinite(max_fre_mm) && max_fre_mm >= 0.0,
          "ToolGeometry '" + name + "': max_fre_mm must be >= 0");
  Require(!tip_in_tool || tip_in_tool->allFinite(), "ToolGeometry '" + name + "': non-finite tip");
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = markers_in_tool[static_cast<std::size_t>(i)];
    Require(p.allFinite(), "ToolGeometry '" + name + "': non-finite marker");
    for (int j = 0; j < i; ++j) {
      Require((p - markers_in_tool[static_cast<std::size_t>(j)]).norm() >= marker_diameter_mm,
              "ToolGeometry '" + name + "': markers " + std::to_string(j) + " and " +
                  std::to_string(i) + " are closer than one marker diameter (duplicate)");
    }
  }
  const std::vector<double> s = SingularValues(markers_in_tool);
  Require(s.size() >= 2 && s[1] / std::sqrt(static_cast<double>(n)) >= kCollinearMm,
          "ToolGeometry '" + name + "': markers are collinear");
}

Eigen::Vector3d MarkerPlaneNormal(const ToolGeometry& tool) {
  return ComputePrincipalAxes(tool.markers_in_tool).axes.col(2);  // the least spread
}

std::vector<MarkerPlate> MarkerPlates(const ToolGeometry& tool) {
  const Points3d& m = tool.markers_in_tool;
  const PrincipalAxes all = ComputePrincipalAxes(m);
  const MarkerPlate whole{all.axes.col(2),
                          all.spreads(2) / std::sqrt(static_cast<double>(m.size()))};
  std::vector<MarkerPlate> plates(m.size(), whole);
  if (m.size() <= 4) return plates;  // a marker and its three nearest: the whole tool
  for (std::size_t k = 0; k < m.size(); ++k) {
    std::vector<std::size_t> order(m.size());
    for (std::size_t i = 0; i < m.size(); ++i) order[i] = i;
    std::partial_sort(order.begin(), order.begin() + 4, order.end(),
                      [&](std::size_t a, std::size_t b) {
                        return (m[a] - m[k]).squaredNorm() < (m[b] - m[k]).squaredNorm();
                      });
    const Points3d local = {m[order[0]], m[order[1]], m[order[2]], m[order[3]]};
    const PrincipalAxes axes = ComputePrincipalAxes(local);
    if (axes.spreads(1) / 2.0 >= kCollinearMm) {
      plates[k] = {axes.axes.col(2), axes.spreads(2) / 2.0};  // sqrt(4) points
    }
  }
  return plates;
}

std::vector<Eigen::Vector3d> MarkerPlaneNormals(const ToolGeometry& tool) {
  std::vector<Eigen::Vector3d> normals;
  for (const MarkerPlate& p : MarkerPlates(tool)) normals.push_back(p.normal_in_tool);
  return normals;
}

ToolGeometryReport AnalyzeToolGeometry(const ToolGeometry& tool,
                                       std::span<const ToolGeometry> others) {
  tool.Check();
  const Points3d& m = tool.markers_in_tool;
  ToolGeometryReport r;
  for (std::size_t i = 0; i < m.size(); ++i) {
    for (std::size_t j = i + 1; j < m.size(); ++j) r.distances_mm.push_back((m[i] - m[j]).norm());
  }
  r.min_distance_mm = *std::min_element(r.distances_mm.begin(), r.distances_mm.end());
  r.max_distance_mm = *std::max_element(r.distances_mm.begin(), r.distances_mm.end());
  r.min_distance_difference_mm = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < r.distances_mm.size(); ++i) {
    for (std::size_t j = i + 1; j < r.distances_mm.size(); ++j) {
      r.min_distance_difference_mm =
          std::min(r.min_distance_difference_mm, std::abs(r.distances_mm[i] - r.distances_mm[j]));
    }
  }
  const int n = static_cast<int>(m.size());
  r.self_symmetry_fre_mm = ConfusionSearch(m, m, n, true).Run();
  const std::vector<double> s = SingularValues(m);
  r.planarity_rms_mm = s.size() >= 3 ? s[2] / std::sqrt(static_cast<double>(n)) : 0.0;
  for (const ToolGeometry& other : others) {
    other.Check();
    double min_difference = std::numeric_limits<double>::infinity();
    const Points3d& o = other.markers_in_tool;
    for (const double d : r.distances_mm) {
      for (std::size_t k = 0; k < o.size(); ++k) {
        for (std::size_t l = k + 1; l < o.size(); ++l) {
          min_difference = std::min(min_difference, std::abs(d - (o[k] - o[l]).norm()));
        }
      }
    }
    r.min_segment_difference_mm.push_back(min_difference);
    const int size = std::min(tool.min_visible, static_cast<int>(o.size()));
    r.confusion_fre_mm.push_back(ConfusionSearch(m, o, size, false).Run());
  }
  return r;
}

}  // namespace tofnav
