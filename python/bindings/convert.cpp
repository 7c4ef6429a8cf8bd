// SPDX-License-Identifier: BSD-3-Clause
// numpy <-> tofnav conversions shared by the bindings.
#include "convert.hpp"

#include <string>

namespace tofnav::python {

Rigid3d RigidFromArray(const ArrayD& matrix) {
  if (matrix.ndim() != 2 || (matrix.shape(0) != 4 && matrix.shape(0) != 3) ||
      matrix.shape(1) != 4) {
    throw py::value_error("a transform must be a 4 x 4 (or 3 x 4) array");
  }
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (py::ssize_t r = 0; r < matrix.shape(0); ++r) {
    for (py::ssize_t c = 0; c < 4; ++c) m(r, c) = matrix.at(r, c);
  }
  return Rigid3d::FromMatrix(m);
}

py::array_t<double> ArrayFromRigid(const Rigid3d& transform) {
  return ArrayFromMatrix(transform.ToMatrix());
}

py::object OptionalArrayFromRigid(const std::optional<Rigid3d>& transform) {
  if (!transform) return py::none();
  return ArrayFromRigid(*transform);
}

std::optional<Rigid3d> OptionalRigidFromObject(const py::object& matrix) {
  if (matrix.is_none()) return std::nullopt;
  return RigidFromArray(matrix.cast<ArrayD>());
}

Points3d PointsFromArray(const ArrayD& points, const char* name) {
  if (points.ndim() != 2 || points.shape(1) != 3) {
    throw py::value_error(std::string(name) + " must be an (N, 3) array");
  }
  Points3d result(static_cast<std::size_t>(points.shape(0)));
  for (std::size_t i = 0; i < result.size(); ++i) {
    const double* p = points.data(static_cast<py::ssize_t>(i), 0);
    result[i] = {p[0], p[1], p[2]};
  }
  return result;
}

py::array_t<double> ArrayFromPoints(const Points3d& points) {
  py::array_t<double> array({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  double* out = array.mutable_data();
  for (const Eigen::Vector3d& p : points) {
    *out++ = p.x();
    *out++ = p.y();
    *out++ = p.z();
  }
  return array;
}

Eigen::Vector3d VectorFromArray(const ArrayD& vector, const char* name) {
  if (vector.size() != 3) throw py::value_error(std::string(name) + " must have 3 values");
  return {vector.data()[0], vector.data()[1], vector.data()[2]};
}

std::optional<Eigen::AlignedBox3d> OptionalBoxFromObjects(const py::object& box_min,
                                                          const py::object& box_max) {
  if (box_min.is_none() != box_max.is_none()) {
    throw py::value_error("give both ends of the box (e.g. roi_min and roi_max), or neither");
  }
  if (box_min.is_none()) return std::nullopt;
  return Eigen::AlignedBox3d(VectorFromArray(box_min.cast<ArrayD>(), "box minimum"),
                             VectorFromArray(box_max.cast<ArrayD>(), "box maximum"));
}

py::array_t<double> ArrayFromVector(const Eigen::VectorXd& vector) {
  py::array_t<double> array(vector.size());
  std::copy_n(vector.data(), vector.size(), array.mutable_data());
  return array;
}

py::array_t<double> ArrayFromMatrix(const Eigen::MatrixXd& matrix) {
  py::array_t<double> array({matrix.rows(), matrix.cols()});
  for (Eigen::Index r = 0; r < matrix.rows(); ++r) {
    for (Eigen::Index c = 0; c < matrix.cols(); ++c) array.mutable_at(r, c) = matrix(r, c);
  }
  return array;
}

}  // namespace tofnav::python
