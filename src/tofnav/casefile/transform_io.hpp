// SPDX-License-Identifier: BSD-3-Clause
// Rigid transforms in files: JSON with its frames named, ITK/3D Slicer .tfm, plain 4x4 text.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

/// A transform with the names of its frames (e.g. "tool" from "image"), [mm].
struct NamedTransform {
  std::string target_frame;  // letters, digits and '_' (empty only for the text format)
  std::string source_frame;
  Rigid3d target_from_source;
  /// JSON only: figures written under "quality" (e.g. {"rmse_mm", 0.4}), read back in order.
  std::vector<std::pair<std::string, double>> figures;
};

/// By extension (any case): .json, .tfm (the frames are not stored: ReadTransform leaves them
/// empty) or .txt. IoError for other extensions and for malformed files.
NamedTransform ReadTransform(const std::filesystem::path& path);
/// Writes through a temporary file renamed into place; PreconditionError for bad frame names.
void WriteTransform(const std::filesystem::path& path, const NamedTransform& transform);

/// JSON: {"target_frame": "tool", "source_frame": "image", "units": "mm",
///        "target_from_source": [[r00, r01, r02, tx], [..], [..], [0, 0, 0, 1]],
///        "quality": {"rmse_mm": 0.4, ...}}  (column vectors: x_in_target = M x_in_source).
/// Unknown keys are errors (a typo must not pass silently); "units" and "quality" are optional.
NamedTransform DecodeTransformJson(std::span<const std::uint8_t> bytes,
                                   const std::filesystem::path& source = "<json>");
std::string EncodeTransformJson(const NamedTransform& transform);

/// ITK text transform (.tfm) as 3D Slicer reads and writes it: one AffineTransform_double_3_3
/// (or _float_, or MatrixOffsetTransformBase) in LPS and in the resampling convention, i.e. the
/// file holds the inverse of the transform the node applies: Slicer's ToParent of a node whose
/// child is `a` and parent is `b` is our `b_from_a` with both frames in LPS. ITK maps
/// y = A (x - c) + t + c with c the FixedParameters, so b_from_a = inverse([A | t + c - A c]).
/// A non-rigid matrix is an IoError. Decode returns b_from_a (parent_from_child).
Rigid3d DecodeItkTransform(std::span<const std::uint8_t> bytes,
                           const std::filesystem::path& source = "<tfm>");
std::string EncodeItkTransform(const Rigid3d& parent_from_child);

/// Plain text: optional '#' comment lines (the writer's first line names the frames as
/// "# tofnav transform <target>_from_<source> [mm] ..."), then the 4x4 matrix row by row; the
/// last row must be 0 0 0 1.
NamedTransform DecodeTransformText(std::span<const std::uint8_t> bytes,
                                   const std::filesystem::path& source = "<txt>");
std::string EncodeTransformText(const NamedTransform& transform);

}  // namespace tofnav
