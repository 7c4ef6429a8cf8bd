// SPDX-License-Identifier: BSD-3-Clause
// Tape stickers drawn on an object's surface (Marker::conforms_to_object), for the ray caster.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "tofnav/sim/scene.hpp"

namespace tofnav::sim {

/// One sticker on an object, in that object's frame.
struct Decal {
  int tool = -1;
  int marker = -1;
  double radius_mm = 0.0;
  int material = -1;
  Eigen::Vector3d centre_in_object = Eigen::Vector3d::Zero();  // set by PlaceDecals
  Eigen::Vector3d normal_in_object = Eigen::Vector3d::UnitZ();
};

/// The stickers of every tool, listed per object they lie on (one list per scene object).
std::vector<std::vector<Decal>> CollectDecals(const Scene& scene);

/// Places each decal on its object for the scene's current object and tool poses.
void PlaceDecals(const Scene& scene, std::vector<std::vector<Decal>>& decals);

/// The decal whose footprint holds `point_in_object` (within its radius, measured in its plane),
/// or nullptr.
const Decal* FindDecal(std::span<const Decal> decals, const Eigen::Vector3d& point_in_object);

}  // namespace tofnav::sim
