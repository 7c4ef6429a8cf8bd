// SPDX-License-Identifier: BSD-3-Clause
// The identification as a consensus of runs that each leave a tenth of the frames out, the
// medoid kept (issue 40 item 2; docs/correction.md 2.9).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/pipeline/identify.hpp"

namespace tofnav {

/// How far apart two identified models are, in millimetres of their effect: the Euclidean norm
/// of the differences of C1 (compared at a's references), C3 (mm per unit of the angle term),
/// C4, C2 times 500 mm (the middle of AHAT's range) and the cyclic error's in-phase and
/// quadrature amplitudes (docs/correction.md 2.9).
double ModelDistanceMm(const DepthErrorModel& a, const DepthErrorModel& b);

/// The index of the medoid of `models`: the one with the least sum of ModelDistanceMm to the
/// others; ties go to the lowest index (the full run, first). Throws std::invalid_argument when
/// `models` is empty.
std::size_t MedoidIndex(const std::vector<DepthErrorModel>& models);

/// The medoid's own stability, as cheap as its runs: each subset run (never the full one) left out
/// of the consensus in turn, the medoid of the rest, and the largest change of its C1 (at the
/// medoid's references) from the medoid of all.
struct ConsensusJackknife {
  double max_c1_change_mm = 0.0;
  std::vector<std::size_t> kept_without_run;  // per subset run k: the medoid without run k + 1
};
ConsensusJackknife JackknifeMedoid(const std::vector<DepthErrorModel>& models);

/// The consensus's soft centre (docs/correction.md 2.16): a Gaussian-weighted mean of the models,
/// each re-expressed at the medoid's references, in the coordinates ModelDistanceMm measures
/// (C1, C2 x 500 mm, C3, C4 and the cyclic error's two quadrature amplitudes), iterated from the
/// medoid to the nearest mode (mean shift) with weights exp(-d^2 / (2 s^2)), d a model's distance
/// from the centre and s = kConsensusScaleMm. Runs of one minimum scatter by tenths of a
/// millimetre and count almost equally; a nearby minimum 4 mm away counts e^-8 as much. Unlike
/// the medoid, which jumps from one run to another when a run is left out, the mean moves by about
/// a run's offset over the number of runs. The form, references, multipath options and report are
/// the medoid's; the cyclic error is averaged only when every run has the medoid's period (else
/// the medoid's). Throws std::invalid_argument when `models` is empty.
inline constexpr double kConsensusScaleMm = 1.0;
DepthErrorModel ConsensusMean(const std::vector<DepthErrorModel>& models);

/// The mean's own stability: each subset run (never the full one) left out in turn, the
/// ConsensusMean of the rest (one model per subset run, in order), and the largest change of its
/// C1 (at the mean of all's references) from the mean of all.
struct ConsensusMeanJackknife {
  double max_c1_change_mm = 0.0;
  std::vector<DepthErrorModel> without_run;  // per subset run k: the mean without run k + 1
};
ConsensusMeanJackknife JackknifeMean(const std::vector<DepthErrorModel>& models);

/// Which runs placed the skin first in another basin than the best one: `best` is the run whose
/// first placement kept the largest inlier fraction (the figure each run chose its own by; the
/// first on a tie, none without placements), `elsewhere` the runs whose placement differs from it
/// (PlacementsDiffer), in order. Throws std::invalid_argument on different lengths.
struct BasinCheck {
  std::optional<std::size_t> best;
  std::vector<std::size_t> elsewhere;
};
BasinCheck CheckBasins(const std::vector<std::optional<MergedPlacement>>& placements,
                       const std::vector<double>& inlier_fractions);

/// Which runs ended in another minimum than the run of least cost: `best` is the run with the
/// least final Eq. (7) cost per frame used (the figure every run minimised; the first on a tie),
/// `elsewhere` the runs whose model lies more than kOtherMinimumMm from it (ModelDistanceMm), in
/// order. Runs of one minimum agree within about a millimetre, two nearby minima that one skin's
/// data tilt between lie about 4 mm apart (docs/correction.md 2.9; the medoid decides there),
/// and the wrong minimum of dark, far skin lies 18 mm away, 11 mm below in C1 (2.14). Throws
/// std::invalid_argument when `models` is empty.
struct MinimumCheck {
  std::size_t best = 0;
  std::vector<std::size_t> elsewhere;
};
inline constexpr double kOtherMinimumMm = 5.0;
MinimumCheck CheckMinima(const std::vector<DepthErrorModel>& models);

struct IdentifyConsensusResult {
  IdentifyRecordingResult full;                  // every picked frame
  std::vector<IdentifyRecordingResult> subsets;  // subset k leaves out picked frame j, j % 10 == k
  std::size_t kept = 0;                          // 0: the full run; k + 1: subset k
  /// Runs identified again with the best first placement among their candidates, because
  /// their own lay in another basin (docs/correction.md 2.13).
  std::vector<std::size_t> identified_again;
  /// Runs identified again from the least-cost run's model because theirs lay in another
  /// minimum (CheckMinima), and of them those whose new answer cost less and was kept
  /// (docs/correction.md 2.14).
  std::vector<std::size_t> restarted;
  std::vector<std::size_t> restart_kept;
  /// Run i: 0 the full one, k + 1 subset k (throws std::out_of_range beyond them).
  const IdentifyRecordingResult& Run(std::size_t i) const;
  const IdentifyRecordingResult& Kept() const { return Run(kept); }
  /// Every run's model, the full run first.
  std::vector<DepthErrorModel> Models() const;
};

/// IdentifyFromRecording on every picked frame, then on `subsets` sets that each leave a tenth of
/// them out (subset k: FrameLeaveOut{k, 10}), and the medoid kept: a session near the balance of
/// Err_C's terms lands in one of two minima depending on which frames it saw, and the medoid
/// follows the answer most of them give (docs/correction.md 2.9). `subsets` in [0, 10] (throws
/// std::invalid_argument otherwise): with none the full run alone, with one the full run kept (a
/// tie) and the subset a stability check only. Every run then starts from one basin: the first
/// placement of the skin kept with the largest inlier fraction over the runs is offered to each
/// run whose own placement differs from it (PlacementsDiffer), and that run is identified again.
/// Then every run whose model lies in another minimum than the least-cost run's (CheckMinima) is
/// identified again with stage 2 started from that model (and its placement offered), and keeps
/// whichever of its two answers costs less on its own frames: which minimum a run reaches then
/// rests on the cost, not on which tenth it left out. `progress(run, runs, done, total)`, run 0
/// the full one.
IdentifyConsensusResult IdentifyWithConsensus(
    const AhatRecording& recording, const AhatCamera& camera,
    const std::optional<MarkerRangeModel>& marker_range, const SurfaceIndex* skin,
    const IdentifyRecordingOptions& options, int subsets,
    const std::function<void(int, int, std::size_t, std::size_t)>& progress = {});

}  // namespace tofnav
