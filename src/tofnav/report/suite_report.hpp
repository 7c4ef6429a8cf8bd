// SPDX-License-Identifier: BSD-3-Clause
// The robustness suite's page: one self-contained HTML table of its rows (docs/suite.md).
#pragma once

#include <filesystem>
#include <string>

namespace tofnav {

/// The page for `suite_json` (written by `tofnav evaluate suite`: {"format": "tofnav-suite-result",
/// "rows": [...], "summary": {...}}): the table of every case with each figure marked against
/// its acceptance line, the summary, and a bar chart of the reconstruction and guidance errors.
/// No scripts, no external URLs. IoError when the file is missing or malformed.
std::string RenderSuiteHtml(const std::filesystem::path& suite_json);
/// RenderSuiteHtml written to `out_html` through WriteFileAtomically.
void WriteSuiteHtml(const std::filesystem::path& suite_json, const std::filesystem::path& out_html);

}  // namespace tofnav
