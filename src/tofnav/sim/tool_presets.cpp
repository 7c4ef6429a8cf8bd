// SPDX-License-Identifier: BSD-3-Clause
// Tool presets. Layouts are irregular so that every pair distance is distinct (no symmetric
// matches for a tracker).
#include "tofnav/sim/tool_presets.hpp"

#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

struct DiscSpec {
  double x_mm;
  double y_mm;
  double diameter_mm;
};

struct Preset {
  const char* name;
  Eigen::Vector2d plate_mm;
  std::vector<DiscSpec> discs;
};

std::vector<Preset> Presets() {
  return {
      {"planar-six",
       {90.0, 70.0},
       {{-35.0, -25.0, 10.0},
        {-4.0, -27.0, 10.0},
        {33.0, -19.0, 10.0},
        {-30.0, 23.0, 10.0},
        {9.0, 14.0, 10.0},
        {36.0, 27.0, 10.0}}},
      {"tape-seven",
       {140.0, 140.0},
       {{0.0, 0.0, 20.0},
        {42.0, 3.0, 12.0},
        {19.0, 40.0, 12.0},
        {-24.0, 37.0, 12.0},
        {-45.0, -2.0, 12.0},
        {-19.0, -41.0, 12.0},
        {27.0, -35.0, 12.0}}},
      {"reference-a",
       {80.0, 60.0},
       {{-30.0, -20.0, 10.0}, {26.0, -22.0, 10.0}, {-17.0, 21.0, 10.0}, {31.0, 16.0, 10.0}}},
      {"reference-b",
       {80.0, 60.0},
       {{-32.0, -8.0, 10.0}, {12.0, -23.0, 10.0}, {-6.0, 24.0, 10.0}, {33.0, 12.0, 10.0}}},
  };
}

}  // namespace

std::vector<std::string> ToolPresetNames() {
  std::vector<std::string> names;
  for (const Preset& preset : Presets()) names.emplace_back(preset.name);
  names.emplace_back("spheres-four");
  return names;
}

Tool ToolPreset(const std::string& preset, std::string name, int material) {
  Tool tool;
  tool.name = std::move(name);
  if (preset == "spheres-four") {
    constexpr double kDiameterMm = 11.5, kPostMm = 8.0;
    for (const Eigen::Vector2d& xy : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(55.0, 0.0),
                                      Eigen::Vector2d(21.0, 44.0), Eigen::Vector2d(-14.0, 71.0)}) {
      tool.markers.push_back(SphereMarker({xy.x(), xy.y(), kPostMm}, kDiameterMm, material));
    }
    return tool;
  }
  for (const Preset& p : Presets()) {
    if (preset != p.name) continue;
    for (const DiscSpec& d : p.discs) {
      tool.markers.push_back(DiscMarkerOnSurface({d.x_mm, d.y_mm, 0.0}, Eigen::Vector3d::UnitZ(),
                                                 d.diameter_mm, material));
    }
    return tool;
  }
  std::string known;
  for (const std::string& n : ToolPresetNames()) known += (known.empty() ? "" : ", ") + n;
  Require(false, "unknown tool preset '" + preset + "' (known: " + known + ")");
  return tool;
}

Eigen::Vector2d ToolPresetPlateMm(const std::string& preset) {
  for (const Preset& p : Presets()) {
    if (preset == p.name) return p.plate_mm;
  }
  return Eigen::Vector2d::Zero();
}

}  // namespace tofnav::sim
