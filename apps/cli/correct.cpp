// SPDX-License-Identifier: BSD-3-Clause
// tofnav correct: apply a depth_model.json to a recording (Eq. 4 on surfaces, Eq. 2 on markers).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <optional>

#include "commands.hpp"
#include "config_json.hpp"
#include "head_region_option.hpp"
#include "progress.hpp"
#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/correction/correct_range.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/open_recording.hpp"

namespace tofnav {

int RunCorrect(int argc, char** argv) {
  CLI::App app{
      "Correct the range of every frame with a depth model: writes an hl2ss recording "
      "(--out X.bin, range rounded to mm) or one PLY point cloud per frame (--out DIR)",
      "tofnav correct"};
  AddConfigOptions(app);
  std::filesystem::path recording_path, calibration_path, model_path, frf_path, out_path;
  std::optional<double> sample_offset;
  bool all_pixels = false, quiet = false;
  CorrectRangeOptions options;
  app.add_option("recording", recording_path, "AHAT recording")->required();
  app.add_option("--calibration", calibration_path, "hl2ss calibration folder")->required();
  app.add_option("--sample-offset", sample_offset, "calibration table sample offset (0 or 0.5)");
  app.add_option("--depth-model", model_path, "depth_model.json (tofnav identify)")->required();
  app.add_option("--marker-error", frf_path, "f_rf JSON (unset: the model file's)");
  app.add_option("--out", out_path, "corrected .bin recording, or a folder for PLY clouds")
      ->required();
  AddHeadRegionOption(app, options.segmentation.head_region);
  app.add_option("--roi-radius-mm", options.segmentation.roi_radius_mm,
                 "keep only pixels this close to the markers' centroid (0 = no limit)");
  app.add_flag("--all-pixels", all_pixels, "correct every valid pixel, not only the ROI");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  TOFNAV_PARSE(app, argc, argv);

  const DepthModelFile model = ReadDepthModelJson(model_path);
  const AhatCamera camera(ReadHl2ssCalibration(calibration_path, sample_offset));
  const std::unique_ptr<AhatRecording> recording = OpenAhatRecording(recording_path);
  if (model.marker_range) options.marker_model = *model.marker_range;
  if (!frf_path.empty()) options.marker_model = ReadMarkerRangeJson(frf_path).model;
  options.roi_only = !all_pixels;
  const bool to_recording = out_path.extension() == ".bin";
  std::optional<Hl2ssRecordingWriter> writer;
  if (to_recording) {
    writer.emplace(out_path);
  } else {
    std::filesystem::create_directories(out_path);
  }
  ProgressBar progress("correct", quiet);
  const std::size_t count = recording->frame_count();
  for (std::size_t i = 0; i < count; ++i) {
    AhatFrame frame = recording->ReadFrame(i);
    const Image<float> corrected = CorrectRangeImage(frame, camera, model.model, options);
    if (writer) {
      for (std::size_t p = 0; p < corrected.size(); ++p) {
        const float d = corrected.pixels()[p];
        frame.range_mm.pixels()[p] =
            d > 0.0f && d < kAhatInvalidRange ? static_cast<std::uint16_t>(std::lround(d)) : 0;
      }
      writer->Append(frame);
    } else {
      PointCloud cloud;
      for (int v = 0; v < corrected.height(); ++v) {
        for (int u = 0; u < corrected.width(); ++u) {
          if (corrected(u, v) > 0.0f)
            cloud.points.push_back(camera.PointFromRange(u, v, corrected(u, v)));
        }
      }
      char name[32];
      std::snprintf(name, sizeof(name), "frame_%06zu.ply", i);
      WritePointCloud(out_path / name, cloud);
    }
    progress.Update(i + 1, count);
  }
  if (writer) writer->Close();
  if (!quiet)
    std::cout << "wrote " << count << " corrected frames to " << out_path.string() << "\n";
  return EXIT_SUCCESS;
}

}  // namespace tofnav
