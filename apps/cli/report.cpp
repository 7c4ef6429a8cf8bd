// SPDX-License-Identifier: BSD-3-Clause
// tofnav report: the evaluation report (one self-contained HTML page) of a demo directory.
#include "tofnav/report/report.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "config_json.hpp"

namespace tofnav {

int RunReport(int argc, char** argv) {
  CLI::App app{
      "Write the evaluation report of a `tofnav demo --out DIR` directory: one self-contained "
      "HTML page with the paper's tables beside ours and the figures (docs/report.md)",
      "tofnav report"};
  AddConfigOptions(app);
  std::filesystem::path demo_dir, out_path;
  ReportOptions options;
  bool quiet = false, json = false;
  app.add_option("dir", demo_dir, "demo output directory (holds demo.json)")->required();
  app.add_option("--out", out_path, "output HTML file (unset: DIR/report.html)");
  app.add_option("--render-size", options.render_size_px, "side of each mesh rendering [px]")
      ->check(CLI::Range(64, 2048));
  app.add_option("--error-max", options.error_max_mm,
                 "top of the error colour scale [mm] (0: the 95th percentile)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", quiet, "no summary");
  app.add_flag("--json", json, "print the summary as one JSON object");
  TOFNAV_PARSE(app, argc, argv);

  if (out_path.empty()) out_path = demo_dir / "report.html";
  const auto start = std::chrono::steady_clock::now();
  WriteHtmlReport(demo_dir, out_path, options);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto bytes = std::filesystem::file_size(out_path);
  if (json) {
    std::cout << WithOptions(nlohmann::ordered_json{{"dir", demo_dir.string()},
                                                    {"out", out_path.string()},
                                                    {"bytes", bytes},
                                                    {"elapsed_s", elapsed_s}},
                             app)
                     .dump()
              << "\n";
  } else if (!quiet) {
    std::cout << "wrote " << out_path.string() << " (" << bytes / 1024 << " KiB) in " << elapsed_s
              << " s\n";
  }
  return EXIT_SUCCESS;
}

}  // namespace tofnav
