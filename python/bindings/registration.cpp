// SPDX-License-Identifier: BSD-3-Clause
// Surface registration (skin to reconstruction, with quality and refusal) and paired points.
#include <pybind11/stl.h>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/registration/paired_points.hpp"
#include "tofnav/registration/register_surface.hpp"

namespace tofnav::python {
namespace {

RegisterSurfaceResult Register(const ArrayD& points, const TriangleMesh& skin_in_image,
                               const py::object& normals, const py::object& targets,
                               const py::object& guess, double sample_spacing_mm) {
  PointCloud reconstruction;
  reconstruction.points = PointsFromArray(points, "reconstruction");
  if (!normals.is_none())
    reconstruction.normals = PointsFromArray(normals.cast<ArrayD>(), "normals");
  reconstruction.CheckConsistent();
  const Points3d target_points =
      targets.is_none() ? Points3d{} : PointsFromArray(targets.cast<ArrayD>(), "targets");
  const std::optional<Rigid3d> tool_from_image_guess = OptionalRigidFromObject(guess);
  py::gil_scoped_release release;
  const SurfaceIndex skin(skin_in_image);
  return RegisterSurface(reconstruction, skin, target_points,
                         {.sample_spacing_mm = sample_spacing_mm}, tool_from_image_guess);
}

}  // namespace

void DefineRegistration(py::module_& m) {
  py::class_<RegisterSurfaceResult>(m, "SurfaceRegistration", "RegisterSurface's result")
      .def_property_readonly(
          "tool_from_image",
          [](const RegisterSurfaceResult& r) { return ArrayFromRigid(r.tool_from_image); })
      .def_property_readonly("accepted",
                             [](const RegisterSurfaceResult& r) { return r.quality.accepted(); })
      .def_property_readonly(
          "status", [](const RegisterSurfaceResult& r) { return ToString(r.quality.status); })
      .def_property_readonly("message",
                             [](const RegisterSurfaceResult& r) { return r.quality.message; })
      .def_property_readonly("rmse_mm",
                             [](const RegisterSurfaceResult& r) { return r.quality.rmse_mm; })
      .def_property_readonly(
          "inlier_fraction",
          [](const RegisterSurfaceResult& r) { return r.quality.inlier_fraction; })
      .def_property_readonly(
          "residual_sigma_mm",
          [](const RegisterSurfaceResult& r) { return r.quality.residual_sigma_mm; })
      .def_property_readonly(
          "rotation_conditioning",
          [](const RegisterSurfaceResult& r) { return r.quality.conditioning.rotation; })
      .def_property_readonly(
          "translation_conditioning",
          [](const RegisterSurfaceResult& r) { return r.quality.conditioning.translation; })
      .def_property_readonly(
          "predicted_tre_mm",
          [](const RegisterSurfaceResult& r) { return r.quality.predicted_tre_mm; })
      .def_property_readonly("ambiguity",
                             [](const RegisterSurfaceResult& r) { return r.quality.ambiguity; })
      .def_property_readonly("icp_iterations",
                             [](const RegisterSurfaceResult& r) { return r.icp.iterations; });
  m.def("register_surface", &Register, py::arg("reconstruction_in_tool"), py::arg("skin_in_image"),
        py::arg("normals") = py::none(), py::arg("targets_in_image") = py::none(),
        py::arg("tool_from_image_guess") = py::none(), py::arg("sample_spacing_mm") = 1.5,
        "register the CT skin (Mesh in image) to reconstructed points (N, 3) in tool: automatic "
        "coarse alignment unless a 4 x 4 guess is given, then robust point-to-plane ICP");

  m.def(
      "register_paired_points",
      [](const ArrayD& source, const ArrayD& target) {
        const PairedPointResult r = RegisterPairedPoints(PointsFromArray(source, "source"),
                                                         PointsFromArray(target, "target"));
        return py::make_tuple(ArrayFromRigid(r.target_from_source), r.fre_rms_mm, r.residuals_mm);
      },
      py::arg("source"), py::arg("target"),
      "paired (N, 3) points -> (target_from_source 4 x 4, FRE RMS [mm], residuals [mm])");
}

}  // namespace tofnav::python
