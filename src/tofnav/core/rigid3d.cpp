// SPDX-License-Identifier: BSD-3-Clause
// The one rigid transform type, and rotation vectors.
#include "tofnav/core/rigid3d.hpp"

#include <cmath>
#include <sstream>

#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"

namespace tofnav {

Rigid3d Rigid3d::FromMatrix(const Eigen::Matrix4d& matrix, double tolerance) {
  const Eigen::Matrix3d r = matrix.topLeftCorner<3, 3>();
  const double orthogonality =
      (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double bottom = (matrix.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff();
  if (!(orthogonality <= tolerance && std::abs(r.determinant() - 1.0) <= tolerance &&
        bottom <= tolerance)) {
    std::ostringstream text;
    text << "not a rigid transform (|R^T R - I| = " << orthogonality
         << ", det R = " << r.determinant() << ", last row error " << bottom << "):\n"
         << matrix;
    Require(false, text.str());
  }
  // Project onto SO(3) so small numerical drift in stored matrices does not accumulate.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d nearest = svd.matrixU() * svd.matrixV().transpose();
  return {Eigen::Quaterniond(nearest), matrix.topRightCorner<3, 1>()};
}

Eigen::Matrix4d Rigid3d::ToMatrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation.toRotationMatrix();
  m.topRightCorner<3, 1>() = translation;
  return m;
}

Rigid3d Rigid3d::Inverse() const {
  const Eigen::Quaterniond inverse_rotation = rotation.conjugate();
  return {inverse_rotation, -(inverse_rotation * translation)};
}

double RotationDistanceRad(const Rigid3d& a, const Rigid3d& b) {
  return a.rotation.angularDistance(b.rotation);
}

double TranslationDistanceMm(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation - b.translation).norm();
}

Eigen::Vector3d RotationVector(const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd aa(q.w() < 0.0 ? Eigen::Quaterniond(-q.coeffs()) : q);
  return aa.angle() * aa.axis();
}

Eigen::Quaterniond FromRotationVector(const Eigen::Vector3d& rotation_vector_rad) {
  const double angle = rotation_vector_rad.norm();
  if (angle == 0.0) return Eigen::Quaterniond::Identity();  // any other angle is exact
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation_vector_rad / angle));
}

}  // namespace tofnav
