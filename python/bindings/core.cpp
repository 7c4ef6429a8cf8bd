// SPDX-License-Identifier: BSD-3-Clause
// Mesh (TriangleMesh) with numpy attributes.
#include <pybind11/stl.h>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav::python {
namespace {

py::array_t<std::int64_t> ArrayFromTriangles(const std::vector<Eigen::Vector3i>& triangles) {
  py::array_t<std::int64_t> array({static_cast<py::ssize_t>(triangles.size()), py::ssize_t{3}});
  std::int64_t* out = array.mutable_data();
  for (const Eigen::Vector3i& t : triangles) {
    for (int c = 0; c < 3; ++c) *out++ = t[c];
  }
  return array;
}

std::vector<Eigen::Vector3i> TrianglesFromArray(const ArrayI& array) {
  if (array.ndim() != 2 || array.shape(1) != 3) {
    throw py::value_error("triangles must be an (M, 3) integer array");
  }
  std::vector<Eigen::Vector3i> triangles(static_cast<std::size_t>(array.shape(0)));
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const std::int64_t* t = array.data(static_cast<py::ssize_t>(i), 0);
    triangles[i] = {static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2])};
  }
  return triangles;
}

TriangleMesh MakeMesh(const ArrayD& vertices, const ArrayI& triangles, const py::object& normals,
                      const py::object& scalars) {
  TriangleMesh mesh;
  mesh.vertices = PointsFromArray(vertices, "vertices");
  mesh.triangles = TrianglesFromArray(triangles);
  if (!normals.is_none()) mesh.vertex_normals = PointsFromArray(normals.cast<ArrayD>(), "normals");
  if (!scalars.is_none()) {
    const auto values = scalars.cast<ArrayF>();
    mesh.vertex_scalars.assign(values.data(), values.data() + values.size());
  }
  mesh.CheckConsistent();
  return mesh;
}

}  // namespace

void DefineCore(py::module_& m) {
  py::class_<TriangleMesh>(m, "Mesh", "Indexed triangle mesh [mm], counter-clockwise from outside")
      .def(py::init(&MakeMesh), py::arg("vertices"), py::arg("triangles"),
           py::arg("normals") = py::none(), py::arg("scalars") = py::none())
      .def_property_readonly(
          "vertices", [](const TriangleMesh& mesh) { return ArrayFromPoints(mesh.vertices); },
          "(N, 3) float64 [mm]")
      .def_property_readonly(
          "triangles", [](const TriangleMesh& mesh) { return ArrayFromTriangles(mesh.triangles); },
          "(M, 3) int64 vertex indices")
      .def_property_readonly(
          "normals", [](const TriangleMesh& mesh) { return ArrayFromPoints(mesh.vertex_normals); },
          "(N, 3) unit vertex normals, or (0, 3)")
      .def_property_readonly(
          "scalars",
          [](const TriangleMesh& mesh) {
            py::array_t<float> array(static_cast<py::ssize_t>(mesh.vertex_scalars.size()));
            std::copy(mesh.vertex_scalars.begin(), mesh.vertex_scalars.end(), array.mutable_data());
            return array;
          })
      .def(
          "compute_normals",
          [](const TriangleMesh& mesh) { return ArrayFromPoints(mesh.ComputeVertexNormals()); },
          "area-weighted vertex normals from the triangles, (N, 3)")
      .def("surface_area_mm2", &TriangleMesh::SurfaceAreaMm2)
      .def(
          "transformed",
          [](const TriangleMesh& mesh, const ArrayD& b_from_a) {
            return Transform(RigidFromArray(b_from_a), mesh);
          },
          py::arg("b_from_a"), "the mesh mapped by a 4 x 4 rigid transform")
      .def("__repr__", [](const TriangleMesh& mesh) {
        return "<tofnav.Mesh " + std::to_string(mesh.vertices.size()) + " vertices, " +
               std::to_string(mesh.triangles.size()) + " triangles>";
      });
}

}  // namespace tofnav::python
