// SPDX-License-Identifier: BSD-3-Clause
// The paper's experiments as scenarios. World = HoloLens world: +y up, the wearer or the fixed
// headset on the +z side of the set-up, distances from the AHAT optical centre.
#include "tofnav/sim/scenario_builtins.hpp"

#include <Eigen/Geometry>
#include <numbers>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/sim/evd_occluders.hpp"
#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/scenario_pivot.hpp"
#include "tofnav/sim/scenario_verify.hpp"
#include "tofnav/sim/shapes.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav::sim {
namespace {

constexpr double kRateHz = 45.0;

Rigid3d Translation(const Eigen::Vector3d& t) { return {Eigen::Quaterniond::Identity(), t}; }

Rigid3d Rotation(double angle_rad, const Eigen::Vector3d& axis) {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis)), Eigen::Vector3d::Zero()};
}

// world_from_image of an upright head whose face looks at +z: LPS left -> +x, posterior -> -z,
// superior -> +y.
Rigid3d WorldFromUprightImage(const Eigen::Vector3d& head_centre_in_world) {
  Eigen::Matrix3d r;
  r << 1, 0, 0,  //
      0, 0, 1,   //
      0, -1, 0;
  return {Eigen::Quaterniond(r), head_centre_in_world};
}

Material Named(Material m, std::string name) {
  m.name = std::move(name);
  return m;
}

// A preset tool with its plate (an object "<name>_plate") on `mount`.
int AddToolWithPlate(Scenario& s, const std::string& preset, const std::string& name, int mount,
                     const Rigid3d& mount_from_tool, int retro, int plate_material) {
  const Eigen::Vector2d plate = ToolPresetPlateMm(preset);
  if (plate.x() > 0.0 && plate_material >= 0) {  // -1: the markers sit on another surface
    s.AddObject(name + "_plate", PlaneMesh(plate.x(), plate.y()), plate_material, mount,
                mount_from_tool);
  }
  Tool tool = ToolPreset(preset, name, retro);
  tool.scene_from_tool = mount_from_tool;
  return s.AddTool(std::move(tool), mount);
}

// Camera fixed in the world at `eye`, looking at `target`.
Motion FixedCamera(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  return StaticMotion(LookAt(eye, target));
}

Scenario MarkerStage(const PatientHead* /*no patient*/) {
  Scenario s;
  s.name = "marker-stage";
  s.description =
      "IR-tape structure (seven tape circles) on a linear stage moving 300 -> 700 mm away from a "
      "fixed headset at 40 mm/s, tilted 0, 10, 20 and 30 deg (Sec. III-A.1, f_rf)";
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial(RetroCurve::kLinear));
  const int pla = s.scene.AddMaterial(PlaMaterial());
  const Eigen::Vector3d eye(0.0, 300.0, 0.0);
  s.camera.motion = FixedCamera(eye, eye - Eigen::Vector3d::UnitZ());
  constexpr double kSpeedMmPerS = 40.0, kTravelMm = 400.0;
  constexpr auto kRunSlots = static_cast<std::int64_t>(kTravelMm / kSpeedMmPerS * kRateHz);
  std::vector<Motion> runs;
  for (const double tilt_deg : {0.0, 10.0, 20.0, 30.0}) {
    const Eigen::Vector3d centre = eye + Eigen::Vector3d(15.0, -10.0, -300.0);
    const Rigid3d facing = LookAt(centre, centre + Eigen::Vector3d::UnitZ());  // parallel to it
    const Rigid3d start = Translation(centre) *
                          Rotation(tilt_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
                          Rigid3d(facing.rotation, Eigen::Vector3d::Zero());
    Motion run = LinearStageMotion(start, -Eigen::Vector3d::UnitZ(), kSpeedMmPerS, kTravelMm);
    run.segment_slots = kRunSlots;
    runs.push_back(std::move(run));
  }
  const int stage = s.AddMount("stage", SequenceMotion(std::move(runs)));
  AddToolWithPlate(s, "tape-seven", "tape_structure", stage, Rigid3d::Identity(), retro, pla);
  s.frames = 4 * kRunSlots;
  return s;
}

Scenario Materials(const PatientHead* /*no patient*/) {
  Scenario s;
  s.name = "materials";
  s.description =
      "Nylon, PLA, photopolymer and PC-ABS samples in a retro-reflective reference plane, static "
      "at 15 depths 382-655 mm x 6 angles 5-45 deg, 250 frames each (Sec. III-A.2)";
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial(RetroCurve::kLinear));
  const std::vector<Material> samples = {NylonMaterial(), PlaMaterial(), PhotopolymerMaterial(),
                                         PcAbsMaterial()};
  const Eigen::Vector3d eye(0.0, 300.0, 0.0);
  s.camera.motion = FixedCamera(eye, eye - Eigen::Vector3d::UnitZ());
  constexpr std::int64_t kStationSlots = 250;
  constexpr int kDepths = 15;
  std::vector<Motion> stations;
  for (const double angle_deg : {5.0, 13.0, 21.0, 29.0, 37.0, 45.0}) {
    for (int d = 0; d < kDepths; ++d) {
      const double depth_mm = 382.0 + (655.0 - 382.0) * d / (kDepths - 1);
      const Eigen::Vector3d centre = eye - depth_mm * Eigen::Vector3d::UnitZ();
      Motion station = StaticMotion(Translation(centre) *
                                    Rotation(angle_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
                                    Rigid3d(LookAt(centre, eye).rotation, Eigen::Vector3d::Zero()));
      station.segment_slots = kStationSlots;
      stations.push_back(std::move(station));
    }
  }
  const int holder = s.AddMount("holder", SequenceMotion(std::move(stations)));
  s.AddObject("reference_plane", PlaneMesh(240.0, 180.0), retro, holder, Rigid3d::Identity());
  const Eigen::Vector2d slots[4] = {{-55.0, -42.0}, {55.0, -42.0}, {-55.0, 42.0}, {55.0, 42.0}};
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const int material = s.scene.AddMaterial(samples[i]);
    s.AddObject(samples[i].name + "_sample", PlaneMesh(50.0, 50.0), material, holder,
                Translation({slots[i].x(), slots[i].y(), 0.05}));
  }
  s.frames = 6 * kDepths * kStationSlots;
  return s;
}

// An upright head on a static mount, and a table under it. The mount's frame is the image frame
// moved to the head's anatomy centre (identity for the phantom).
int AddUprightPatient(Scenario& s, const PatientHead& head, int skin_material,
                      const std::string& mount_name, const Eigen::Vector3d& centre_in_world) {
  const int table_material = s.scene.AddMaterial(Named(DiffuseMaterial(0.45), "acrylic"));
  const int mount = s.AddMount(mount_name, StaticMotion(WorldFromUprightImage(centre_in_world)));
  AddPatient(s, head, skin_material, mount, Translation(-head.anatomy.centre_in_image));
  const double neck_mm = -HeadPhantomOptions{}.neck_cut_fraction * head.anatomy.semi_axes_mm.z();
  s.AddObject(mount_name + "_board", PlaneMesh(600.0, 450.0), table_material, mount,
              Translation({0.0, 0.0, neck_mm - 0.5}));
  return mount;
}

// Stickers on the patient's skin: their tool frame is the image frame.
void AddStickers(Scenario& s, Tool stickers, int mount) {
  s.AddTool(std::move(stickers), mount);
  s.scene.tools.back().scene_from_tool =
      s.scene.objects[static_cast<std::size_t>(s.patient->object)].scene_from_object;
}

// The built-in phantom unless the caller gave a head.
PatientHead HeadOrPhantom(const PatientHead* head) { return head ? *head : PhantomHead(); }

// The headset worn by someone looking at `target` from the +z side.
Motion Wearer(const Eigen::Vector3d& target, double period_s) {
  Motion motion;
  motion.kind = MotionKind::kHeadWorn;
  motion.head_worn.target_in_world = target;
  motion.head_worn.period_s = period_s;
  return motion;
}

Scenario HeadIdentification(const PatientHead* given_head) {
  Scenario s;
  s.name = "head-identification";
  s.description =
      "Photopolymer head phantom with four 10 mm markers on the forehead, 1000 frames from a "
      "wandering headset at 300-700 mm (Sec. III-A.5, IV-A)";
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial(RetroCurve::kLinear));
  const int skin = s.scene.AddMaterial(PhotopolymerMaterial());
  const Eigen::Vector3d centre(0.0, 200.0, 0.0);
  const PatientHead head = HeadOrPhantom(given_head);
  const int mount = AddUprightPatient(s, head, skin, "table", centre);
  AddStickers(s,
              SkinStickers("forehead_markers", head,
                           {HeadDirection(-0.30, 0.45), HeadDirection(0.28, 0.47),
                            HeadDirection(-0.10, 0.72), HeadDirection(0.16, 0.62)},
                           10.0, retro, s.patient->object),
              mount);
  s.camera.motion = Wearer(WorldFromUprightImage(centre) * Eigen::Vector3d(0.0, -60.0, 40.0), 6.0);
  s.camera.motion.head_worn.azimuth_span_rad = 1.6;
  s.timing.drop_probability = 0.01;
  s.frames = 1000;
  return s;
}

Scenario DepthAccuracy(const PatientHead* /*no patient*/) {
  Scenario s;
  s.name = "depth-accuracy";
  s.description =
      "Triangular pyramid, frustum pyramid and hemisphere (120 mm, photopolymer) on a board with "
      "a six-marker reference, static and facing the headset at about 300 mm, 300 frames "
      "(Sec. IV-A)";
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial(RetroCurve::kLinear));
  const int board_material = s.scene.AddMaterial(Named(DiffuseMaterial(0.45), "acrylic"));
  const int photopolymer = s.scene.AddMaterial(PhotopolymerMaterial());
  const Eigen::Vector3d eye(0.0, 300.0, 0.0), board_centre(0.0, 280.0, -300.0);
  s.camera.motion = FixedCamera(eye, board_centre);
  const int board =
      s.AddMount("stand", StaticMotion(Rigid3d(LookAt(board_centre, eye).rotation, board_centre) *
                                       Rotation(10.0 * kDegToRad, Eigen::Vector3d::UnitY())));
  s.AddObject("board", PlaneMesh(480.0, 300.0), board_material, board, Rigid3d::Identity());
  const std::pair<const char*, TestShape> shapes[] = {
      {"triangular_pyramid", TestShape::kTriangularPyramid},
      {"frustum_pyramid", TestShape::kFrustumPyramid},
      {"hemisphere", TestShape::kHemisphere}};
  double x_mm = -150.0;
  for (const auto& [name, shape] : shapes) {
    s.AddObject(name, TestShapeMesh(shape, kTestShapeSizesMm[0]), photopolymer, board,
                Translation({x_mm, 25.0, 0.05}));
    x_mm += 150.0;
  }
  AddToolWithPlate(s, "planar-six", "reference", board, Translation({0.0, -110.0, 0.0}), retro, -1);
  s.frames = 300;
  return s;
}

// The rotation platform of Sec. IV-B: top centre at the world origin, +y up, sweeping +-45 deg
// about y at 8 deg/s; an acrylic top of width x depth [mm]. Returns the mount.
int AddTurntable(Scenario& s, int material, double width_mm, double depth_mm) {
  Motion turning;
  turning.kind = MotionKind::kRotation;
  turning.start = Rigid3d::Identity();
  turning.rotation = {Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero(), 8.0 * kDegToRad,
                      -45.0 * kDegToRad, 90.0 * kDegToRad};
  const int platform = s.AddMount("turntable", turning);
  s.AddObject("platform", BoxMesh({width_mm, 20.0, depth_mm}), material, platform,
              Translation({0.0, -10.0, 0.0}));
  return platform;
}

Scenario Reconstruction(const PatientHead* given_head) {
  Scenario s;
  s.name = "reconstruction";
  s.description =
      "Nylon head phantom and a six-marker planar tool on a rotation platform sweeping +-45 deg at "
      "8 deg/s, fixed headset 300-500 mm away, 2000 frames (Sec. IV-B)";
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial(RetroCurve::kLinear));
  const int nylon = s.scene.AddMaterial(NylonMaterial());
  const int acrylic = s.scene.AddMaterial(Named(DiffuseMaterial(0.45), "acrylic"));
  const int platform = AddTurntable(s, acrylic, 320.0, 320.0);
  const PatientHead head = HeadOrPhantom(given_head);
  const double neck_mm = HeadPhantomOptions{}.neck_cut_fraction * head.anatomy.semi_axes_mm.z();
  const Eigen::Vector3d head_centre(0.0, neck_mm + 0.5, 0.0);
  AddPatient(s, head, nylon, platform,
             WorldFromUprightImage(head_centre) * Translation(-head.anatomy.centre_in_image));
  const Eigen::Vector3d eye(0.0, head_centre.y() + 200.0, 350.0);
  const Eigen::Vector3d tool_centre(125.0, 40.0, 45.0);
  AddToolWithPlate(s, "planar-six", "planar_tool", platform,
                   Rigid3d(LookAt(tool_centre, eye).rotation, tool_centre), retro, acrylic);
  s.camera.motion = FixedCamera(eye, head_centre);
  s.frames = 2000;
  return s;
}

// The paper's Table II objects: triangular pyramid, frustum pyramid and hemisphere in the four
// sizes, named "<shape>_size<k>" (k = 1..4 for 120, 60, 35, 20 mm), standing on a turntable with
// the six-marker tool; big ones at the back. Same sweep and range as "reconstruction" (Sec. IV-B).
Scenario ReconstructionShapes(const char* name, Material material) {
  Scenario s;
  s.name = name;
  s.description = "Triangular pyramid, frustum pyramid and hemisphere in the four sizes (" +
                  material.name +
                  ") and a six-marker planar tool on a rotation platform sweeping +-45 deg at "
                  "8 deg/s, fixed headset 300-500 mm away, 2000 frames (Sec. IV-B, Table II)";
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial(RetroCurve::kLinear));
  const int shape_material = s.scene.AddMaterial(std::move(material));
  const int acrylic = s.scene.AddMaterial(Named(DiffuseMaterial(0.45), "acrylic"));
  const int platform = AddTurntable(s, acrylic, 440.0, 400.0);
  const std::pair<const char*, TestShape> shapes[] = {
      {"triangular_pyramid", TestShape::kTriangularPyramid},
      {"frustum_pyramid", TestShape::kFrustumPyramid},
      {"hemisphere", TestShape::kHemisphere}};
  // (x, z) of each shape per size on the platform top (y = 0, +z towards the headset).
  const double x_mm[4][3] = {
      {-140.0, 0.0, 140.0}, {-150.0, -70.0, 10.0}, {-150.0, -95.0, -40.0}, {10.0, 45.0, 80.0}};
  const double z_mm[4] = {-110.0, 30.0, 110.0, 110.0};
  const Rigid3d upright = Rotation(-std::numbers::pi / 2.0, Eigen::Vector3d::UnitX());
  for (std::size_t k = 0; k < kTestShapeSizesMm.size(); ++k) {
    for (std::size_t i = 0; i < 3; ++i) {
      s.AddObject(std::string(shapes[i].first) + "_size" + std::to_string(k + 1),
                  TestShapeMesh(shapes[i].second, kTestShapeSizesMm[k]), shape_material, platform,
                  Translation({x_mm[k][i], 0.05, z_mm[k]}) * upright);
    }
  }
  const Eigen::Vector3d eye(0.0, 300.0, 280.0), target(0.0, 30.0, 0.0);
  const Eigen::Vector3d tool_centre(150.0, 40.0, 60.0);
  AddToolWithPlate(s, "planar-six", "planar_tool", platform,
                   Rigid3d(LookAt(tool_centre, eye).rotation, tool_centre), retro, acrylic);
  s.camera.motion = FixedCamera(eye, target);
  s.frames = 2000;
  return s;
}

Scenario ReconstructionShapesNylon(const PatientHead* /*no patient*/) {
  return ReconstructionShapes("reconstruction-shapes", NylonMaterial());
}

Scenario ReconstructionShapesPhotopolymer(const PatientHead* /*no patient*/) {
  return ReconstructionShapes("reconstruction-shapes-pp", PhotopolymerMaterial());
}

Scenario EvdUseCase(const PatientHead* given_head) {
  Scenario s;
  s.name = "evd-usecase";
  s.description =
      "Nylon head phantom on a headframe with two reference tools, three 10 mm forehead markers "
      "and nine planned trajectories, a drape around the head, a hand and a tracked instrument "
      "passing over the forehead and the tools; a wandering headset at 300-700 mm, 2000 frames "
      "(Sec. V)";
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial(RetroCurve::kLinear));
  const int nylon = s.scene.AddMaterial(NylonMaterial());
  const int acrylic = s.scene.AddMaterial(Named(DiffuseMaterial(0.45), "acrylic_plate"));
  const Eigen::Vector3d centre(0.0, 200.0, 0.0);
  const PatientHead head = HeadOrPhantom(given_head);
  const int headframe = AddUprightPatient(s, head, nylon, "headframe", centre);
  for (const double side : {1.0, -1.0}) {  // LPS +x is the patient's left
    const Eigen::Vector3d at(side * 118.0, -15.0, -10.0);
    const Eigen::Vector3d normal(side * 0.45, -0.65, 0.6);
    AddToolWithPlate(s, side > 0.0 ? "reference-a" : "reference-b",
                     side > 0.0 ? "reference_left" : "reference_right", headframe,
                     Rigid3d(LookAt(at, at + normal, Eigen::Vector3d::UnitZ()).rotation, at), retro,
                     acrylic);
  }
  AddStickers(s,
              SkinStickers("forehead_markers", head,
                           {HeadDirection(-0.25, 0.50), HeadDirection(0.22, 0.42),
                            HeadDirection(0.04, 0.74)},
                           10.0, retro, s.patient->object),
              headframe);
  AddEvdOccluders(s, head, headframe, retro);  // drape, hand, instrument (evd_occluders.hpp)
  s.camera.motion = Wearer(WorldFromUprightImage(centre) * Eigen::Vector3d(0.0, -40.0, 50.0), 8.0);
  s.camera.motion.head_worn.azimuth_span_rad = 1.8;
  s.camera.motion.head_worn.max_elevation_rad = 0.9;
  s.timing.drop_probability = 0.01;
  s.frames = 2000;
  return s;
}

struct Builtin {
  const char* name;
  Scenario (*make)(const PatientHead* head);
  bool has_patient;
};

constexpr Builtin kBuiltins[] = {
    {"marker-stage", MarkerStage, false},
    {"materials", Materials, false},
    {"head-identification", HeadIdentification, true},
    {"depth-accuracy", DepthAccuracy, false},
    {"reconstruction", Reconstruction, true},
    {"reconstruction-shapes", ReconstructionShapesNylon, false},
    {"reconstruction-shapes-pp", ReconstructionShapesPhotopolymer, false},
    {"evd-usecase", EvdUseCase, true},
    {"pivot-calibration", [](const PatientHead*) { return PivotCalibrationScenario(); }, false},
    {"verify-landmarks",
     [](const PatientHead* given) {
       const PatientHead head = HeadOrPhantom(given);
       return VerifyLandmarksScenario(EvdUseCase(&head), head);
     },
     true},
};

}  // namespace

std::vector<std::string> BuiltinScenarioNames() {
  std::vector<std::string> names;
  for (const Builtin& b : kBuiltins) names.emplace_back(b.name);
  return names;
}

std::string BuiltinScenarioSummary(const std::string& name) {
  return BuiltinScenario(name).description;
}

Scenario BuiltinScenario(const std::string& name, const PatientHead* head) {
  for (const Builtin& b : kBuiltins) {
    if (name != b.name) continue;
    Require(head == nullptr || b.has_patient,
            "scenario '" + name + "' has no patient: a head cannot be given");
    return b.make(head);
  }
  std::string known;
  for (const std::string& n : BuiltinScenarioNames()) known += (known.empty() ? "" : ", ") + n;
  Require(false, "unknown scenario '" + name + "' (built-ins: " + known + ")");
  return {};
}

}  // namespace tofnav::sim
