// SPDX-License-Identifier: BSD-3-Clause
// Patient heads, skin stickers and the plan.
#include "tofnav/sim/patient.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <utility>

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

Tool SkinStickers(std::string name, const PatientHead& head,
                  const std::vector<Eigen::Vector3d>& directions_in_image, double diameter_mm,
                  int material) {
  constexpr double kHeadRadiusMm = 90.0;  // curvature radius for the sag of a flat disc
  const double offset_mm = 0.1 + 0.25 * diameter_mm * diameter_mm / (2.0 * kHeadRadiusMm);
  Tool tool;
  tool.name = std::move(name);
  for (const Eigen::Vector3d& direction : directions_in_image) {
    const MeshHit hit = head.Probe().RequireHit(direction, "a sticker");
    tool.markers.push_back(
        DiscMarkerOnSurface(hit.point, hit.normal, diameter_mm, material, offset_mm));
  }
  return tool;
}

}  // namespace tofnav::sim
