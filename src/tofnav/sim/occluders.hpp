// SPDX-License-Identifier: BSD-3-Clause
// Things of an operating room that come between the headset and the markers: a hand and forearm,
// a tracked instrument, a surgical drape (docs/simulator.md section 6.4).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/sim/motion.hpp"
#include "tofnav/sim/scenario.hpp"
#include "tofnav/sim/scene.hpp"

namespace tofnav::sim {

/// A forearm and hand as two capsules on the x axis (adult sizes: forearm 60-70 mm thick, hand
/// about 45 mm thick and 180 mm from wrist to fingertips).
struct HandOptions {
  double forearm_diameter_mm = 65.0;
  double forearm_length_mm = 250.0;
  double hand_diameter_mm = 45.0;
  double hand_length_mm = 180.0;
  int segments = 32;  // around each capsule
  void Check() const;
};

/// Closed mesh in the hand frame: origin at the wrist, +x towards the fingertips. The hand capsule
/// spans x = -hand_diameter / 2 .. hand_length - hand_diameter / 2 (its rear cap centred on the
/// wrist), the forearm x = -forearm_length .. 0 (its front cap swallows the hand's rear cap).
TriangleMesh HandMesh(const HandOptions& options = {});

/// A large cloth around the head: a sheet in the z = 0 plane (normal +z) with an elliptical
/// opening, optionally wrinkled by a seeded height field.
struct DrapeOptions {
  double width_mm = 900.0;                               // along x
  double height_mm = 700.0;                              // along y
  Eigen::Vector2d opening_semi_axes_mm = {90.0, 110.0};  // centred on the origin
  double cell_mm = 8.0;                                  // about the mesh's edge length
  double wrinkle_amplitude_mm = 6.0;                     // peak height of the folds (0: flat)
  double wrinkle_wavelength_mm = 120.0;
  std::uint64_t seed = 1;  // the folds' directions, wavelengths and phases
  void Check() const;
};

/// The drape's open mesh (vertex normals towards +z). Height z(x, y) = amplitude * sum_k w_k
/// sin(2 pi u_k . (x, y) / lambda_k + phi_k) / sum_k w_k over six seeded folds: directions u_k
/// uniform, lambda_k in 0.6 .. 1.4 x the wavelength, weights w_k = 1 / (k + 1).
TriangleMesh DrapeMesh(const DrapeOptions& options = {});

/// A rod carrying a tracked marker array (a pointer, an EVD stylet holder): the markers of a tool
/// preset, and a rod that runs 1 mm behind the preset's z = 0 plane from under the markers'
/// centroid along -y of the tool frame.
struct InstrumentOptions {
  std::string preset = "spheres-four";  // sim/tool_presets.hpp
  double rod_diameter_mm = 4.0;
  double rod_length_mm = 200.0;
  void Check() const;
};

/// The rod's mesh in the tool frame of ToolPreset(options.preset, ...).
TriangleMesh InstrumentRodMesh(const InstrumentOptions& options = {});
/// The rod's far end (the tip) in the tool frame.
Eigen::Vector3d InstrumentTipInTool(const InstrumentOptions& options = {});

/// Adds object `name` (HandMesh) on a new mount `<name>_motion` moving with `motion`; returns the
/// object.
int AddHand(Scenario& scenario, const std::string& name, const HandOptions& options, int material,
            Motion motion);
/// Adds tool `name` (the preset's markers, `marker_material`) and object `<name>_rod` on a new
/// mount `<name>_motion`; returns the tool.
int AddInstrument(Scenario& scenario, const std::string& name, const InstrumentOptions& options,
                  int marker_material, int rod_material, Motion motion);

/// An occluder that comes in, hovers and leaves: parked (out of view) until `enter_slot`, then at
/// `hover` shifted by `approach_mm`, moving to `hover` in `move_slots`, holding it for
/// `hover_slots`, leaving to `hover` shifted by `leave_mm` in `move_slots`, parked again.
struct Pass {
  std::int64_t enter_slot = 0;
  std::int64_t move_slots = 10;
  std::int64_t hover_slots = 20;
  Rigid3d hover;  // world_from_mount while hovering
  Eigen::Vector3d approach_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d leave_mm = Eigen::Vector3d::Zero();
};
/// Keyframes of the passes (in slot order, not overlapping) between stays at `parked`.
Motion PassesMotion(const Rigid3d& parked, const std::vector<Pass>& passes);

}  // namespace tofnav::sim
