// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/sensor/ahat_recording.hpp"

#include "tofnav/core/require.hpp"

namespace tofnav {

std::size_t AhatRecording::NearestFrame(std::uint64_t ticks) const {
  const std::size_t n = frame_count();
  Require(n > 0, "NearestFrame on an empty recording");
  // Binary search on the non-decreasing timestamps.
  std::size_t lo = 0;
  std::size_t hi = n;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (host_ticks(mid) < ticks) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  if (lo == n) return n - 1;
  if (lo == 0) return 0;
  return (ticks - host_ticks(lo - 1) <= host_ticks(lo) - ticks) ? lo - 1 : lo;
}

}  // namespace tofnav
