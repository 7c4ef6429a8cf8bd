// SPDX-License-Identifier: BSD-3-Clause
// Marker clearance: ray probes from each marker against the scene's objects (Embree).
#include "tofnav/sim/scenario_sanity.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/raycaster.hpp"
#include "tofnav/sim/simulator.hpp"

namespace tofnav::sim {
namespace {

constexpr double kDiscProbeFraction = 0.9;  // of the radius: the rim probes
constexpr int kDiscRimProbes = 8;
constexpr double kInsideFraction = 0.9;  // of a sphere's rays meeting a closed mesh's back
// |cos| between a hit's normal and the ray below which the side it was met from is uncertain: the
// interpolated vertex normals of a faceted mesh tilt up to half a facet angle off the face's.
constexpr double kMinFacing = 0.1;

// Every edge of the mesh shared by exactly two triangles.
bool IsClosed(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return false;
  std::unordered_map<std::uint64_t, int> edges;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint32_t>(std::min(t[k], t[(k + 1) % 3]));
      const auto b = static_cast<std::uint32_t>(std::max(t[k], t[(k + 1) % 3]));
      ++edges[(std::uint64_t{a} << 32) | b];
    }
  }
  return std::all_of(edges.begin(), edges.end(), [](const auto& e) { return e.second == 2; });
}

// Unit directions: the six axes and a Fibonacci sphere of `count`.
std::vector<Eigen::Vector3d> ProbeDirections(int count) {
  std::vector<Eigen::Vector3d> d;
  for (int k = 0; k < 3; ++k) {
    d.push_back(Eigen::Vector3d::Unit(k));
    d.push_back(-Eigen::Vector3d::Unit(k));
  }
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    d.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return d;
}

Rigid3d At(const Eigen::Vector3d& point) { return {Eigen::Quaterniond::Identity(), point}; }

class Prober {
 public:
  Prober(const Scenario& s, const MarkerClearanceOptions& options)
      : scenario_(s),
        objects_(ObjectsOnly(s.scene)),
        raycaster_(objects_),
        directions_(ProbeDirections(options.sphere_rays)) {
    for (const SceneObject& o : objects_.objects) closed_.push_back(IsClosed(o.mesh));
  }

  // Poses objects at `slot`; returns world_from_tool of every tool.
  std::vector<Rigid3d> Pose(std::int64_t slot) {
    const std::vector<Rigid3d> mounts = ScenarioMountPoses(scenario_, slot);
    const auto in_world = [&](int mount, const Rigid3d& mount_from_x) {
      return mount < 0 ? mount_from_x : mounts[static_cast<std::size_t>(mount)] * mount_from_x;
    };
    for (std::size_t o = 0; o < objects_.objects.size(); ++o) {
      objects_.objects[o].scene_from_object =
          in_world(scenario_.object_mounts[o], scenario_.scene.objects[o].scene_from_object);
    }
    std::vector<Rigid3d> tools;
    for (std::size_t t = 0; t < scenario_.scene.tools.size(); ++t) {
      tools.push_back(in_world(scenario_.tool_mounts[t], scenario_.scene.tools[t].scene_from_tool));
    }
    return tools;
  }

  // Deepest reach (object, depth) of a marker posed by world_from_tool; depth <= 0 when clear.
  std::pair<int, double> Probe(const Marker& m, const Rigid3d& world_from_tool) {
    const double r = 0.5 * m.diameter_mm;
    const Eigen::Vector3d centre = world_from_tool * m.centre_in_tool;
    std::pair<int, double> deepest = {-1, 0.0};
    if (m.shape == MarkerShape::kSphere) {
      std::vector<RayHit> hits(directions_.size());
      raycaster_.SetPoses(objects_, At(centre));
      raycaster_.Intersect(directions_, hits);
      std::vector<int> back_counts(objects_.objects.size(), 0);
      std::vector<double> nearest_back(objects_.objects.size(), 1e300);
      for (std::size_t i = 0; i < hits.size(); ++i) {
        const RayHit& h = hits[i];
        const double facing = h.hit() ? h.normal_in_ahat.dot(directions_[i]) : 0.0;
        if (std::abs(facing) < kMinFacing) continue;  // grazing: the side is uncertain
        const auto o = static_cast<std::size_t>(h.object);
        if (facing > 0.0) {
          ++back_counts[o];
          nearest_back[o] = std::min(nearest_back[o], h.range_mm);
        } else if (h.range_mm < r) {
          Deeper(deepest, h.object, r - h.range_mm);
        }
      }
      for (std::size_t o = 0; o < back_counts.size(); ++o) {  // the centre behind a surface
        const bool inside =
            closed_[o] && back_counts[o] >= kInsideFraction * static_cast<double>(hits.size());
        if (nearest_back[o] < r || inside)
          Deeper(deepest, static_cast<int>(o), r + nearest_back[o]);
      }
      return deepest;
    }
    const Eigen::Vector3d normal = world_from_tool.rotation * m.normal_in_tool.normalized();
    const Eigen::Vector3d side = normal.unitOrthogonal(), up = normal.cross(side);
    std::vector<Eigen::Vector3d> points = {centre};
    for (int k = 0; k < kDiscRimProbes; ++k) {
      const double a = 2.0 * std::numbers::pi * k / kDiscRimProbes;
      points.push_back(centre + kDiscProbeFraction * r * (std::cos(a) * side + std::sin(a) * up));
    }
    const Eigen::Vector3d direction[1] = {normal};
    for (const Eigen::Vector3d& p : points) {
      RayHit hit[1];
      raycaster_.SetPoses(objects_, At(p));
      raycaster_.Intersect(direction, hit);
      const RayHit& h = hit[0];
      if (h.hit() && h.normal_in_ahat.dot(normal) > kMinFacing &&
          (h.range_mm < r || closed_[static_cast<std::size_t>(h.object)])) {
        Deeper(deepest, h.object, h.range_mm);
      }
    }
    return deepest;
  }

 private:
  static Scene ObjectsOnly(const Scene& scene) {
    Scene objects;
    objects.materials = scene.materials;
    objects.objects = scene.objects;
    return objects;
  }
  static void Deeper(std::pair<int, double>& deepest, int object, double depth_mm) {
    if (depth_mm > deepest.second) deepest = {object, depth_mm};
  }

  const Scenario& scenario_;
  Scene objects_;  // the scenario's objects at the probed slot's world poses, no tools
  SceneRaycaster raycaster_;
  std::vector<Eigen::Vector3d> directions_;
  std::vector<bool> closed_;
};

// Slot 0 and every mount's key slots within the slots the frames span, earliest `max_slots`. A
// run that keeps every n-th slot (timing.slot_stride) spans n slots a frame: its frames show the
// motion's later keys too (dropped and throttled slots stretch it further; not counted here).
std::vector<std::int64_t> CheckedSlots(const Scenario& s, int max_slots) {
  const std::int64_t spanned = s.frames * std::max<std::int64_t>(1, s.timing.slot_stride);
  std::vector<std::int64_t> slots = {0};
  for (const Mount& m : s.mounts) {
    for (const std::int64_t slot : MotionKeySlots(m.motion)) {
      if (slot < spanned) slots.push_back(slot);
    }
  }
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  if (static_cast<int>(slots.size()) > max_slots) slots.resize(static_cast<std::size_t>(max_slots));
  return slots;
}

}  // namespace

void MarkerClearanceOptions::Check() const {
  Require(tolerance_mm >= 0.0 && std::isfinite(tolerance_mm),
          "MarkerClearanceOptions.tolerance_mm must be >= 0");
  Require(sphere_rays >= 6, "MarkerClearanceOptions.sphere_rays must be >= 6");
  Require(max_slots >= 1, "MarkerClearanceOptions.max_slots must be >= 1");
}

std::vector<MarkerIntersection> FindMarkerIntersections(const Scenario& scenario,
                                                        const MarkerClearanceOptions& options) {
  options.Check();
  scenario.Check();
  std::vector<MarkerIntersection> found;
  if (scenario.scene.objects.empty() || scenario.scene.tools.empty()) return found;
  Prober prober(scenario, options);
  for (const std::int64_t slot : CheckedSlots(scenario, options.max_slots)) {
    const std::vector<Rigid3d> world_from_tools = prober.Pose(slot);
    for (std::size_t t = 0; t < scenario.scene.tools.size(); ++t) {
      const std::vector<Marker>& markers = scenario.scene.tools[t].markers;
      for (std::size_t m = 0; m < markers.size(); ++m) {
        if (markers[m].conforms_to_object >= 0) continue;  // tape drawn on its object's surface
        const auto [object, depth_mm] = prober.Probe(markers[m], world_from_tools[t]);
        if (depth_mm <= options.tolerance_mm) continue;
        const auto same = [&](const MarkerIntersection& f) {
          return f.tool == static_cast<int>(t) && f.marker == static_cast<int>(m);
        };
        auto it = std::find_if(found.begin(), found.end(), same);
        if (it == found.end()) {
          found.push_back({static_cast<int>(t), static_cast<int>(m), object, depth_mm, slot});
        } else if (depth_mm > it->depth_mm) {
          *it = {static_cast<int>(t), static_cast<int>(m), object, depth_mm, slot};
        }
      }
    }
  }
  std::stable_sort(found.begin(), found.end(),
                   [](const auto& a, const auto& b) { return a.depth_mm > b.depth_mm; });
  return found;
}

std::string DescribeMarkerIntersection(const Scenario& scenario, const MarkerIntersection& hit) {
  const Tool& tool = scenario.scene.tools[static_cast<std::size_t>(hit.tool)];
  const Marker& marker = tool.markers[static_cast<std::size_t>(hit.marker)];
  std::ostringstream diameter;
  diameter << marker.diameter_mm;
  char depth[32];
  std::snprintf(depth, sizeof(depth), "%.1f", hit.depth_mm);
  std::string line = "scenario: tool '" + tool.name + "' marker " + std::to_string(hit.marker) +
                     " (" + (marker.shape == MarkerShape::kSphere ? "sphere" : "disc") + ", " +
                     diameter.str() + " mm) intersects the " +
                     scenario.scene.objects[static_cast<std::size_t>(hit.object)].name +
                     " surface by " + depth + " mm";
  if (hit.slot > 0) line += ", at slot " + std::to_string(hit.slot);
  return line;
}

void RequireMarkersClear(const Scenario& scenario, const MarkerClearanceOptions& options) {
  const std::vector<MarkerIntersection> found = FindMarkerIntersections(scenario, options);
  // The message is the user's line itself, without Require's source location.
  if (!found.empty()) throw PreconditionError(DescribeMarkerIntersection(scenario, found[0]));
}

}  // namespace tofnav::sim
