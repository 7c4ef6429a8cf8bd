// SPDX-License-Identifier: BSD-3-Clause
// Patient heads, skin stickers and the plan.
#include "tofnav/sim/patient.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sim/mesh_probe.hpp"

namespace tofnav::sim {

const MeshProbe& PatientHead::Probe() const {
  // Rebuilt when the anatomy centre moved (e.g. a scenario overrides it).
  if (!probe_ || probe_->origin() != anatomy.centre_in_image) {
    probe_ = std::make_shared<const MeshProbe>(skin_in_image, anatomy.centre_in_image);
  }
  return *probe_;
}

Rigid3d PhantomImageFromHead() {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitZ())),
          Eigen::Vector3d::Zero()};
}

PatientHead PhantomHead(const HeadPhantomOptions& options) {
  const Rigid3d image_from_head = PhantomImageFromHead();
  PatientHead head;
  head.source = "phantom";
  head.skin_in_image = Transform(image_from_head, HeadPhantomMesh(options));
  head.anatomy.centre_in_image = image_from_head.translation;
  head.anatomy.semi_axes_mm = options.semi_axes_mm;
  return head;
}

PatientHead MeshHead(TriangleMesh skin_in_image, std::string source) {
  Require(!skin_in_image.triangles.empty(), "MeshHead: the head mesh has no triangles");
  PatientHead head;
  head.source = std::move(source);
  head.anatomy = AnatomyFromBounds(skin_in_image);
  if (skin_in_image.vertex_normals.empty()) {
    skin_in_image.vertex_normals = skin_in_image.ComputeVertexNormals();
  }
  head.skin_in_image = std::move(skin_in_image);
  return head;
}

int AddPatient(Scenario& scenario, const PatientHead& head, int material, int mount,
               const Rigid3d& mount_from_image, const EvdPlanOptions& plan_options) {
  Require(!scenario.patient.has_value(), "AddPatient: the scenario already has a patient");
  Patient patient;
  patient.head_source = head.source;
  patient.anatomy = head.anatomy;
  patient.plan = PlanEvdTrajectories(head.Probe(), head.anatomy, plan_options);
  patient.object =
      scenario.AddObject("head", head.skin_in_image, material, mount, mount_from_image);
  scenario.patient = std::move(patient);
  return scenario.patient->object;
}

Eigen::Vector3d HeadDirection(double azimuth_rad, double elevation_rad) {
  // LPS: left +x, anterior -y, superior +z.
  return {std::sin(azimuth_rad) * std::cos(elevation_rad),
          -std::cos(azimuth_rad) * std::cos(elevation_rad), std::sin(elevation_rad)};
}

namespace {

// The skin points under a disc of `radius_mm` at `point` with unit `normal` (probed at its rim
// and half radius from 30 mm above, along -normal), with `point` first.
std::vector<Eigen::Vector3d> SkinUnderDisc(const TriangleMesh& skin, const Eigen::Vector3d& point,
                                           const Eigen::Vector3d& normal, double radius_mm) {
  constexpr double kAboveMm = 30.0;
  constexpr int kRimProbes = 16;
  const Eigen::Vector3d side = normal.unitOrthogonal(), up = normal.cross(side);
  std::vector<Eigen::Vector3d> points = {point};
  for (const double fraction : {0.5, 1.0}) {
    for (int k = 0; k < kRimProbes; ++k) {
      const double a = 2.0 * std::numbers::pi * k / kRimProbes;
      const Eigen::Vector3d above = point +
                                    fraction * radius_mm * (std::cos(a) * side + std::sin(a) * up) +
                                    kAboveMm * normal;
      if (const std::optional<MeshHit> hit = IntersectMesh(skin, above, -normal))
        points.push_back(hit->point);
    }
  }
  return points;
}

// How far the skin under a disc rises above the plane through its first point (0 on a smooth
// convex skin, millimetres on a rough one: a CT's wrinkles and brows), where a rigid flat
// sticker must be lifted that far or its rim sinks into the skin.
double SkinRise(const std::vector<Eigen::Vector3d>& under, const Eigen::Vector3d& normal) {
  double rise = 0.0;
  for (const Eigen::Vector3d& p : under) rise = std::max(rise, normal.dot(p - under.front()));
  return rise;
}

// The least-squares plane of the skin under a disc: through the points' mean, normal along
// their least-variance axis on the side of `normal` (one triangle's normal is rough on a CT or
// MR skin). The first point and `normal` when too few points were found.
std::pair<Eigen::Vector3d, Eigen::Vector3d> MeanPlane(const std::vector<Eigen::Vector3d>& under,
                                                      const Eigen::Vector3d& normal) {
  if (under.size() < 8) return {under.front(), normal};
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : under) mean += p;
  mean /= static_cast<double>(under.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : under) scatter += (p - mean) * (p - mean).transpose();
  const auto solver = DecomposeSymmetric(scatter);
  const Eigen::Vector3d axis = solver.vectors.col(0);
  return {mean, axis.dot(normal) >= 0.0 ? axis : Eigen::Vector3d(-axis)};
}

}  // namespace

Tool SkinStickers(std::string name, const PatientHead& head,
                  const std::vector<Eigen::Vector3d>& directions_in_image, double diameter_mm,
                  int material, int skin_object) {
  constexpr double kHeadRadiusMm = 90.0;  // curvature radius for the sag of a flat disc
  constexpr double kTapeMm = 0.1;         // a tape sticker's thickness
  // A rigid disc: 0.1 mm over the skin (not coplanar with it), plus a quarter of the sag on a
  // 90 mm head; on a rough skin at least as far as it rises over the footprint.
  const double sag_offset_mm = 0.1 + 0.25 * diameter_mm * diameter_mm / (2.0 * kHeadRadiusMm);
  Tool tool;
  tool.name = std::move(name);
  for (const Eigen::Vector3d& direction : directions_in_image) {
    const MeshHit hit = head.Probe().RequireHit(direction, "a sticker");
    const Eigen::Vector3d normal = hit.normal.normalized();
    const std::vector<Eigen::Vector3d> under =
        SkinUnderDisc(head.skin_in_image, hit.point, normal, 0.5 * diameter_mm);
    if (skin_object < 0) {
      tool.markers.push_back(DiscMarkerOnSurface(hit.point, normal, diameter_mm, material,
                                                 std::max(sag_offset_mm, SkinRise(under, normal))));
      continue;
    }
    // Tape over the skin's mean plane under it (it bridges wrinkles smaller than itself), its
    // centre where the probe ray's hit projects onto that plane.
    const auto [mean, plane_normal] = MeanPlane(under, normal);
    const Eigen::Vector3d on_plane = hit.point - plane_normal.dot(hit.point - mean) * plane_normal;
    Marker m = DiscMarkerOnSurface(on_plane, plane_normal, diameter_mm, material, kTapeMm);
    m.conforms_to_object = skin_object;
    tool.markers.push_back(m);
  }
  return tool;
}

}  // namespace tofnav::sim
