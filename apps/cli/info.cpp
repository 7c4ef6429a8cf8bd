// SPDX-License-Identifier: BSD-3-Clause
// tofnav info: what a recording, calibration or mesh holds.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "config_json.hpp"
#include "tofnav/describe/describe.hpp"

namespace tofnav {

int RunInfo(int argc, char** argv) {
  CLI::App app{
      "Describe an AHAT recording (hl2ss .bin, StreamRecorder folder), an hl2ss calibration "
      "(folder or Mode-2 blob) or a mesh (.ply/.stl/.obj)",
      "tofnav info"};
  AddConfigOptions(app);
  std::filesystem::path path;
  bool json = false;
  DescribeOptions options;
  app.add_option("path", path, "file or folder")->required();
  app.add_flag("--json", json, "print one JSON object");
  app.add_option("--sample-frames", options.sample_frames,
                 "frames decoded for depth/AB/pose statistics, spread evenly (0 = all)");
  TOFNAV_PARSE(app, argc, argv);
  std::cout << (json ? DescribeAsJson(path, options) + "\n" : DescribeAsText(path, options));
  return EXIT_SUCCESS;
}

}  // namespace tofnav
