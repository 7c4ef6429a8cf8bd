// SPDX-License-Identifier: BSD-3-Clause
// Shapes of scenario objects: analytic meshes, the head phantom, mesh files.
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/scenario/scenario_json_internal.hpp"
#include "tofnav/sim/head_phantom.hpp"
#include "tofnav/sim/occluders.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav::internal {
namespace {

constexpr int kMaxSegments = 1024;  // a 1024-segment sphere already has 10^6 triangles

using HeadPhantomOptions = sim::HeadPhantomOptions;
constexpr Field<HeadPhantomOptions> kPhantomFields[] = {
    {"nose_height_mm", &HeadPhantomOptions::nose_height_mm},
    {"brow_height_mm", &HeadPhantomOptions::brow_height_mm},
    {"eye_socket_depth_mm", &HeadPhantomOptions::eye_socket_depth_mm},
    {"neck_cut_fraction", &HeadPhantomOptions::neck_cut_fraction}};

constexpr Field<sim::HandOptions> kHandFields[] = {
    {"forearm_diameter_mm", &sim::HandOptions::forearm_diameter_mm},
    {"forearm_length_mm", &sim::HandOptions::forearm_length_mm},
    {"hand_diameter_mm", &sim::HandOptions::hand_diameter_mm},
    {"hand_length_mm", &sim::HandOptions::hand_length_mm}};

constexpr Field<sim::DrapeOptions> kDrapeFields[] = {
    {"width_mm", &sim::DrapeOptions::width_mm},
    {"height_mm", &sim::DrapeOptions::height_mm},
    {"cell_mm", &sim::DrapeOptions::cell_mm},
    {"wrinkle_amplitude_mm", &sim::DrapeOptions::wrinkle_amplitude_mm},
    {"wrinkle_wavelength_mm", &sim::DrapeOptions::wrinkle_wavelength_mm}};

}  // namespace

HeadPhantomOptions ParsePhantomOptions(JsonFields& in) {
  HeadPhantomOptions options;
  ReadFields(in, options, kPhantomFields);
  in.Read("semi_axes_mm", options.semi_axes_mm);
  in.Read("segments", options.segments);
  if (options.segments > kMaxSegments) Fail(in.At("segments"), "must be <= 1024");
  return options;
}

TriangleMesh ParseShape(const Json& json, const std::string& where,
                        const std::filesystem::path& base) {
  JsonFields in(json, where);
  const std::string kind = [&] {
    std::string k;
    in.Read("kind", k);
    return k;
  }();
  TriangleMesh mesh;
  Checked(where, [&] {
    if (kind == "plane") {
      double width_mm = 100.0, height_mm = 100.0;
      in.Read("width_mm", width_mm);
      in.Read("height_mm", height_mm);
      mesh = sim::PlaneMesh(width_mm, height_mm);
    } else if (kind == "box") {
      Eigen::Vector3d size_mm(100.0, 100.0, 100.0);
      in.Read("size_mm", size_mm);
      mesh = sim::BoxMesh(size_mm);
    } else if (kind == "sphere") {
      double radius_mm = 50.0;
      int segments = 96;
      in.Read("radius_mm", radius_mm);
      in.Read("segments", segments);
      if (segments > kMaxSegments) Fail(in.At("segments"), "must be <= 1024");
      mesh = sim::SphereMesh(radius_mm, segments);
    } else if (kind == "test_shape") {
      const std::pair<const char*, sim::TestShape> shapes[] = {
          {"triangular_pyramid", sim::TestShape::kTriangularPyramid},
          {"frustum_pyramid", sim::TestShape::kFrustumPyramid},
          {"hemisphere", sim::TestShape::kHemisphere}};
      double size_mm = sim::kTestShapeSizesMm[0];
      in.Read("size_mm", size_mm);
      mesh =
          sim::TestShapeMesh(ReadEnum(in, "shape", sim::TestShape::kHemisphere, shapes), size_mm);
    } else if (kind == "capsule") {
      double diameter_mm = 20.0, length_mm = 100.0;
      int segments = 32;
      in.Read("diameter_mm", diameter_mm);
      in.Read("length_mm", length_mm);
      in.Read("segments", segments);
      if (segments > kMaxSegments) Fail(in.At("segments"), "must be <= 1024");
      mesh = sim::CapsuleMesh(diameter_mm, length_mm, segments);
    } else if (kind == "hand") {
      sim::HandOptions hand;
      ReadFields(in, hand, kHandFields);
      in.Read("segments", hand.segments);
      mesh = sim::HandMesh(hand);
    } else if (kind == "drape") {
      sim::DrapeOptions drape;
      ReadFields(in, drape, kDrapeFields);
      in.Read("opening_semi_axes_mm", drape.opening_semi_axes_mm);
      in.Read("seed", drape.seed);
      mesh = sim::DrapeMesh(drape);
    } else if (kind == "head_phantom") {
      mesh = sim::HeadPhantomMesh(ParsePhantomOptions(in));
    } else if (kind == "mesh") {
      std::string path;
      in.Read("path", path);
      if (path.empty()) Fail(in.At("path"), "a mesh shape needs a path");
      mesh = ReadMesh(base / path);
      if (mesh.vertex_normals.empty()) mesh.vertex_normals = mesh.ComputeVertexNormals();
    } else {
      Fail(in.At("kind"),
           "unknown shape '" + kind +
               "' (plane, box, sphere, capsule, hand, drape, test_shape, head_phantom, mesh)");
    }
  });
  in.Finish();
  return mesh;
}

}  // namespace tofnav::internal
