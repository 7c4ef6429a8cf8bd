// SPDX-License-Identifier: BSD-3-Clause
// Hands, instruments and drapes as scene objects and tools.
#include "tofnav/sim/occluders.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "tofnav/core/require.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/sim/random.hpp"
#include "tofnav/sim/shapes.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav::sim {
namespace {

constexpr double kRodGapMm = 1.0;  // between the rod and the tool's z = 0 plane
constexpr int kFolds = 6;

// Appends `part` moved by b_from_part to `mesh`.
void Append(TriangleMesh& mesh, const TriangleMesh& part, const Rigid3d& b_from_part) {
  const TriangleMesh moved = Transform(b_from_part, part);
  const int offset = static_cast<int>(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), moved.vertices.begin(), moved.vertices.end());
  mesh.vertex_normals.insert(mesh.vertex_normals.end(), moved.vertex_normals.begin(),
                             moved.vertex_normals.end());
  for (const Eigen::Vector3i& t : moved.triangles)
    mesh.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
}

Rigid3d Shift(const Eigen::Vector3d& t) { return {Eigen::Quaterniond::Identity(), t}; }

// The `index`-th uniform number in [0, 1) of a seed (SplitMix64 of the stream).
double Uniform(std::uint64_t seed, std::uint64_t index) {
  return static_cast<double>(MixBits(StreamSeed(seed, index)) >> 11) * 0x1.0p-53;
}

// One fold of the drape's height field: w sin(k . p + phase).
struct Fold {
  Eigen::Vector2d wave_per_mm;  // 2 pi u / lambda
  double phase_rad = 0.0;
  double weight = 0.0;
};

std::array<Fold, kFolds> Folds(const DrapeOptions& o) {
  std::array<Fold, kFolds> folds{};
  double total = 0.0;
  for (int k = 0; k < kFolds; ++k) {
    const auto draw = [&](std::uint64_t i) { return Uniform(o.seed, 3 * k + i); };
    const double direction = kTwoPi * draw(0);
    const double wavelength = o.wrinkle_wavelength_mm * (0.6 + 0.8 * draw(1));
    Fold& f = folds[static_cast<std::size_t>(k)];
    f.wave_per_mm = kTwoPi / wavelength * Eigen::Vector2d(std::cos(direction), std::sin(direction));
    f.phase_rad = kTwoPi * draw(2);
    f.weight = 1.0 / (k + 1);
    total += f.weight;
  }
  for (Fold& f : folds) f.weight *= o.wrinkle_amplitude_mm / total;
  return folds;
}

}  // namespace

void HandOptions::Check() const {
  Require(forearm_diameter_mm > 0.0 && forearm_length_mm >= forearm_diameter_mm,
          "HandOptions: need 0 < forearm_diameter_mm <= forearm_length_mm");
  Require(hand_diameter_mm > 0.0 && hand_length_mm >= hand_diameter_mm,
          "HandOptions: need 0 < hand_diameter_mm <= hand_length_mm");
  Require(hand_diameter_mm <= forearm_diameter_mm,
          "HandOptions: the hand must not be thicker than the forearm");
  Require(segments >= 8 && segments <= 256 && segments % 2 == 0,
          "HandOptions.segments must be even, 8 .. 256");
}

TriangleMesh HandMesh(const HandOptions& o) {
  o.Check();
  TriangleMesh mesh;
  Append(mesh, CapsuleMesh(o.forearm_diameter_mm, o.forearm_length_mm, o.segments),
         Shift({-0.5 * o.forearm_length_mm, 0.0, 0.0}));
  Append(mesh, CapsuleMesh(o.hand_diameter_mm, o.hand_length_mm, o.segments),
         Shift({0.5 * (o.hand_length_mm - o.hand_diameter_mm), 0.0, 0.0}));
  return mesh;
}

void DrapeOptions::Check() const {
  Require(width_mm > 0.0 && height_mm > 0.0 && std::isfinite(width_mm) && std::isfinite(height_mm),
          "DrapeOptions: width_mm and height_mm must be positive");
  Require((opening_semi_axes_mm.array() > 0.0).all() && opening_semi_axes_mm.x() < 0.5 * width_mm &&
              opening_semi_axes_mm.y() < 0.5 * height_mm,
          "DrapeOptions: the opening must be positive and inside the drape");
  Require(cell_mm >= 1.0 && std::isfinite(cell_mm), "DrapeOptions.cell_mm must be >= 1");
  Require(2.0 * (width_mm + height_mm) / cell_mm * std::hypot(width_mm, height_mm) / cell_mm <= 4e6,
          "DrapeOptions: more than 2 million cells (raise cell_mm)");
  Require(wrinkle_amplitude_mm >= 0.0 && std::isfinite(wrinkle_amplitude_mm),
          "DrapeOptions.wrinkle_amplitude_mm must be >= 0");
  Require(wrinkle_wavelength_mm > 0.0 && std::isfinite(wrinkle_wavelength_mm),
          "DrapeOptions.wrinkle_wavelength_mm must be > 0");
}

TriangleMesh DrapeMesh(const DrapeOptions& o) {
  o.Check();
  const double half_w = 0.5 * o.width_mm, half_h = 0.5 * o.height_mm;
  const double a = o.opening_semi_axes_mm.x(), b = o.opening_semi_axes_mm.y();
  // An annulus from the opening's ellipse out to the rectangle: spokes at angles, rings between.
  const int spokes =
      std::max(32, static_cast<int>(std::ceil(2.0 * (o.width_mm + o.height_mm) / o.cell_mm)));
  const int rings = std::max(
      2, static_cast<int>(std::ceil((std::hypot(half_w, half_h) - std::min(a, b)) / o.cell_mm)));
  const std::array<Fold, kFolds> folds = Folds(o);
  TriangleMesh mesh;
  for (int i = 0; i <= rings; ++i) {
    for (int j = 0; j < spokes; ++j) {
      const double angle = kTwoPi * j / spokes;
      const Eigen::Vector2d u(std::cos(angle), std::sin(angle));
      const double inner = 1.0 / std::hypot(u.x() / a, u.y() / b);
      const double outer = std::min(std::abs(u.x()) > 1e-12 ? half_w / std::abs(u.x()) : 1e300,
                                    std::abs(u.y()) > 1e-12 ? half_h / std::abs(u.y()) : 1e300);
      const Eigen::Vector2d p = (inner + (outer - inner) * i / rings) * u;
      double z = 0.0;
      Eigen::Vector2d slope = Eigen::Vector2d::Zero();
      for (const Fold& f : folds) {
        const double arg = f.wave_per_mm.dot(p) + f.phase_rad;
        z += f.weight * std::sin(arg);
        slope += f.weight * std::cos(arg) * f.wave_per_mm;
      }
      mesh.vertices.emplace_back(p.x(), p.y(), z);
      mesh.vertex_normals.push_back(Eigen::Vector3d(-slope.x(), -slope.y(), 1.0).normalized());
    }
  }
  const auto index = [&](int i, int j) { return i * spokes + j % spokes; };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < spokes; ++j) {  // outward, then counter-clockwise: normal +z
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j), index(i + 1, j + 1));
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j + 1), index(i, j + 1));
    }
  }
  return mesh;
}

void InstrumentOptions::Check() const {
  Require(rod_diameter_mm > 0.0 && rod_length_mm >= rod_diameter_mm && std::isfinite(rod_length_mm),
          "InstrumentOptions: need 0 < rod_diameter_mm <= rod_length_mm");
  (void)ToolPreset(preset, "instrument", 0);  // throws for an unknown preset
}

namespace {

// Start of the rod's axis (under the markers' centroid) in the tool frame.
Eigen::Vector3d RodStartInTool(const InstrumentOptions& o) {
  o.Check();
  const Tool tool = ToolPreset(o.preset, "instrument", 0);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Marker& m : tool.markers) centroid += m.centre_in_tool;
  centroid /= static_cast<double>(tool.markers.size());
  return {centroid.x(), centroid.y(), -(0.5 * o.rod_diameter_mm + kRodGapMm)};
}

}  // namespace

TriangleMesh InstrumentRodMesh(const InstrumentOptions& o) {
  const Eigen::Vector3d start = RodStartInTool(o);
  // The capsule's +x turned onto the tool's -y, centred half a rod length down from the start.
  const Rigid3d tool_from_capsule(
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.5 * std::numbers::pi, Eigen::Vector3d::UnitZ())),
      start - Eigen::Vector3d(0.0, 0.5 * o.rod_length_mm, 0.0));
  return Transform(tool_from_capsule, CapsuleMesh(o.rod_diameter_mm, o.rod_length_mm, 16));
}

Eigen::Vector3d InstrumentTipInTool(const InstrumentOptions& o) {
  return RodStartInTool(o) - Eigen::Vector3d(0.0, o.rod_length_mm, 0.0);
}

int AddHand(Scenario& scenario, const std::string& name, const HandOptions& options, int material,
            Motion motion) {
  const int mount = scenario.AddMount(name + "_motion", std::move(motion));
  return scenario.AddObject(name, HandMesh(options), material, mount, Rigid3d::Identity());
}

int AddInstrument(Scenario& scenario, const std::string& name, const InstrumentOptions& options,
                  int marker_material, int rod_material, Motion motion) {
  const int mount = scenario.AddMount(name + "_motion", std::move(motion));
  scenario.AddObject(name + "_rod", InstrumentRodMesh(options), rod_material, mount,
                     Rigid3d::Identity());
  const Eigen::Vector2d plate = ToolPresetPlateMm(options.preset);
  if (plate.x() > 0.0) {  // disc presets sit on their plate
    scenario.AddObject(name + "_plate", PlaneMesh(plate.x(), plate.y()), rod_material, mount,
                       Rigid3d::Identity());
  }
  Tool tool = ToolPreset(options.preset, name, marker_material);
  tool.tip_in_tool = InstrumentTipInTool(options);
  return scenario.AddTool(std::move(tool), mount);
}

Motion PassesMotion(const Rigid3d& parked, const std::vector<Pass>& passes) {
  std::vector<Keyframe> keyframes;
  const auto shifted = [](const Rigid3d& pose, const Eigen::Vector3d& by) {
    return Rigid3d(pose.rotation, pose.translation + by);
  };
  for (const Pass& pass : passes) {
    Require(pass.move_slots >= 1 && pass.hover_slots >= 1,
            "PassesMotion: move_slots and hover_slots must be >= 1");
    const bool parked_before = keyframes.empty() || keyframes.back().slot < pass.enter_slot - 1;
    if (pass.enter_slot > 0 && parked_before) keyframes.push_back({pass.enter_slot - 1, parked});
    std::int64_t slot = pass.enter_slot;
    keyframes.push_back({slot, shifted(pass.hover, pass.approach_mm)});
    keyframes.push_back({slot += pass.move_slots, pass.hover});
    keyframes.push_back({slot += pass.hover_slots, pass.hover});
    keyframes.push_back({slot += pass.move_slots, shifted(pass.hover, pass.leave_mm)});
    keyframes.push_back({slot + 1, parked});
  }
  if (keyframes.empty()) keyframes.push_back({0, parked});
  Motion motion = KeyframeMotion(std::move(keyframes));
  motion.Check();
  return motion;
}

}  // namespace tofnav::sim
