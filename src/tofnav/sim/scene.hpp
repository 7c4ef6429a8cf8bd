// SPDX-License-Identifier: BSD-3-Clause
// Simulator scenes: posed meshes with materials, and rigid tools made of retro-reflective markers.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/sim/material.hpp"

namespace tofnav::sim {

/// A rigid mesh in the scene. Its vertex normals, when present, are interpolated for shading
/// (incidence); otherwise the face normal is used.
struct SceneObject {
  std::string name;
  TriangleMesh mesh;  // in the object frame [mm]
  int material = 0;   // index into Scene::materials
  Rigid3d scene_from_object;
};

enum class MarkerShape {
  kSphere,  // exact sphere, e.g. an NDI-style retro-reflective ball
  kDisc,    // exact flat disc, e.g. a circle of IR tape
};

/// One marker of a tool, in the tool frame.
struct Marker {
  MarkerShape shape = MarkerShape::kSphere;
  double diameter_mm = 10.0;
  Eigen::Vector3d centre_in_tool = Eigen::Vector3d::Zero();   // sphere or disc centre [mm]
  Eigen::Vector3d normal_in_tool = Eigen::Vector3d::UnitZ();  // disc front side; unused for spheres
  int material = 0;  // index into Scene::materials (normally a retro-reflective one)
  /// A tape sticker on the surface of this object (index into Scene::objects; -1: a rigid
  /// sphere or flat disc). Drawn as a decal: a ray that meets the object within diameter / 2 of
  /// centre_in_tool (measured in the sticker's plane) meets the sticker instead, on the plane
  /// through centre_in_tool with normal normal_in_tool, which is then the least-squares plane of
  /// the surface under the sticker lifted by the tape's thickness: tape bridges wrinkles smaller
  /// than itself, and nothing of it floats beside or sinks behind the surface. The tool must move
  /// with the object (same mount).
  int conforms_to_object = -1;
};

/// A rigid set of markers (a tracked tool, or stickers that move with an object).
struct Tool {
  std::string name;
  std::vector<Marker> markers;
  Rigid3d scene_from_tool;
  /// A pointer's or instrument's tip, when it has one (the truth a pivot calibration finds).
  std::optional<Eigen::Vector3d> tip_in_tool;
};

/// Everything the camera can see. Geometry is fixed once a renderer is built from the scene;
/// poses (scene_from_object, scene_from_tool) may change between frames.
struct Scene {
  std::vector<Material> materials;
  std::vector<SceneObject> objects;
  std::vector<Tool> tools;

  /// Appends a material and returns its index.
  int AddMaterial(Material material);
  /// Appends an object and returns its index.
  int AddObject(std::string name, TriangleMesh mesh, int material,
                const Rigid3d& scene_from_object);
  /// Appends a tool and returns its index.
  int AddTool(Tool tool);
  /// Flat marker id used in truth images: tools in order, markers in order within a tool.
  int MarkerId(int tool, int marker) const;
  /// Throws PreconditionError on bad material indices, inconsistent meshes or bad markers.
  void Check() const;
};

/// A sphere marker centred at `centre_in_tool`.
Marker SphereMarker(const Eigen::Vector3d& centre_in_tool, double diameter_mm, int material);
/// A tape disc lying on a surface at `point_in_tool` with outward unit normal `normal_in_tool`,
/// lifted by `offset_mm` so it is not coplanar with the surface. On a curved surface, add the
/// sag of the disc (r^2 / (2 R) for curvature radius R) to the offset, or its rim sinks below.
Marker DiscMarkerOnSurface(const Eigen::Vector3d& point_in_tool,
                           const Eigen::Vector3d& normal_in_tool, double diameter_mm, int material,
                           double offset_mm = 0.1);

}  // namespace tofnav::sim
