// SPDX-License-Identifier: BSD-3-Clause
// `tofnav info`: what a recording, calibration, mesh or volume holds.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

namespace tofnav {

struct DescribeOptions {
  /// Frames decoded for depth/AB/pose statistics, spread evenly over the recording (0 = all).
  std::size_t sample_frames = 32;
};

/// Describes `path` (an hl2ss recording, hl2ss calibration folder or Mode-2 blob, StreamRecorder
/// capture folder, mesh, volume, simulation truth.json or Slicer markups) as a JSON object:
/// {"kind": ..., ...}. IoError when it is none of them.
std::string DescribeAsJson(const std::filesystem::path& path, const DescribeOptions& options = {});
/// The same facts as indented "key: value" lines for a terminal.
std::string DescribeAsText(const std::filesystem::path& path, const DescribeOptions& options = {});

}  // namespace tofnav
