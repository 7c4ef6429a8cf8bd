// SPDX-License-Identifier: BSD-3-Clause
// evd-usecase's drape, hand and instrument. Poses are built in the headframe mount (`image` at
// the anatomy centre: +x the patient's left, +y posterior, +z superior), then put in the world.
#include "tofnav/sim/evd_occluders.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sim/head_phantom.hpp"
#include "tofnav/sim/occluders.hpp"

namespace tofnav::sim {
namespace {

constexpr std::int64_t kMoveSlots = 10;    // about 0.2 s in, 0.2 s out (0.5-1.5 m/s)
constexpr std::int64_t kHoverSlots = 14;   // over reference_right
constexpr double kHandOverSkinMm = 70.0;   // hand axis above the forehead
constexpr double kHandOverToolMm = 35.0;   // the palm's axis over reference_right's plate
constexpr double kArrayOverToolMm = 25.0;  // the instrument's marker plane over reference_left's
constexpr double kDrapeOverNeckMm = 15.0;
constexpr double kDrapeClearanceMm = 22.0;  // opening beyond the cranium's cross-section

// A frame whose x axis is `x_axis` (the hand's forearm-to-fingers direction).
Eigen::Quaterniond AlongX(const Eigen::Vector3d& x_axis) {
  return RotationBetween(Eigen::Vector3d::UnitX(), x_axis.normalized());
}

const Tool& NamedTool(const Scenario& s, const char* name) {
  for (const Tool& t : s.scene.tools) {
    if (t.name == name) return t;
  }
  Require(false, std::string("AddEvdOccluders: no tool '") + name + "'");
  return s.scene.tools.front();
}

// `v` without its component along unit `n`, normalised.
Eigen::Vector3d Across(const Eigen::Vector3d& v, const Eigen::Vector3d& n) {
  return (v - v.dot(n) * n).normalized();
}

// The palm axis's height over a tool's plate (its z = 0 plane) for a hand hovering along unit
// `axis_in_tool` (in the plate) with its middle over the tool's origin: kHandOverToolMm, or as
// high as keeps every marker out of the hand and the forearm (HandMesh's two capsules, both along
// the axis): a sphere by its centre and radius, a disc by its centre and rim. Spheres on posts
// reach 19.4 mm above the plate, higher than the 12.5 mm the default leaves under the palm.
double HandOverToolMm(const Tool& tool, const Eigen::Vector3d& axis_in_tool, double hand_middle_mm,
                      const HandOptions& hand) {
  const Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(axis_in_tool);
  const double wrist = -hand_middle_mm;  // along the axis, from the tool's origin
  struct Capsule {
    double from, to, radius;
  };
  const double forearm_r = 0.5 * hand.forearm_diameter_mm, hand_r = 0.5 * hand.hand_diameter_mm;
  const Capsule capsules[] = {
      {wrist, wrist + hand.hand_length_mm - hand.hand_diameter_mm, hand_r},
      {wrist - hand.forearm_length_mm + forearm_r, wrist - forearm_r, forearm_r}};
  double height = kHandOverToolMm;
  const auto keep_out = [&](const Eigen::Vector3d& p, double r) {
    const double along = p.dot(axis_in_tool), side = p.dot(across);
    for (const Capsule& c : capsules) {
      const double gap = std::max({0.0, c.from - along, along - c.to});
      const double reach = c.radius + r, lateral_sq = gap * gap + side * side;
      if (lateral_sq < reach * reach) {
        height = std::max(height, p.z() + std::sqrt(reach * reach - lateral_sq));
      }
    }
  };
  for (const Marker& m : tool.markers) {
    if (m.shape == MarkerShape::kSphere) {
      keep_out(m.centre_in_tool, 0.5 * m.diameter_mm);
      continue;
    }
    keep_out(m.centre_in_tool, 0.0);
    const Eigen::Vector3d u = m.normal_in_tool.unitOrthogonal(), v = m.normal_in_tool.cross(u);
    for (int k = 0; k < 16; ++k) {
      const double a = 2.0 * std::numbers::pi * k / 16.0;
      keep_out(m.centre_in_tool + 0.5 * m.diameter_mm * (std::cos(a) * u + std::sin(a) * v), 0.0);
    }
  }
  return height;
}

int ToolIndex(const Scenario& s, const char* name) {
  for (std::size_t t = 0; t < s.scene.tools.size(); ++t) {
    if (s.scene.tools[t].name == name) return static_cast<int>(t);
  }
  return -1;
}

// reference_right's plate normal and the hand's axis over it (mount frame; both AddEvdOccluders
// and ClearEvdHandOverTools).
std::pair<Eigen::Vector3d, Eigen::Vector3d> RightNormalAndHandAxis(const Tool& right) {
  const Eigen::Vector3d normal = right.scene_from_tool.rotation * Eigen::Vector3d::UnitZ();
  return {normal, Across(-Eigen::Vector3d::UnitY(), normal)};  // the hand points to the face
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

  const Tool& right_tool = NamedTool(s, "reference_right");
  const Rigid3d& right = right_tool.scene_from_tool;
  const auto [right_normal, hand_axis] = RightNormalAndHandAxis(right_tool);
  const double over_tool_mm = HandOverToolMm(right_tool, right.rotation.inverse() * hand_axis,
                                             hand_middle_mm, hand_options);
  Pass reference_pass;
  reference_pass.enter_slot = kEvdHandReferenceSlot;
  reference_pass.move_slots = kMoveSlots;
  reference_pass.hover_slots = kHoverSlots;
  reference_pass.hover = world({AlongX(hand_axis), right.translation + over_tool_mm * right_normal -
                                                       hand_middle_mm * hand_axis});
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
  instrument_pass.hover_slots = 18;
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
  const int hand_mount = s.FindMount("hand_motion");
  const int right = ToolIndex(s, "reference_right");
  if (hand_mount < 0 || right < 0) return;
  const Tool& tool = s.scene.tools[static_cast<std::size_t>(right)];
  const int tool_mount = s.tool_mounts[static_cast<std::size_t>(right)];
  const Rigid3d world_from_mount =
      tool_mount < 0 ? Rigid3d::Identity()
                     : s.mounts[static_cast<std::size_t>(tool_mount)].motion.start;
  const auto [normal, hand_axis] = RightNormalAndHandAxis(tool);
  const HandOptions hand;
  const double middle = 0.5 * (hand.hand_length_mm - hand.hand_diameter_mm);
  const double needed =
      HandOverToolMm(tool, tool.scene_from_tool.rotation.inverse() * hand_axis, middle, hand);
  Motion& motion = s.mounts[static_cast<std::size_t>(hand_mount)].motion;
  // The pass over reference_right: its four keyframes from entering to leaving (PassesMotion).
  const std::int64_t first = kEvdHandReferenceSlot, last = first + 2 * kMoveSlots + kHoverSlots;
  double height = needed;
  for (const Keyframe& k : motion.keyframes) {
    if (k.slot == first + kMoveSlots) {  // the hover: the palm axis's height over the plate
      height = (world_from_mount.Inverse() * k.pose).translation.dot(normal) -
               tool.scene_from_tool.translation.dot(normal);
    }
  }
  if (needed <= height) return;
  const Eigen::Vector3d lift = (needed - height) * (world_from_mount.rotation * normal);
  for (Keyframe& k : motion.keyframes) {
    if (k.slot >= first && k.slot <= last) k.pose.translation += lift;
  }
}

}  // namespace tofnav::sim
