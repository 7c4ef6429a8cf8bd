// SPDX-License-Identifier: BSD-3-Clause
// The patient of a scenario: head skin in CT image coordinates, stickers on it, its EVD plan.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/sim/evd_plan.hpp"
#include "tofnav/sim/head_phantom.hpp"
#include "tofnav/sim/mesh_probe.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// A head skin in `image` (CT LPS) coordinates and where its cranium lies.
struct PatientHead {
  std::string source;  // "phantom", "mesh:<path>"
  TriangleMesh skin_in_image;
  HeadAnatomy anatomy;
  /// Rays from the anatomy centre against the skin, built on first use.
  const MeshProbe& Probe() const;

 private:
  mutable std::shared_ptr<const MeshProbe> probe_;
};

/// image_from_head for the phantom: a half turn about z, so the phantom's +y (face) becomes LPS
/// anterior (-y) and +z stays superior; its centre is the image origin. The phantom is left-right
/// symmetric, so its +x becomes the right side (LPS -x).
Rigid3d PhantomImageFromHead();

/// The built-in phantom as a patient head (anatomy = its ellipsoid).
PatientHead PhantomHead(const HeadPhantomOptions& options = {});
/// A head mesh already in image coordinates (upright, LPS); anatomy from its bounding box.
PatientHead MeshHead(TriangleMesh skin_in_image, std::string source);

/// Adds the skin as scene object "head" with `material` on `mount` (-1: world) at
/// mount_from_image, plans the EVD trajectories and sets scenario.patient. Returns the object.
int AddPatient(Scenario& scenario, const PatientHead& head, int material, int mount,
               const Rigid3d& mount_from_image, const EvdPlanOptions& plan_options = {});

/// Skin direction in image coordinates from the anatomy centre at azimuth (to the patient's
/// left) and elevation (up) from straight anterior [rad].
Eigen::Vector3d HeadDirection(double azimuth_rad, double elevation_rad);

/// A tool of retro-reflective tape discs stuck on the skin where rays from the anatomy centre
/// along `directions_in_image` leave it; tool frame = image frame. With `skin_object` >= 0 (the
/// skin's index in the scene) each disc follows the skin 0.1 mm in front of it (tape bends to the
/// skin; Marker::conforms_to_object). With -1 each is a rigid flat disc lifted by its sag on a
/// 90 mm head or, on a rough skin, as far as the skin rises over its footprint (so no rim sinks
/// in): on a rough skin it then stands millimetres in front of the skin around it.
/// Add it on the patient's mount with mount_from_tool = mount_from_image.
Tool SkinStickers(std::string name, const PatientHead& head,
                  const std::vector<Eigen::Vector3d>& directions_in_image, double diameter_mm,
                  int material, int skin_object);

}  // namespace tofnav::sim
