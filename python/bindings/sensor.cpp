// SPDX-License-Identifier: BSD-3-Clause
// Calibration, Frame and AhatCamera: rays, projection, range image to points.
#include <pybind11/stl.h>

#include <cmath>
#include <limits>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav::python {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

AhatFrame MakeFrame(const ArrayU16& depth, const ArrayU16& ab, const py::object& world_from_rig,
                    double timestamp_s) {
  AhatFrame frame;
  frame.range_mm = ImageFromArray<std::uint16_t>(depth, "depth");
  frame.ab = ImageFromArray<std::uint16_t>(ab, "ab");
  frame.world_from_rig = OptionalRigidFromObject(world_from_rig);
  frame.host_ticks = static_cast<std::uint64_t>(std::llround(timestamp_s / kSecondsPerHostTick));
  return frame;
}

py::array_t<double> Rays(const AhatCamera& camera, const ArrayD& pixels) {
  if (pixels.ndim() != 2 || pixels.shape(1) != 2) {
    throw py::value_error("pixels must be an (N, 2) array of (u, v)");
  }
  py::array_t<double> rays({pixels.shape(0), py::ssize_t{3}});
  for (py::ssize_t i = 0; i < pixels.shape(0); ++i) {
    const std::optional<Eigen::Vector3d> ray = camera.Ray({pixels.at(i, 0), pixels.at(i, 1)});
    for (py::ssize_t c = 0; c < 3; ++c) rays.mutable_at(i, c) = ray ? (*ray)[c] : kNan;
  }
  return rays;
}

py::array_t<double> Project(const AhatCamera& camera, const ArrayD& points) {
  const Points3d input = PointsFromArray(points, "points");
  py::array_t<double> pixels({static_cast<py::ssize_t>(input.size()), py::ssize_t{2}});
  for (std::size_t i = 0; i < input.size(); ++i) {
    const std::optional<Eigen::Vector2d> pixel = camera.Project(input[i]);
    const auto row = static_cast<py::ssize_t>(i);
    pixels.mutable_at(row, 0) = pixel ? pixel->x() : kNan;
    pixels.mutable_at(row, 1) = pixel ? pixel->y() : kNan;
  }
  return pixels;
}

py::array_t<double> PointsFromRange(const AhatCamera& camera, const ArrayD& range_mm) {
  if (range_mm.ndim() != 2 || range_mm.shape(0) != camera.height() ||
      range_mm.shape(1) != camera.width()) {
    throw py::value_error("range_mm must be a (height, width) array");
  }
  py::array_t<double> points({range_mm.shape(0), range_mm.shape(1), py::ssize_t{3}});
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const Eigen::Vector3d p = camera.PointFromRange(u, v, range_mm.at(v, u));
      for (int c = 0; c < 3; ++c) points.mutable_at(v, u, c) = p[c];
    }
  }
  return points;
}

py::array_t<bool> ValidMask(const AhatCamera& camera) {
  py::array_t<bool> mask({camera.height(), camera.width()});
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) mask.mutable_at(v, u) = camera.IsValid(u, v);
  }
  return mask;
}

}  // namespace

void DefineSensor(py::module_& m) {
  py::class_<AhatCalibration>(m, "Calibration", "AHAT device calibration (unit-plane table)")
      .def_property_readonly(
          "rig_from_ahat", [](const AhatCalibration& c) { return ArrayFromRigid(c.rig_from_ahat); })
      .def_readonly("sample_offset_px", &AhatCalibration::sample_offset_px)
      .def_readonly("scale", &AhatCalibration::scale)
      .def_readonly("alias_mm", &AhatCalibration::alias_mm)
      .def_property_readonly(
          "uv2xy",
          [](const AhatCalibration& c) {
            py::array_t<float> table({c.uv2xy.height(), c.uv2xy.width(), 2});
            for (int v = 0; v < c.uv2xy.height(); ++v) {
              for (int u = 0; u < c.uv2xy.width(); ++u) {
                table.mutable_at(v, u, 0) = c.uv2xy(u, v).x();
                table.mutable_at(v, u, 1) = c.uv2xy(u, v).y();
              }
            }
            return table;
          },
          "(H, W, 2) float32 unit-plane (x, y) per pixel, NaN where invalid");
  m.def(
      "synthetic_calibration",
      [](double focal_px, double sample_offset_px) {
        return MakeSyntheticAhatCalibration(
            {.focal_px = focal_px, .sample_offset_px = sample_offset_px});
      },
      py::arg("focal_px") = 254.0, py::arg("sample_offset_px") = 0.5,
      "an equidistant-fisheye 512 x 512 calibration with known truth "
      "(MakeSyntheticAhatCalibration)");

  py::class_<AhatFrame>(m, "Frame", "one AHAT frame: depth (range along the ray, mm) and AB")
      .def(py::init(&MakeFrame), py::arg("depth"), py::arg("ab"),
           py::arg("world_from_rig") = py::none(), py::arg("timestamp_s") = 0.0)
      .def_property_readonly(
          "depth", [](const AhatFrame& f) { return ArrayFromImage(f.range_mm); },
          "(512, 512) uint16 range [mm] along each pixel's ray, 0 = invalid")
      .def_property_readonly(
          "ab", [](const AhatFrame& f) { return ArrayFromImage(f.ab); },
          "(512, 512) uint16 active brightness")
      .def_property_readonly(
          "world_from_rig",
          [](const AhatFrame& f) { return OptionalArrayFromRigid(f.world_from_rig); })
      .def_readonly("host_ticks", &AhatFrame::host_ticks)
      .def_property_readonly("timestamp_s", &AhatFrame::timestamp_s)
      .def_readonly("depth_step_mm", &AhatFrame::depth_step_mm)
      .def_readonly("ab_lossy", &AhatFrame::ab_lossy,
                    "AB is a lossy stream's square code (AB = code^2, docs/ahat.md 3.6.1)");

  py::class_<AhatCamera>(m, "AhatCamera", "AHAT camera model from a calibration's ray table")
      .def(py::init([](const AhatCalibration& calibration, double pixel_centre_offset_px,
                       double valid_radius_px) {
             return AhatCamera(calibration, {.pixel_centre_offset_px = pixel_centre_offset_px,
                                             .valid_radius_px = valid_radius_px});
           }),
           py::arg("calibration"), py::arg("pixel_centre_offset_px") = 0.5,
           py::arg("valid_radius_px") = 0.0)
      .def_property_readonly("width", &AhatCamera::width)
      .def_property_readonly("height", &AhatCamera::height)
      .def_property_readonly("rig_from_ahat",
                             [](const AhatCamera& c) { return ArrayFromRigid(c.rig_from_ahat()); })
      .def_property_readonly(
          "principal_point_px",
          [](const AhatCamera& c) { return ArrayFromVector(c.principal_point_px()); })
      .def("valid_mask", &ValidMask, "(H, W) bool: pixels with a usable ray")
      .def("rays", &Rays, py::arg("pixels"),
           "(N, 2) pixel positions (u, v), centres at integers -> (N, 3) unit rays, NaN if invalid")
      .def("project", &Project, py::arg("points"),
           "(N, 3) points in ahat [mm] -> (N, 2) pixel positions, NaN outside the field")
      .def("points_from_range", &PointsFromRange, py::arg("range_mm"),
           "(H, W) range [mm] -> (H, W, 3) points in ahat [mm], zero where invalid or range 0");
}

}  // namespace tofnav::python
