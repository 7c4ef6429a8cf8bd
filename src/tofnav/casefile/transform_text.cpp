// SPDX-License-Identifier: BSD-3-Clause
// Transform text formats: ITK/3D Slicer .tfm (LPS, resampling convention) and a plain 4x4 matrix.
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <string>

#include "tofnav/casefile/transform_io.hpp"
#include "tofnav/casefile/transform_matrix.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/mesh_text.hpp"

namespace tofnav {
namespace {

/// The ITK transform types whose Parameters are 9 matrix entries (row-major) and 3 translations.
bool IsMatrixOffsetType(std::string_view type) {
  return type == "AffineTransform_double_3_3" || type == "AffineTransform_float_3_3" ||
         type == "MatrixOffsetTransformBase_double_3_3" ||
         type == "MatrixOffsetTransformBase_float_3_3";
}

/// `count` finite numbers on the current line, then its end.
template <std::size_t N>
std::array<double, N> NumbersOnLine(TextScanner& scanner, std::string_view what) {
  std::array<double, N> values{};
  for (double& v : values) {
    const auto token = scanner.TokenOnLine();
    if (!token) scanner.Fail("expected " + std::to_string(N) + " numbers of " + std::string(what));
    if (!ParseNumber(*token, v) || !std::isfinite(v)) scanner.FailExpected("a finite number");
  }
  scanner.ExpectLineEnd(what);
  return values;
}

/// Space-separated shortest round-trip decimals (exact for doubles), "-0" written as "0".
void AppendNumbers(std::string& out, const double* values, int count) {
  for (int i = 0; i < count; ++i) {
    if (i > 0) out += ' ';
    AppendNumber(out, values[i] == 0.0 ? 0.0 : values[i]);
  }
}

}  // namespace

Rigid3d RigidFromMatrix(const Eigen::Matrix4d& matrix, const std::filesystem::path& source,
                        std::optional<std::uint64_t> offset) {
  if (!matrix.allFinite()) throw IoError(source, offset, "the transform is not finite");
  try {
    return Rigid3d::FromMatrix(matrix, kRigidTolerance);
  } catch (const PreconditionError& e) {
    throw IoError(source, offset, std::string("not a rigid transform: ") + e.what());
  }
}

bool IsFrameName(std::string_view name) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) return false;
  }
  return true;
}

Rigid3d DecodeItkTransform(std::span<const std::uint8_t> bytes,
                           const std::filesystem::path& source) {
  TextScanner scanner(bytes, source);
  for (const std::string_view word : {"#Insight", "Transform", "File"}) {
    if (scanner.TokenOnLine() != word) scanner.FailExpected("'#Insight Transform File V1.0'");
  }
  scanner.SkipLine();
  std::optional<std::array<double, 12>> parameters;
  std::optional<std::array<double, 3>> centre;
  std::uint64_t parameters_offset = 0;
  bool have_type = false;
  while (const auto token = scanner.NextToken()) {
    if (*token == "Transform:") {
      const std::string_view type = scanner.Token("a transform type");
      if (type.starts_with("CompositeTransform_")) {  // a wrapper: its parts follow
        scanner.ExpectLineEnd("the transform type");
        continue;
      }
      if (!IsMatrixOffsetType(type)) scanner.FailExpected("AffineTransform_double_3_3 (rigid)");
      if (have_type) scanner.Fail("more than one transform (expected exactly one)");
      have_type = true;
      scanner.ExpectLineEnd("the transform type");
    } else if (*token == "Parameters:") {
      if (!have_type || parameters) scanner.Fail("Parameters without their own Transform: line");
      parameters_offset = scanner.token_offset();
      parameters = NumbersOnLine<12>(scanner, "Parameters (9 matrix entries, 3 translations)");
    } else if (*token == "FixedParameters:") {
      if (!have_type || centre) scanner.Fail("FixedParameters without their own Transform: line");
      centre = NumbersOnLine<3>(scanner, "FixedParameters (the centre)");
    } else if (token->starts_with("#")) {
      scanner.SkipLine();  // "#Transform N" and comments
    } else {
      scanner.FailExpected("Transform:, Parameters: or FixedParameters:");
    }
  }
  if (!parameters || !centre) {
    throw IoError(source, bytes.size(), "expected a transform with Parameters and FixedParameters");
  }
  // ITK: y = A (x - c) + t + c maps the fixed (parent) space into the moving (child) one.
  Eigen::Matrix3d a;
  for (int i = 0; i < 9; ++i) a(i / 3, i % 3) = (*parameters)[static_cast<std::size_t>(i)];
  const Eigen::Vector3d t((*parameters)[9], (*parameters)[10], (*parameters)[11]);
  const Eigen::Vector3d c((*centre)[0], (*centre)[1], (*centre)[2]);
  Eigen::Matrix4d child_from_parent = Eigen::Matrix4d::Identity();
  child_from_parent.topLeftCorner<3, 3>() = a;
  child_from_parent.topRightCorner<3, 1>() = t + c - a * c;
  const Rigid3d rigid = RigidFromMatrix(child_from_parent, source, parameters_offset);
  return rigid.Inverse();
}

std::string EncodeItkTransform(const Rigid3d& parent_from_child) {
  const Eigen::Matrix4d m = parent_from_child.Inverse().ToMatrix();  // the resampling direction
  Require(m.allFinite(), "EncodeItkTransform: the transform must be finite");
  std::string out = "#Insight Transform File V1.0\n#Transform 0\n";
  out += "Transform: AffineTransform_double_3_3\nParameters: ";
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> a = m.topLeftCorner<3, 3>();
  AppendNumbers(out, a.data(), 9);
  out += ' ';
  const Eigen::Vector3d t = m.topRightCorner<3, 1>();
  AppendNumbers(out, t.data(), 3);
  out += "\nFixedParameters: 0 0 0\n";
  return out;
}

NamedTransform DecodeTransformText(std::span<const std::uint8_t> bytes,
                                   const std::filesystem::path& source) {
  TextScanner scanner(bytes, source);
  NamedTransform transform;
  Eigen::Matrix4d m;
  int read = 0;
  std::uint64_t first_offset = 0;
  while (const auto token = scanner.NextToken()) {
    if (token->starts_with("#")) {
      // "# tofnav transform <target>_from_<source> ..." names the frames.
      // Strings, not optional<string_view>: GCC 12 -O3 warns (maybe-uninitialized) on those.
      const std::string tofnav(scanner.TokenOnLine().value_or(""));
      const std::string kind(tofnav.empty() ? "" : scanner.TokenOnLine().value_or(""));
      const std::string name(kind.empty() ? "" : scanner.TokenOnLine().value_or(""));
      if (*token == "#" && tofnav == "tofnav" && kind == "transform" && !name.empty()) {
        const std::size_t split = name.find("_from_");
        if (split == std::string::npos || !IsFrameName(name.substr(0, split)) ||
            !IsFrameName(name.substr(split + 6))) {
          scanner.FailExpected("<target>_from_<source> frame names");
        }
        transform.target_frame = name.substr(0, split);
        transform.source_frame = name.substr(split + 6);
      }
      scanner.SkipLine();
      continue;
    }
    if (read == 16) scanner.Fail("expected the end of the file after 16 matrix entries");
    if (read == 0) first_offset = scanner.token_offset();
    double value = 0.0;
    if (!ParseNumber(*token, value) || !std::isfinite(value))
      scanner.FailExpected("a finite number");
    m(read / 4, read % 4) = value;
    ++read;
  }
  if (read < 16) {
    throw IoError(source, bytes.size(),
                  "expected 16 matrix entries, found " + std::to_string(read));
  }
  transform.target_from_source = RigidFromMatrix(m, source, first_offset);
  return transform;
}

std::string EncodeTransformText(const NamedTransform& transform) {
  const bool named = !transform.target_frame.empty() || !transform.source_frame.empty();
  Require(!named || (IsFrameName(transform.target_frame) && IsFrameName(transform.source_frame)),
          "EncodeTransformText: frame names must be letters, digits and '_'");
  std::string out = "# tofnav transform ";
  out += named ? transform.target_frame + "_from_" + transform.source_frame + " [mm]"
               : std::string("[mm]");
  out += ": x_in_target = M * x_in_source\n";
  const Eigen::Matrix4d m = transform.target_from_source.ToMatrix();
  Require(m.allFinite(), "EncodeTransformText: the transform must be finite");
  for (int r = 0; r < 4; ++r) {
    const Eigen::RowVector4d row = m.row(r);
    AppendNumbers(out, row.data(), 4);
    out += '\n';
  }
  return out;
}

}  // namespace tofnav
