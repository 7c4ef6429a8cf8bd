// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate suite's table: the printed rows, the summary over them and the spread over seeds
// (docs/suite.md).
#pragma once

#include <cstddef>
#include <vector>

#include "tofnav/evaluation/suite_case.hpp"

namespace tofnav {

/// One case's row as a line of the printed table (stdout).
void PrintRow(const SuiteJson& row);
/// Typical (median), best and worst of each figure over the rows, and how many rows meet every
/// line, were refused or had a failed stage.
SuiteJson SuiteSummary(const std::vector<SuiteJson>& rows);
/// Per case, SuiteSummary of its runs over the seeds, with the range the tracking RMS's sampling
/// error alone would give them (`tracking_mm_sampling_range`, docs/statistics.md).
SuiteJson SpreadOverSeeds(const std::vector<SuiteJson>& rows);
/// The spread as a table on stdout.
void PrintSpread(const SuiteJson& spread, std::size_t seeds);

}  // namespace tofnav
