// SPDX-License-Identifier: BSD-3-Clause
// The one place that knows about threads: a deterministic parallel loop over [begin, end).
#pragma once

#include <cstdint>
#include <functional>

namespace tofnav {

/// Calls body(i) for every i in [begin, end), in parallel (TBB). The body must only write to
/// state owned by index i, so the result is the same for any thread count.
/// @param grain  indices per task; larger for cheap bodies
void ParallelFor(std::int64_t begin, std::int64_t end,
                 const std::function<void(std::int64_t)>& body, std::int64_t grain = 1);

}  // namespace tofnav
