// SPDX-License-Identifier: BSD-3-Clause
// Identification from a recording: frame preparation, two stages, the skin placed once.
#include "tofnav/pipeline/identify.hpp"

#include "tofnav/correction/initial_pose.hpp"
#include "tofnav/imaging/skin.hpp"

namespace tofnav {

IdentifyRecordingResult IdentifyFromRecording(
    const AhatRecording& recording, const AhatCamera& camera,
    const std::optional<MarkerRangeModel>& marker_range, const SurfaceIndex* skin,
    const IdentifyRecordingOptions& options,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  const std::vector<int> picked =
      EvenSubsample(static_cast<int>(recording.frame_count()), options.max_frames);
  const std::vector<IdentificationFrame> frames = PrepareIdentificationFrames(
      picked,
      [&](int i) {
        AhatFrame frame = recording.ReadFrame(static_cast<std::size_t>(i));
        if (options.prepare_frame) options.prepare_frame(frame);
        return frame;
      },
      camera, marker_range.value_or(MarkerRangeModel{}), options.sampling, progress);
  IdentifyRecordingResult result;
  // Stage 1: smoothness only (no CT needed, cheap). Stage 2 (with a skin): both costs from there,
  // with the skin registered once to head clouds corrected by the stage-1 model.
  DepthErrorModel& model = result.file.model;
  model = IdentifyDepthModel(frames, nullptr, options.start, options.identification);
  if (skin != nullptr) {
    const double stage1_s = model.report.seconds;
    const InitialPoseResult pose = InitialImageFromAhat(frames, *skin, model);
    const CorrectnessTarget target{skin, pose.image_from_ahat};
    result.reference_frame = frames[static_cast<std::size_t>(pose.reference_frame)].index;
    result.icp_rmse_mm = pose.registration.icp.rmse_mm;
    result.icp_inlier_fraction = pose.registration.icp.inlier_fraction;
    model = IdentifyDepthModel(frames, &target, model, options.identification);
    model.report.seconds += stage1_s;
    if (options.cross_validate_folds >= 2) {
      model.report.cross_validation =
          CrossValidateModels(frames, &target, DefaultModelCandidates(),
                              options.cross_validate_folds, options.identification);
    }
  } else if (options.cross_validate_folds >= 2) {
    model.report.cross_validation =
        CrossValidateModels(frames, nullptr, DefaultModelCandidates(), options.cross_validate_folds,
                            options.identification);
  }
  model.multipath = options.sampling.multipath;
  result.file.marker_range = marker_range;
  return result;
}

TriangleMesh SkinIsoSurface(const CtVolume& ct, std::optional<double> iso_hu) {
  SkinOptions options;
  options.threshold = iso_hu;
  return ExtractSkin(ct, options).mesh;
}

}  // namespace tofnav
