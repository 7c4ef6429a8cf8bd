// SPDX-License-Identifier: BSD-3-Clause
// numpy <-> tofnav conversions shared by the bindings (copies, shapes checked, ValueError else).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>

#include "tofnav/core/image.hpp"
#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"

namespace tofnav::python {

namespace py = pybind11;
using ArrayD = py::array_t<double, py::array::c_style | py::array::forcecast>;
using ArrayF = py::array_t<float, py::array::c_style | py::array::forcecast>;
using ArrayI = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
using ArrayU16 = py::array_t<std::uint16_t, py::array::c_style | py::array::forcecast>;

/// 4 x 4 (or 3 x 4) rigid matrix -> Rigid3d (PreconditionError when not rigid).
Rigid3d RigidFromArray(const ArrayD& matrix);
py::array_t<double> ArrayFromRigid(const Rigid3d& transform);
py::object OptionalArrayFromRigid(const std::optional<Rigid3d>& transform);
std::optional<Rigid3d> OptionalRigidFromObject(const py::object& matrix);

/// (N, 3) <-> points; (3,) <-> vector.
Points3d PointsFromArray(const ArrayD& points, const char* name);
py::array_t<double> ArrayFromPoints(const Points3d& points);
Eigen::Vector3d VectorFromArray(const ArrayD& vector, const char* name);
/// The box [box_min, box_max] from two (3,) arrays, or nullopt when both are None (ValueError when
/// only one is).
std::optional<Eigen::AlignedBox3d> OptionalBoxFromObjects(const py::object& box_min,
                                                          const py::object& box_max);
py::array_t<double> ArrayFromVector(const Eigen::VectorXd& vector);
py::array_t<double> ArrayFromMatrix(const Eigen::MatrixXd& matrix);

/// (H, W) array <-> Image (row v, column u).
template <typename T>
Image<T> ImageFromArray(const py::array_t<T, py::array::c_style | py::array::forcecast>& array,
                        const char* name) {
  if (array.ndim() != 2) throw py::value_error(std::string(name) + " must be a 2-D array");
  Image<T> image(static_cast<int>(array.shape(1)), static_cast<int>(array.shape(0)));
  std::copy_n(array.data(), image.size(), image.data());
  return image;
}
template <typename T>
py::array_t<T> ArrayFromImage(const Image<T>& image) {
  py::array_t<T> array({image.height(), image.width()});
  std::copy_n(image.data(), image.size(), array.mutable_data());
  return array;
}

}  // namespace tofnav::python
