// SPDX-License-Identifier: BSD-3-Clause
// How far a figure measured over one run would move on another run of the same process: the
// standard error of an RMS over a correlated time series, and the expected range of K draws.
#pragma once

#include <span>

namespace tofnav {

/// Standard error of Rms(series) for values in time order whose errors are correlated over a few
/// samples (a filter's output): overlapping batch means of the squares (batch length
/// round(sqrt(n))) give the mean square's standard error, and the delta method carries it to the
/// root (SE(sqrt m) = SE(m) / (2 sqrt m)); docs/statistics.md, "Sampling error of an RMS".
/// 0 when every value is 0. Throws PreconditionError on fewer than 4 values or a NaN value.
double RmsStandardError(std::span<const double> series);

/// E[max - min] of k independent standard normal draws (k >= 2): 1.128 for two, 1.693 for three
/// (Tippett's d2 constants); the range a figure with standard error s is expected to span over k
/// runs is this times s. Throws PreconditionError for k < 2.
double ExpectedRangeOfNormals(int k);

}  // namespace tofnav
