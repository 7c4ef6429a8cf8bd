// SPDX-License-Identifier: BSD-3-Clause
// Checks shared by the casefile JSON readers (internal to casefile).
#pragma once

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace tofnav {

/// The most knots a spline in a casefile JSON may have (a bound against hostile files).
inline constexpr std::size_t kMaxJsonKnots = 100000;

/// `value` as a finite double; an IoError naming `path` and `what` otherwise.
double FiniteJsonNumber(const nlohmann::ordered_json& value, const std::filesystem::path& path,
                        const std::string& what);

}  // namespace tofnav
