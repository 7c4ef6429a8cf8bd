// SPDX-License-Identifier: BSD-3-Clause
// Internal to describe.cpp: `tofnav info` for JSON documents (simulation truth, Slicer markups).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

namespace tofnav::internal {

/// {"kind": "simulation truth" | "markups", ...}; IoError for any other or malformed JSON.
nlohmann::ordered_json DescribeJsonDocument(const std::filesystem::path& path);

}  // namespace tofnav::internal
