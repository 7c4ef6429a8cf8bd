// SPDX-License-Identifier: BSD-3-Clause
// Fidelity, the skin study (paper Sec. III-A, 10 participants): each participant's skin drawn
// from the simulator's spread, forehead stickers seen from 180-500 mm; the depth error is each
// sticker's (f_rf-corrected) distance to the cubic surface fitted to the skin around it (Eq. 6
// with no skin correction), averaged per participant.
#include <cmath>

#include "tofnav/core/statistics.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/correction/surface_costs.hpp"
#include "tofnav/evaluation/fidelity.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/sim/scenario_fidelity.hpp"

namespace tofnav {
namespace {

const char* const kSkinSource = "paper Sec. III-A (10 participants, 180-500 mm)";

// One participant's mean depth error [mm]: |mean distance| of each marker patch, averaged.
double ParticipantErrorMm(const FidelityOptions& options, const MarkerRangeModel& frf, int index,
                          const sim::Material& skin, std::size_t& patches) {
  const auto frames = static_cast<std::int64_t>(std::max(
      10.0, std::round(static_cast<double>(options.participant_frames) * options.frames_scale)));
  const sim::Scenario scenario = sim::SkinStudyScenario(sim::PhantomHead(), skin, frames);
  const std::string label = "skin study: participant " + std::to_string(index + 1);
  const std::filesystem::path dir = options.out / ("skin_participant_" + std::to_string(index + 1));
  SimulateForFidelity(options, scenario, dir, label,
                      options.seed + static_cast<std::uint64_t>(index));
  const RecordingWithCamera opened =
      OpenRecordingWithCamera(dir / "rm_depth_ahat.bin", dir / "calibration");
  IdentificationSampling sampling;
  sampling.multipath.enabled = false;  // the raw skin, as measured
  std::vector<int> indices(opened.recording->frame_count());
  for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<int>(i);
  const std::vector<IdentificationFrame> prepared = PrepareIdentificationFrames(
      indices, [&](int i) { return opened.recording->ReadFrame(static_cast<std::size_t>(i)); },
      *opened.camera, frf, sampling);
  DepthErrorModel none;  // no skin correction: the skin's own error
  none.multipath.enabled = false;
  std::vector<double> per_patch;
  for (const IdentificationFrame& f : prepared) {
    for (const MarkerPatch& patch : f.markers) {
      const std::vector<double> d = SmoothnessDistances(patch, none);
      if (!d.empty()) per_patch.push_back(std::abs(Mean(d)));
    }
  }
  if (per_patch.empty()) throw std::runtime_error(label + ": no sticker with skin around it");
  patches = per_patch.size();
  return Mean(per_patch);
}

}  // namespace

void FidelitySkinStudy(const FidelityOptions& options, const MarkerRangeModel& frf,
                       FidelityResult& result) {
  std::vector<double> errors;
  nlohmann::ordered_json participants = nlohmann::ordered_json::array();
  for (int i = 0; i < options.participants; ++i) {
    const sim::Material skin = sim::SkinParticipant(options.seed, i);
    std::size_t patches = 0;
    errors.push_back(ParticipantErrorMm(options, frf, i, skin, patches));
    participants.push_back({{"participant", i + 1},
                            {"albedo", skin.albedo},
                            {"subsurface_delay_ps", skin.subsurface_delay_ps},
                            {"sticker_observations", patches},
                            {"mean_error_mm", errors.back()}});
  }
  const Summary s = Summarise(errors);
  result.rows.push_back(
      MakeFidelityRow("skin study", "mean skin depth error [mm]", kSkinSource, 7.58, 1.49, s.mean));
  result.rows.push_back(MakeFidelityRow("skin study", "sd across participants [mm]", kSkinSource,
                                        1.49, std::nullopt, s.sd));
  result.details["skin_study"] = {{"participants", participants}};
}

}  // namespace tofnav
