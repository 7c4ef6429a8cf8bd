// SPDX-License-Identifier: BSD-3-Clause
// Skin extraction on real heads as clinical scans cut them (issue 16, docs/registration.md 1.):
// the Debian CT (invesalius-examples) and MR (mricron-data), read at test time, each cropped on
// every face through the head; skipped when a package is absent.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <tuple>

#include "tofnav/fusion/mesh_test_util.hpp"
#include "tofnav/imaging/skin.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {
namespace {

constexpr double kKeptFraction = 0.7;  // of the extent along the cropped axis
/// Triangles this close to the cut are left out of the comparison: the surface may differ
/// there (the cut face's own air classification, the ball padded past the border).
constexpr double kCutMarginMm = 10.0;
/// Away from the cut the cropped volume's voxels are the same, so the skin should be too: the
/// same vertices up to the round-off of a moved origin, and the same area (measured: all 12 crops
/// 100 % and 0.000 %). The slack allows for air pockets reached only across the cut (a sinus
/// opened by it), whose classification may change near the margin.
constexpr double kSameVertexMm = 1e-6;
constexpr double kMinSameVertexFraction = 0.99;
constexpr double kAreaRelTol = 0.005;

struct Case {
  const char* name;  // the test's suffix
  const char* path;
  const char* package;
};

/// Vertices hashed on a 1 mm grid: is there one within `tolerance` of p?
class VertexSet {
 public:
  explicit VertexSet(const Points3d& vertices) {
    for (const Eigen::Vector3d& v : vertices) cells_.emplace(Key(v), v);
  }
  bool Contains(const Eigen::Vector3d& p, double tolerance) const {
    const auto [first, last] = cells_.equal_range(Key(p));
    for (auto it = first; it != last; ++it) {
      if ((it->second - p).norm() <= tolerance) return true;
    }
    // A vertex at round-off distance across a cell boundary: look in the neighbours too.
    for (int n = 1; n < 27; ++n) {
      const Eigen::Vector3d q =
          p + tolerance * Eigen::Vector3d(n % 3 - 1, n / 3 % 3 - 1, n / 9 - 1);
      const auto [f, l] = cells_.equal_range(Key(q));
      for (auto it = f; it != l; ++it) {
        if ((it->second - p).norm() <= tolerance) return true;
      }
    }
    return false;
  }

 private:
  using CellKey = std::tuple<long, long, long>;
  static CellKey Key(const Eigen::Vector3d& p) {
    return {std::lround(std::floor(p.x())), std::lround(std::floor(p.y())),
            std::lround(std::floor(p.z()))};
  }
  std::multimap<CellKey, Eigen::Vector3d> cells_;
};

/// Area of the triangles whose centroid lies, along `axis`, inside voxel range [lo, hi].
double AreaBetween(const TriangleMesh& mesh, const CtVolume& volume, int axis, double lo,
                   double hi) {
  double area = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d &a = mesh.vertices[static_cast<std::size_t>(t[0])],
                          &b = mesh.vertices[static_cast<std::size_t>(t[1])],
                          &c = mesh.vertices[static_cast<std::size_t>(t[2])];
    const double index = volume.PointToIjk((a + b + c) / 3.0)[axis];
    if (index >= lo && index <= hi) area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

void ExpectValidMesh(const TriangleMesh& mesh) {
  ASSERT_GT(mesh.triangles.size(), 1000U);
  EXPECT_NO_THROW(mesh.CheckConsistent());  // indices in range
  for (const Eigen::Vector3d& v : mesh.vertices) ASSERT_TRUE(v.allFinite());
  for (const Eigen::Vector3d& n : mesh.vertex_normals) ASSERT_TRUE(n.allFinite());
  const EdgeCounts edges = CountEdges(mesh);
  EXPECT_EQ(edges.non_manifold, 0);
  EXPECT_EQ(edges.misoriented, 0);
}

class SkinRealVolumes : public testing::TestWithParam<Case> {};

TEST_P(SkinRealVolumes, CroppedOnEachFaceAgreesWithTheWholeSkin) {
  const Case& c = GetParam();
  if (!std::filesystem::exists(c.path)) GTEST_SKIP() << c.package << " not installed";
#ifdef TOFNAV_SANITIZED
  GTEST_SKIP() << "12 skin extractions take minutes under the sanitizers; the -Werror pass runs it";
#endif
  const CtVolume whole = ReadVolume(c.path);
  const SkinResult reference = ExtractSkin(whole);
  ExpectValidMesh(reference.mesh);
  const VertexSet reference_vertices(reference.mesh.vertices);
  for (int axis = 0; axis < 3; ++axis) {
    const int n = whole.dims[static_cast<std::size_t>(axis)];
    const int kept = static_cast<int>(std::lround(kKeptFraction * n));
    const double margin = kCutMarginMm / whole.spacing_mm()[axis];
    for (const bool keep_low : {true, false}) {
      SCOPED_TRACE(testing::Message()
                   << c.path << " axis " << axis << (keep_low ? " low" : " high"));
      std::array<int, 3> first = {0, 0, 0}, dims = whole.dims;
      first[static_cast<std::size_t>(axis)] = keep_low ? 0 : n - kept;
      dims[static_cast<std::size_t>(axis)] = kept;
      const CtVolume crop = CropVolume(whole, first, dims);
      // The whole volume's threshold: Otsu's (MR) depends on the field of view, the property
      // tested here is how the border is meshed.
      SkinOptions options;
      options.threshold = reference.threshold;
      const SkinResult skin = ExtractSkin(crop, options);
      ExpectValidMesh(skin.mesh);
      // In the whole volume's voxel indices: the kept range without the margin at the cut.
      const double lo = keep_low ? 0.0 : n - kept + margin;
      const double hi = keep_low ? kept - 1 - margin : n - 1.0;
      const double area = AreaBetween(skin.mesh, whole, axis, lo, hi);
      const double reference_area = AreaBetween(reference.mesh, whole, axis, lo, hi);
      std::size_t compared = 0, same = 0;
      for (const Eigen::Vector3d& v : skin.mesh.vertices) {
        const double index = whole.PointToIjk(v)[axis];
        if (index < lo || index > hi) continue;
        ++compared;
        same += reference_vertices.Contains(v, kSameVertexMm) ? 1 : 0;
      }
      const double same_fraction = static_cast<double>(same) / static_cast<double>(compared);
      std::printf(
          "%s axis %d %s: %zu triangles, area %.0f vs %.0f mm^2 (%+.3f %%), %.4f of %zu "
          "vertices the same\n",
          std::filesystem::path(c.path).filename().c_str(), axis, keep_low ? "low" : "high",
          skin.mesh.triangles.size(), area, reference_area, 100.0 * (area / reference_area - 1.0),
          same_fraction, compared);
      EXPECT_NEAR(area, reference_area, kAreaRelTol * reference_area);
      EXPECT_GE(same_fraction, kMinSameVertexFraction);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    DebianHeads, SkinRealVolumes,
    testing::Values(Case{"CraniumCt", "/usr/share/doc/invesalius-examples/examples/Cranium.inv3",
                         "invesalius-examples"},
                    Case{"Ch2Mr", "/usr/share/mricron/templates/ch2.nii.gz", "mricron-data"}),
    [](const testing::TestParamInfo<Case>& param_info) {
      return std::string(param_info.param.name);
    });

}  // namespace
}  // namespace tofnav
