// SPDX-License-Identifier: BSD-3-Clause
// First-hit ray casting with Embree 3: per-object and per-tool BVHs under one instance level.
#include "tofnav/sim/raycaster.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/decals.hpp"

namespace tofnav::sim {
namespace {

struct DeviceDeleter {
  void operator()(RTCDeviceTy* device) const { rtcReleaseDevice(device); }
};
struct SceneDeleter {
  void operator()(RTCSceneTy* scene) const { rtcReleaseScene(scene); }
};
struct GeometryDeleter {
  void operator()(RTCGeometryTy* geometry) const { rtcReleaseGeometry(geometry); }
};
using DevicePtr = std::unique_ptr<RTCDeviceTy, DeviceDeleter>;
using ScenePtr = std::unique_ptr<RTCSceneTy, SceneDeleter>;
using GeometryPtr = std::unique_ptr<RTCGeometryTy, GeometryDeleter>;

constexpr unsigned kInvalidId = RTC_INVALID_GEOMETRY_ID;
constexpr std::size_t kBatchRays = 256;  // rays per rtcIntersect1M call

void ThrowOnDeviceError(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE) {
    throw std::runtime_error(std::string("Embree error ") +
                             std::to_string(static_cast<int>(error)) + " in " + what);
  }
}

template <typename T>
T* NewBuffer(RTCGeometry geometry, RTCBufferType type, RTCFormat format, std::size_t count) {
  void* data = rtcSetNewGeometryBuffer(geometry, type, 0, format, sizeof(T), count);
  return static_cast<T*>(data);
}

struct Float3 {
  float x, y, z;
};
struct Float4 {
  float x, y, z, w;
};
struct Uint3 {
  unsigned a, b, c;
};

Float3 ToFloat3(const Eigen::Vector3d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

// Markers of one tool split into Embree's sphere and oriented-disc point geometries.
struct ToolPrimitives {
  unsigned sphere_geometry = kInvalidId;
  unsigned disc_geometry = kInvalidId;
  std::vector<int> sphere_markers;  // primID -> marker index
  std::vector<int> disc_markers;
};

// What Refine needs of one triangle, contiguous so a hit touches one or two cache lines.
struct TriangleRecord {
  Eigen::Vector3d v0;          // first vertex [mm]
  Eigen::Vector3d face;        // unit face normal (counter-clockwise: outward)
  Eigen::Vector3f n0, n1, n2;  // vertex normals, or the face normal
};

struct MeshRecords {
  std::size_t vertex_count = 0;
  std::vector<TriangleRecord> triangles;
};

MeshRecords MakeRecords(const TriangleMesh& mesh) {
  MeshRecords records;
  records.vertex_count = mesh.vertices.size();
  records.triangles.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const auto vertex = [&](int k) -> const Eigen::Vector3d& {
      return mesh.vertices[static_cast<std::size_t>(t[k])];
    };
    TriangleRecord r;
    r.v0 = vertex(0);
    const Eigen::Vector3d cross = (vertex(1) - vertex(0)).cross(vertex(2) - vertex(0));
    r.face = cross.norm() > 0.0 ? Eigen::Vector3d(cross.normalized()) : Eigen::Vector3d::Zero();
    const auto normal = [&](int k) -> Eigen::Vector3f {
      return mesh.vertex_normals.empty()
                 ? r.face.cast<float>()
                 : mesh.vertex_normals[static_cast<std::size_t>(t[k])].cast<float>();
    };
    r.n0 = normal(0);
    r.n1 = normal(1);
    r.n2 = normal(2);
    records.triangles.push_back(r);
  }
  return records;
}

struct Instance {
  int object = -1;  // exactly one of object / tool is set
  int tool = -1;
  GeometryPtr geometry;
  Eigen::Matrix3d local_from_ahat_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d ahat_origin_in_local = Eigen::Vector3d::Zero();
  Eigen::Matrix3d ahat_from_local_rotation = Eigen::Matrix3d::Identity();
};

}  // namespace

struct SceneRaycaster::Impl {
  DevicePtr device;
  ScenePtr top;
  std::vector<ScenePtr> prototypes;
  std::vector<Instance> instances;  // index = geomID in `top`
  std::vector<MeshRecords> meshes;
  std::vector<int> object_materials;
  std::vector<std::vector<Marker>> tool_markers;
  std::vector<ToolPrimitives> tool_primitives;
  std::vector<std::vector<Decal>> object_decals;  // per object

  void AddInstance(ScenePtr prototype, int object, int tool) {
    GeometryPtr geometry(rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_INSTANCE));
    rtcSetGeometryInstancedScene(geometry.get(), prototype.get());
    rtcSetGeometryTimeStepCount(geometry.get(), 1);
    const unsigned id = rtcAttachGeometry(top.get(), geometry.get());
    Require(id == instances.size(), "SceneRaycaster: unexpected Embree geometry id");
    Instance instance;
    instance.object = object;
    instance.tool = tool;
    instance.geometry = std::move(geometry);
    instances.push_back(std::move(instance));
    prototypes.push_back(std::move(prototype));
  }

  ScenePtr MeshPrototype(const TriangleMesh& mesh) {
    ScenePtr scene(rtcNewScene(device.get()));
    rtcSetSceneBuildQuality(scene.get(), RTC_BUILD_QUALITY_HIGH);
    GeometryPtr geometry(rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE));
    Float3* vertices = NewBuffer<Float3>(geometry.get(), RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3,
                                         mesh.vertices.size());
    Uint3* triangles = NewBuffer<Uint3>(geometry.get(), RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT3,
                                        mesh.triangles.size());
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) vertices[i] = ToFloat3(mesh.vertices[i]);
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
      const Eigen::Vector3i& t = mesh.triangles[i];
      triangles[i] = {static_cast<unsigned>(t[0]), static_cast<unsigned>(t[1]),
                      static_cast<unsigned>(t[2])};
    }
    rtcCommitGeometry(geometry.get());
    rtcAttachGeometry(scene.get(), geometry.get());
    rtcCommitScene(scene.get());
    return scene;
  }

  ScenePtr ToolPrototype(const std::vector<Marker>& markers, ToolPrimitives& primitives) {
    ScenePtr scene(rtcNewScene(device.get()));
    for (int i = 0; i < static_cast<int>(markers.size()); ++i) {
      if (markers[static_cast<std::size_t>(i)].conforms_to_object >= 0) continue;  // a decal
      auto& list = markers[static_cast<std::size_t>(i)].shape == MarkerShape::kSphere
                       ? primitives.sphere_markers
                       : primitives.disc_markers;
      list.push_back(i);
    }
    const auto add_points = [&](const std::vector<int>& indices, RTCGeometryType type) {
      GeometryPtr geometry(rtcNewGeometry(device.get(), type));
      Float4* points = NewBuffer<Float4>(geometry.get(), RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT4,
                                         indices.size());
      Float3* normals = type == RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT
                            ? NewBuffer<Float3>(geometry.get(), RTC_BUFFER_TYPE_NORMAL,
                                                RTC_FORMAT_FLOAT3, indices.size())
                            : nullptr;
      for (std::size_t k = 0; k < indices.size(); ++k) {
        const Marker& m = markers[static_cast<std::size_t>(indices[k])];
        const Float3 c = ToFloat3(m.centre_in_tool);
        points[k] = {c.x, c.y, c.z, static_cast<float>(0.5 * m.diameter_mm)};
        if (normals != nullptr) normals[k] = ToFloat3(m.normal_in_tool.normalized());
      }
      rtcCommitGeometry(geometry.get());
      return rtcAttachGeometry(scene.get(), geometry.get());
    };
    if (!primitives.sphere_markers.empty()) {
      primitives.sphere_geometry =
          add_points(primitives.sphere_markers, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    }
    if (!primitives.disc_markers.empty()) {
      primitives.disc_geometry =
          add_points(primitives.disc_markers, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    }
    rtcCommitScene(scene.get());
    return scene;
  }

  // Exact double-precision hit on the primitive Embree found; `local` is the instance frame.
  RayHit Refine(const RTCRayHit& rayhit, const Eigen::Vector3d& direction_in_ahat) const {
    RayHit hit;
    const Instance& instance = instances[rayhit.hit.instID[0]];
    const Eigen::Vector3d o = instance.ahat_origin_in_local;
    const Eigen::Vector3d d = instance.local_from_ahat_rotation * direction_in_ahat;
    const double embree_range = static_cast<double>(rayhit.ray.tfar);
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    double range = embree_range;
    const auto plane_range = [&](const Eigen::Vector3d& n, const Eigen::Vector3d& p) {
      const double denom = n.dot(d);
      const double t = denom != 0.0 ? n.dot(p - o) / denom : embree_range;
      return std::isfinite(t) && t > 0.0 ? t : embree_range;
    };
    if (instance.object >= 0) {
      const std::size_t object = static_cast<std::size_t>(instance.object);
      const TriangleRecord& tri = meshes[object].triangles[rayhit.hit.primID];
      range = plane_range(tri.face, tri.v0);
      const float u = rayhit.hit.u, v = rayhit.hit.v;  // Embree: p = (1-u-v) p0 + u p1 + v p2
      normal = ((1.0f - u - v) * tri.n0 + u * tri.n1 + v * tri.n2).cast<double>();
      hit.object = instance.object;
      hit.material = object_materials[object];
      if (const Decal* decal = FindDecal(object_decals[object], o + range * d)) {
        // The tape: its plane along this ray, with the plane's normal for shading.
        normal = decal->normal_in_object;
        range = plane_range(normal, decal->centre_in_object);
        hit.object = -1;
        hit.tool = decal->tool;
        hit.marker = decal->marker;
        hit.material = decal->material;
      }
    } else {
      const std::size_t tool = static_cast<std::size_t>(instance.tool);
      const ToolPrimitives& primitives = tool_primitives[tool];
      const bool sphere = rayhit.hit.geomID == primitives.sphere_geometry;
      const int index =
          (sphere ? primitives.sphere_markers : primitives.disc_markers)[rayhit.hit.primID];
      const Marker& marker = tool_markers[tool][static_cast<std::size_t>(index)];
      if (sphere) {
        const double radius = 0.5 * marker.diameter_mm;
        const Eigen::Vector3d oc = o - marker.centre_in_tool;
        const double b = d.dot(oc);
        const double disc = b * b - (oc.squaredNorm() - radius * radius);
        range = -b - std::sqrt(std::max(disc, 0.0));
        if (range <= 0.0) range = embree_range;
        normal = o + range * d - marker.centre_in_tool;
      } else {
        normal = marker.normal_in_tool;
        range = plane_range(normal, marker.centre_in_tool);
      }
      hit.tool = instance.tool;
      hit.marker = index;
      hit.material = marker.material;
    }
    hit.range_mm = range;
    hit.normal_in_ahat = instance.ahat_from_local_rotation * normal;  // Intersect normalises
    return hit;
  }
};

SceneRaycaster::SceneRaycaster(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  scene.Check();
  impl_->device.reset(rtcNewDevice(nullptr));
  if (!impl_->device) throw std::runtime_error("Embree: rtcNewDevice failed");
  impl_->top.reset(rtcNewScene(impl_->device.get()));
  rtcSetSceneFlags(impl_->top.get(), RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(impl_->top.get(), RTC_BUILD_QUALITY_LOW);
  for (int i = 0; i < static_cast<int>(scene.objects.size()); ++i) {
    const SceneObject& object = scene.objects[static_cast<std::size_t>(i)];
    impl_->meshes.push_back(MakeRecords(object.mesh));
    impl_->object_materials.push_back(object.material);
    if (object.mesh.triangles.empty()) continue;
    impl_->AddInstance(impl_->MeshPrototype(object.mesh), i, -1);
  }
  impl_->object_decals = CollectDecals(scene);
  for (int i = 0; i < static_cast<int>(scene.tools.size()); ++i) {
    const Tool& tool = scene.tools[static_cast<std::size_t>(i)];
    impl_->tool_markers.push_back(tool.markers);
    impl_->tool_primitives.emplace_back();
    if (std::all_of(tool.markers.begin(), tool.markers.end(),
                    [](const Marker& m) { return m.conforms_to_object >= 0; })) {
      continue;  // no rigid marker: nothing for Embree (an empty tool included)
    }
    impl_->AddInstance(impl_->ToolPrototype(tool.markers, impl_->tool_primitives.back()), -1, i);
  }
  ThrowOnDeviceError(impl_->device.get(), "building the scene");
  SetPoses(scene, Rigid3d::Identity());
}

SceneRaycaster::~SceneRaycaster() = default;
SceneRaycaster::SceneRaycaster(SceneRaycaster&&) noexcept = default;
SceneRaycaster& SceneRaycaster::operator=(SceneRaycaster&&) noexcept = default;

void SceneRaycaster::SetPoses(const Scene& scene, const Rigid3d& scene_from_ahat) {
  Require(scene.objects.size() == impl_->meshes.size() &&
              scene.tools.size() == impl_->tool_markers.size(),
          "SceneRaycaster::SetPoses: the scene has other objects or tools than at construction");
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    Require(scene.objects[i].mesh.vertices.size() == impl_->meshes[i].vertex_count &&
                scene.objects[i].mesh.triangles.size() == impl_->meshes[i].triangles.size(),
            "SceneRaycaster::SetPoses: an object's mesh changed since construction");
  }
  for (std::size_t i = 0; i < scene.tools.size(); ++i) {
    Require(scene.tools[i].markers.size() == impl_->tool_markers[i].size(),
            "SceneRaycaster::SetPoses: a tool's markers changed since construction");
  }
  PlaceDecals(scene, impl_->object_decals);
  const Rigid3d ahat_from_scene = scene_from_ahat.Inverse();
  for (Instance& instance : impl_->instances) {
    const Rigid3d& scene_from_local =
        instance.object >= 0
            ? scene.objects[static_cast<std::size_t>(instance.object)].scene_from_object
            : scene.tools[static_cast<std::size_t>(instance.tool)].scene_from_tool;
    const Rigid3d ahat_from_local = ahat_from_scene * scene_from_local;
    const Rigid3d local_from_ahat = ahat_from_local.Inverse();
    instance.ahat_from_local_rotation = ahat_from_local.RotationMatrix();
    instance.local_from_ahat_rotation = local_from_ahat.RotationMatrix();
    instance.ahat_origin_in_local = local_from_ahat.translation;
    float transform[12];  // 3x4 column-major: the rotation's columns, then the translation
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) {
        transform[3 * c + r] = static_cast<float>(instance.ahat_from_local_rotation(r, c));
      }
    }
    for (int r = 0; r < 3; ++r)
      transform[9 + r] = static_cast<float>(ahat_from_local.translation[r]);
    rtcSetGeometryTransform(instance.geometry.get(), 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR,
                            transform);
    rtcCommitGeometry(instance.geometry.get());
  }
  rtcCommitScene(impl_->top.get());
  ThrowOnDeviceError(impl_->device.get(), "updating poses");
}

void SceneRaycaster::Intersect(std::span<const Eigen::Vector3d> directions_in_ahat,
                               std::span<RayHit> hits) const {
  Require(directions_in_ahat.size() == hits.size(), "SceneRaycaster::Intersect: size mismatch");
  thread_local std::vector<RTCRayHit> batch;
  batch.resize(kBatchRays);
  for (std::size_t first = 0; first < hits.size(); first += kBatchRays) {
    const std::size_t count = std::min(kBatchRays, hits.size() - first);
    for (std::size_t k = 0; k < count; ++k) {
      const Eigen::Vector3d& d = directions_in_ahat[first + k];
      RTCRayHit& r = batch[k];
      r.ray.org_x = r.ray.org_y = r.ray.org_z = 0.0f;
      r.ray.tnear = 0.0f;
      r.ray.dir_x = static_cast<float>(d.x());
      r.ray.dir_y = static_cast<float>(d.y());
      r.ray.dir_z = static_cast<float>(d.z());
      r.ray.time = 0.0f;
      r.ray.tfar = std::numeric_limits<float>::infinity();
      r.ray.mask = ~0u;
      r.ray.id = static_cast<unsigned>(k);
      r.ray.flags = 0;
      r.hit.geomID = kInvalidId;
      r.hit.instID[0] = kInvalidId;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect1M(impl_->top.get(), &context, batch.data(), static_cast<unsigned>(count),
                   sizeof(RTCRayHit));
    for (std::size_t k = 0; k < count; ++k) {
      hits[first + k] = batch[k].hit.geomID == kInvalidId
                            ? RayHit{}
                            : impl_->Refine(batch[k], directions_in_ahat[first + k]);
    }
    // A separate loop lets the square roots and divisions of many hits overlap.
    for (std::size_t k = 0; k < count; ++k) {
      Eigen::Vector3d& n = hits[first + k].normal_in_ahat;
      const double length = n.norm();
      if (length > 0.0) n *= 1.0 / length;
    }
  }
}

}  // namespace tofnav::sim
