// SPDX-License-Identifier: BSD-3-Clause
// Ray queries against triangle meshes. Plain double arithmetic in the loop: it runs over every
// triangle of a head mesh per query, also in unoptimised test builds.
#include "tofnav/sim/mesh_probe.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

struct V3 {
  double x, y, z;
};
V3 Sub(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 Cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double Dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 Load(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace

std::optional<MeshHit> IntersectMesh(const TriangleMesh& mesh, const Eigen::Vector3d& origin,
                                     const Eigen::Vector3d& direction) {
  const Eigen::Vector3d unit = direction.normalized();
  Require(unit.allFinite() && origin.allFinite(), "IntersectMesh: bad ray");
  const V3 o = Load(origin), d = Load(unit);
  const Eigen::Vector3d* vertices = mesh.vertices.data();
  double best = INFINITY;
  std::size_t best_triangle = 0;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {  // Moller & Trumbore 1997
    const int* t = mesh.triangles[i].data();
    const V3 a = Load(vertices[t[0]]);
    const V3 e1 = Sub(Load(vertices[t[1]]), a), e2 = Sub(Load(vertices[t[2]]), a);
    const V3 p = Cross(d, e2);
    const double det = Dot(e1, p);
    if (std::abs(det) < 1e-12) continue;  // parallel or degenerate
    const V3 s = Sub(o, a);
    const double u = Dot(s, p) / det;
    if (u < 0.0 || u > 1.0) continue;
    const V3 q = Cross(s, e1);
    const double v = Dot(d, q) / det;
    if (v < 0.0 || u + v > 1.0) continue;
    const double distance = Dot(e2, q) / det;
    if (distance <= 0.0 || distance >= best) continue;
    best = distance;
    best_triangle = i;
  }
  if (!std::isfinite(best)) return std::nullopt;
  const Eigen::Vector3i& t = mesh.triangles[best_triangle];
  const Eigen::Vector3d& a = vertices[t[0]];
  const Eigen::Vector3d normal = (vertices[t[1]] - a).cross(vertices[t[2]] - a).normalized();
  return MeshHit{best, origin + best * unit, normal};
}

MeshHit RequireMeshHit(const TriangleMesh& mesh, const Eigen::Vector3d& origin,
                       const Eigen::Vector3d& direction, const char* what) {
  const std::optional<MeshHit> hit = IntersectMesh(mesh, origin, direction);
  Require(hit.has_value(), std::string("no surface found for ") + what);
  return *hit;
}

Scene MeshProbe::OneObjectScene(const TriangleMesh& mesh) {
  Scene scene;
  scene.AddObject("probe", mesh, scene.AddMaterial(DiffuseMaterial(0.5)), Rigid3d::Identity());
  return scene;
}

MeshProbe::MeshProbe(const TriangleMesh& mesh, const Eigen::Vector3d& origin)
    : origin_(origin), scene_(OneObjectScene(mesh)), raycaster_(scene_) {
  // The rays' frame: at the origin, axes parallel to the mesh frame.
  raycaster_.SetPoses(scene_, Rigid3d(Eigen::Quaterniond::Identity(), origin));
}

std::optional<MeshHit> MeshProbe::Intersect(const Eigen::Vector3d& direction) const {
  const Eigen::Vector3d unit = direction.normalized();
  Require(unit.allFinite(), "MeshProbe: bad direction");
  RayHit hit;
  raycaster_.Intersect({&unit, 1}, {&hit, 1});
  if (!hit.hit()) return IntersectMesh(scene_.objects.front().mesh, origin_, unit);
  return MeshHit{hit.range_mm, origin_ + hit.range_mm * unit, hit.normal_in_ahat};
}

MeshHit MeshProbe::RequireHit(const Eigen::Vector3d& direction, const char* what) const {
  const std::optional<MeshHit> hit = Intersect(direction);
  Require(hit.has_value(), std::string("no surface found for ") + what);
  return *hit;
}

}  // namespace tofnav::sim
