// SPDX-License-Identifier: BSD-3-Clause
// Deterministic parallel loop on TBB.
#include "tofnav/core/parallel_for.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace tofnav {

void ParallelFor(std::int64_t begin, std::int64_t end,
                 const std::function<void(std::int64_t)>& body, std::int64_t grain) {
  if (end <= begin) return;
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(begin, end, std::max<std::int64_t>(grain, 1)),
                    [&](const tbb::blocked_range<std::int64_t>& range) {
                      for (std::int64_t i = range.begin(); i != range.end(); ++i) body(i);
                    });
}

}  // namespace tofnav
