// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: the planned-trajectory readers (markups JSON and legacy .fcsv) on any bytes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "tofnav/casefile/markups_read.hpp"
#include "tofnav/io/io_error.hpp"

namespace {

/// Whatever decodes must be finite: a NaN plan would be a silently wrong target.
void CheckFinite(const std::vector<tofnav::Trajectory>& plan) {
  if (plan.empty()) std::abort();
  for (const tofnav::Trajectory& t : plan) {
    if (!t.entry_lps_mm.allFinite() || !t.target_lps_mm.allFinite()) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  try {
    CheckFinite(tofnav::DecodeTrajectoryMarkups(bytes));
  } catch (const tofnav::IoError&) {
  }
  try {
    CheckFinite(tofnav::DecodeTrajectoryFcsv(bytes));
  } catch (const tofnav::IoError&) {
  }
  try {
    for (const Eigen::Vector3d& p : tofnav::DecodeMarkupPointsJson(bytes)) {
      if (!p.allFinite()) std::abort();
    }
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
