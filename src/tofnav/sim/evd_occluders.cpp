// SPDX-License-Identifier: BSD-3-Clause
// evd-usecase's drape, hand and instrument. Poses are built in the headframe mount (`image` at
// the anatomy centre: +x the patient's left, +y posterior, +z superior), then put in the world.
#include "tofnav/sim/evd_occluders.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sim/head_phantom.hpp"
#include "tofnav/sim/occluders.hpp"
#include "tofnav/sim/scenario_sanity.hpp"

namespace tofnav::sim {
namespace {

constexpr std::int64_t kMoveSlots = 10;   // about 0.2 s in, 0.2 s out (0.5-1.5 m/s)
constexpr std::int64_t kHoverSlots = 14;  // the hand over reference_right
constexpr std::int64_t kInstrumentHoverSlots = 18;
constexpr double kHandOverSkinMm = 70.0;   // hand axis above the forehead
constexpr double kHandOverToolMm = 35.0;   // the palm's axis over reference_right's plate
constexpr double kArrayOverToolMm = 25.0;  // the instrument's marker plane over reference_left's
constexpr double kDrapeOverNeckMm = 15.0;
constexpr double kDrapeClearanceMm = 22.0;  // opening beyond the cranium's cross-section

// A frame whose x axis is `x_axis` (the hand's forearm-to-fingers direction).
Eigen::Quaterniond AlongX(const Eigen::Vector3d& x_axis) {
  return RotationBetween(Eigen::Vector3d::UnitX(), x_axis.normalized());
}

// `v` without its component along unit `n`, normalised.
Eigen::Vector3d Across(const Eigen::Vector3d& v, const Eigen::Vector3d& n) {
  return (v - v.dot(n) * n).normalized();
}

int ToolIndex(const Scenario& s, const char* name) {
  for (std::size_t t = 0; t < s.scene.tools.size(); ++t) {
    if (s.scene.tools[t].name == name) return static_cast<int>(t);
  }
  return -1;
}

const Tool& NamedTool(const Scenario& s, const char* name) {
  const int t = ToolIndex(s, name);
  Require(t >= 0, std::string("AddEvdOccluders: no tool '") + name + "'");
  return s.scene.tools[static_cast<std::size_t>(t)];
}

// Lifts the keyframes of `mount`'s pass (slots first..last) along `up` by the least lift (to 0.25
// mm; at most 64 mm) with which no marker reaches into an object on that mount at those slots, as
// simulate's own check sees it (FindMarkerIntersections, here with no tolerance).
void LiftPassClear(Scenario& s, int mount, std::int64_t first, std::int64_t last,
                   const Eigen::Vector3d& up) {
  std::vector<Keyframe>& keys = s.mounts[static_cast<std::size_t>(mount)].motion.keyframes;
  const auto shift = [&](double lift_mm) {
    for (Keyframe& k : keys) {
      if (k.slot >= first && k.slot <= last) k.pose.translation += lift_mm * up;
    }
  };
  MarkerClearanceOptions options;
  options.tolerance_mm = 0.0;
  options.max_slots = 4096;
  const auto blocked = [&](double lift_mm) {
    shift(lift_mm);
    bool hit = false;
    for (const MarkerIntersection& m : FindMarkerIntersections(s, options)) {
      hit = hit || (m.slot >= first && m.slot <= last &&
                    s.object_mounts[static_cast<std::size_t>(m.object)] == mount);
    }
    shift(-lift_mm);
    return hit;
  };
  if (!blocked(0.0)) return;
  double low = 0.0, high = 8.0;
  while (high < 64.0 && blocked(high)) {
    low = high;
    high *= 2.0;
  }
  while (high - low > 0.25) {
    const double middle = 0.5 * (low + high);
    (blocked(middle) ? low : high) = middle;
  }
  shift(high);
}

}  // namespace

void AddEvdOccluders(Scenario& s, const PatientHead& head, int headframe, int retro) {
  const Rigid3d world_from_mount = s.mounts[static_cast<std::size_t>(headframe)].motion.start;
  const auto world = [&](const Rigid3d& mount_from_x) { return world_from_mount * mount_from_x; };
  const auto world_shift = [&](const Eigen::Vector3d& v) { return world_from_mount.rotation * v; };
  const Eigen::Vector3d& semi = head.anatomy.semi_axes_mm;

  // Drape: 15 mm above the neck cut, an opening 22 mm beyond the cranium's cross-section there.
  const double drape_z = -HeadPhantomOptions{}.neck_cut_fraction * semi.z() + kDrapeOverNeckMm;
  const double shrink = std::sqrt(std::max(0.0, 1.0 - (drape_z / semi.z()) * (drape_z / semi.z())));
  DrapeOptions drape;
  drape.opening_semi_axes_mm =
      shrink * semi.head<2>() + Eigen::Vector2d::Constant(kDrapeClearanceMm);
  const int cloth = s.scene.AddMaterial(DrapeMaterial());
  s.AddObject("drape", DrapeMesh(drape), cloth, headframe,
              {Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, drape_z)});

  // Hand: over the forehead from the patient's right, then over reference_right along its plate.
  const MeshHit forehead = head.Probe().RequireHit(HeadDirection(0.0, 0.55), "the forehead");
  const Eigen::Vector3d over_forehead =
      forehead.point - head.anatomy.centre_in_image + kHandOverSkinMm * forehead.normal;
  const HandOptions hand_options;
  const double hand_middle_mm = 0.5 * (hand_options.hand_length_mm - hand_options.hand_diameter_mm);
  Pass forehead_pass;
  forehead_pass.enter_slot = kEvdHandForeheadSlot;
  forehead_pass.move_slots = kMoveSlots;
  forehead_pass.hover_slots = 20;
  forehead_pass.hover = world({AlongX(Eigen::Vector3d::UnitX()),
                               over_forehead - Eigen::Vector3d(hand_middle_mm, 0.0, 0.0)});
  forehead_pass.approach_mm = world_shift({-300.0, 0.0, 0.0});
  forehead_pass.leave_mm = world_shift({-300.0, 0.0, 60.0});

  const Rigid3d& right = NamedTool(s, "reference_right").scene_from_tool;
  const Eigen::Vector3d right_normal = right.rotation * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d hand_axis = Across(-Eigen::Vector3d::UnitY(), right_normal);  // to the face
  Pass reference_pass;
  reference_pass.enter_slot = kEvdHandReferenceSlot;
  reference_pass.move_slots = kMoveSlots;
  reference_pass.hover_slots = kHoverSlots;
  reference_pass.hover =
      world({AlongX(hand_axis),
             right.translation + kHandOverToolMm * right_normal - hand_middle_mm * hand_axis});
  reference_pass.approach_mm = world_shift(-250.0 * hand_axis);
  reference_pass.leave_mm = world_shift(-250.0 * hand_axis + Eigen::Vector3d(0.0, 0.0, 60.0));

  // Parked behind the wandering headset (on the +z side of the world, looking at -z), far up.
  const Rigid3d parked(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 2500.0, 2500.0));
  const int skin = s.scene.AddMaterial(SkinMaterial());
  AddHand(s, "hand", hand_options, skin, PassesMotion(parked, {forehead_pass, reference_pass}));

  // Instrument: its array over reference_left, the rod pointing at the head across the plate.
  const Rigid3d& left = NamedTool(s, "reference_left").scene_from_tool;
  const Eigen::Vector3d left_normal = left.rotation * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d rod = Across(-left.translation, left_normal);  // towards the head
  const Eigen::Vector3d y_axis = -rod, x_axis = y_axis.cross(left_normal);
  Eigen::Matrix3d tool_axes;
  tool_axes << x_axis, y_axis, left_normal;
  const InstrumentOptions instrument;
  const Eigen::Vector3d tip = InstrumentTipInTool(instrument);
  const Eigen::Vector3d array_centre_in_tool(tip.x(), tip.y() + instrument.rod_length_mm, 0.0);
  const Eigen::Vector3d hover_centre = left.translation + kArrayOverToolMm * left_normal;
  Pass instrument_pass;
  instrument_pass.enter_slot = kEvdInstrumentSlot;
  instrument_pass.move_slots = kMoveSlots;
  instrument_pass.hover_slots = kInstrumentHoverSlots;
  instrument_pass.hover =
      world({Eigen::Quaterniond(tool_axes), hover_centre - tool_axes * array_centre_in_tool});
  instrument_pass.approach_mm = world_shift({250.0, 0.0, 150.0});  // from the left, above
  instrument_pass.leave_mm = instrument_pass.approach_mm;
  const int rod_material = s.scene.AddMaterial([] {
    Material m = DiffuseMaterial(0.3);  // a matt, anodised rod
    m.name = "instrument_rod";
    return m;
  }());
  const Rigid3d parked_apart(parked.rotation, parked.translation + Eigen::Vector3d(1000.0, 0, 0));
  AddInstrument(s, "instrument", instrument, retro, rod_material,
                PassesMotion(parked_apart, {instrument_pass}));
}

void ClearEvdHandOverTools(Scenario& s) {
  // The pass over each reference plate (PassesMotion's four keyframes, entering to leaving), lifted
  // along the plate's normal where it is at the hover (a drifting patient carries it).
  struct Over {
    const char* mount;
    const char* tool;
    std::int64_t first, hover_slots;
  };
  for (const Over& o :
       {Over{"hand_motion", "reference_right", kEvdHandReferenceSlot, kHoverSlots},
        Over{"instrument_motion", "reference_left", kEvdInstrumentSlot, kInstrumentHoverSlots}}) {
    const int mount = s.FindMount(o.mount), tool = ToolIndex(s, o.tool);
    if (mount < 0 || tool < 0) continue;
    const int tool_mount = s.tool_mounts[static_cast<std::size_t>(tool)];
    const Rigid3d world_from_mount =
        tool_mount < 0 ? Rigid3d::Identity()
                       : MotionPose(s.mounts[static_cast<std::size_t>(tool_mount)].motion,
                                    o.first + kMoveSlots, s.timing.rate_hz, 0);
    const Eigen::Vector3d up =
        world_from_mount.rotation *
        s.scene.tools[static_cast<std::size_t>(tool)].scene_from_tool.rotation *
        Eigen::Vector3d::UnitZ();
    LiftPassClear(s, mount, o.first, o.first + 2 * kMoveSlots + o.hover_slots, up);
  }
}

}  // namespace tofnav::sim
