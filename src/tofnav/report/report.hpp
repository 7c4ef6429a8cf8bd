// SPDX-License-Identifier: BSD-3-Clause
// The evaluation report: one self-contained HTML page from a `tofnav demo` output directory.
#pragma once

#include <filesystem>
#include <string>

namespace tofnav {

struct ReportOptions {
  int render_size_px = 320;  // side of each square mesh rendering
  /// Top of the error colour scale [mm]; 0 picks the 95th percentile of the mesh's |errors|.
  double error_max_mm = 0.0;
  void Check() const;  // throws PreconditionError
};

/// The page for the demo directory `demo_dir` (DEMO_SCHEMA: DIR/demo.json and the artefacts it
/// names): header, the paper's tables beside ours and the figures, inline SVG and base64 PNG,
/// no scripts and no external URLs. Stages absent or failed read "not run: <error>"; an artefact
/// that cannot be read replaces only its figure. IoError when demo.json is missing or malformed.
std::string RenderHtmlReport(const std::filesystem::path& demo_dir,
                             const ReportOptions& options = {});

/// RenderHtmlReport written to `out_html` through WriteFileAtomically.
void WriteHtmlReport(const std::filesystem::path& demo_dir, const std::filesystem::path& out_html,
                     const ReportOptions& options = {});

}  // namespace tofnav
