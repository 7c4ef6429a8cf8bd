// SPDX-License-Identifier: BSD-3-Clause
// tofnav convert: re-write a recording as hl2ss RAW, hl2ss ZDEPTH or a StreamRecorder capture.
#include "tofnav/recording/convert.hpp"

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.hpp"
#include "config_json.hpp"
#include "progress.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/open_recording.hpp"

namespace tofnav {

int RunConvert(int argc, char** argv) {
  CLI::App app{"Re-write an AHAT recording in another container", "tofnav convert"};
  AddConfigOptions(app);
  std::filesystem::path input_path, output_path, calibration_path;
  std::optional<double> sample_offset_px;
  bool quiet = false, json = false;
  ConvertOptions options;
  const std::map<std::string, RecordingFormat> formats = {
      {"raw", RecordingFormat::kHl2ssRaw},
      {"zdepth", RecordingFormat::kHl2ssZdepth},
      {"stream-recorder", RecordingFormat::kStreamRecorder}};
  app.add_option("input", input_path, "hl2ss .bin file or StreamRecorder folder")->required();
  app.add_option("output", output_path, ".bin file (raw, zdepth) or folder (stream-recorder)")
      ->required();
  AddEnumOption(app, "--to", options.format, formats, "output container")->required();
  app.add_option("--calibration", calibration_path,
                 "hl2ss calibration folder, for StreamRecorder output from an hl2ss input");
  app.add_option("--sample-offset", sample_offset_px,
                 "LUT sample offset of the calibration (0 or 0.5; unset: auto rule)");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the summary as one JSON object");
  TOFNAV_PARSE(app, argc, argv);

  if (!calibration_path.empty()) {
    options.calibration = ReadHl2ssCalibration(calibration_path, sample_offset_px);
  }
  ProgressBar progress("convert", quiet || json);
  options.progress = [&](std::size_t done, std::size_t total) { progress.Update(done, total); };
  const ConvertResult result =
      ConvertRecording(*OpenAhatRecording(input_path), output_path, options);
  progress.Finish();
  if (json) {
    const nlohmann::ordered_json summary{{"input", input_path.string()},
                                         {"output", output_path.string()},
                                         {"frames_written", result.frames_written},
                                         {"frames_with_pose", result.frames_with_pose}};
    std::cout << WithOptions(summary, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "wrote " << result.frames_written << " frames (" << result.frames_with_pose
            << " with pose) to " << output_path.string() << "\n";
  return EXIT_SUCCESS;
}

}  // namespace tofnav
