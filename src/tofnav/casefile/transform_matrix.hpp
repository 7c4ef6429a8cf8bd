// SPDX-License-Identifier: BSD-3-Clause
// Internal to io/: checks shared by the transform formats (rigid matrices, frame names).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

/// Tolerance on |R^T R - I|, det R and the last row: files store 7 to 17 significant digits.
inline constexpr double kRigidTolerance = 1e-5;

/// The rigid transform of a 4x4 matrix; IoError at `offset` when it is not finite or not rigid.
Rigid3d RigidFromMatrix(const Eigen::Matrix4d& matrix, const std::filesystem::path& source,
                        std::optional<std::uint64_t> offset);

/// Non-empty, letters, digits and '_' only (so it survives every format).
bool IsFrameName(std::string_view name);

}  // namespace tofnav
