// SPDX-License-Identifier: BSD-3-Clause
// The one batched loop over a sequence of frames: read a batch in order, prepare its items in
// parallel, consume them in order. Shared by tracking a recording, reconstruction, the f_rf stage
// samples and identification, so that each decodes sequentially (recordings are not thread-safe),
// spends its heavy per-frame work on every core and keeps its order-dependent state (trackers,
// the TSDF) sequential.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tofnav/core/parallel_for.hpp"

namespace tofnav {

/// Seconds spent in each phase of ForEachInBatches, added to by every call.
struct BatchTimes {
  double read_s = 0.0;
  double prepare_s = 0.0;
  double consume_s = 0.0;
};

/// For positions 0 .. count - 1 in batches of `batch_size`: `read(position)` returns the Item
/// (called in order, one thread), `prepare(item, position)` runs in parallel over the batch's
/// items (it may only touch its own item), then `consume(item, position)` runs in order. The
/// result is the same for any thread count.
template <typename Item, typename Read, typename Prepare, typename Consume>
void ForEachInBatches(std::size_t count, std::size_t batch_size, Read&& read, Prepare&& prepare,
                      Consume&& consume, BatchTimes* times = nullptr) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
  };
  batch_size = std::max<std::size_t>(batch_size, 1);
  std::vector<Item> batch;
  for (std::size_t first = 0; first < count; first += batch_size) {
    const std::size_t n = std::min(batch_size, count - first);
    Clock::time_point t = Clock::now();
    batch.clear();
    for (std::size_t k = 0; k < n; ++k) batch.push_back(read(first + k));
    if (times) times->read_s += seconds(t);
    t = Clock::now();
    ParallelFor(0, static_cast<std::int64_t>(n), [&](std::int64_t k) {
      const auto i = static_cast<std::size_t>(k);
      prepare(batch[i], first + i);
    });
    if (times) times->prepare_s += seconds(t);
    t = Clock::now();
    for (std::size_t k = 0; k < n; ++k) consume(batch[k], first + k);
    if (times) times->consume_s += seconds(t);
  }
}

}  // namespace tofnav
