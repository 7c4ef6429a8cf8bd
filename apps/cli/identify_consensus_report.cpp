// SPDX-License-Identifier: BSD-3-Clause
// tofnav identify --consensus: the runs and the one kept (docs/correction.md 2.9).
#include "identify_consensus_report.hpp"

#include <iostream>
#include <string>

namespace tofnav {

nlohmann::ordered_json ConsensusToJson(const IdentifyConsensusResult& runs, bool mean_kept) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  if (runs.subsets.empty()) return out;
  const DepthErrorModel& kept = runs.Kept().file.model;
  out["kept_run"] = runs.kept;
  out["identified_again"] = runs.identified_again;
  out["restarted_from_least_cost"] = runs.restarted;
  out["restart_kept"] = runs.restart_kept;
  out["runs"] = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i <= runs.subsets.size(); ++i) {
    const DepthErrorModel& m = runs.Run(i).file.model;
    out["runs"].push_back(
        {{"left_out", i == 0 ? std::string("none") : "k % 10 == " + std::to_string(i - 1)},
         {"c1_mm_at_kept_references",
          m.WithReferences(kept.theta_reference_rad, kept.ab_reference).c1_mm},
         {"c2", m.c2},
         {"c3_mm", m.c3_mm},
         {"c4_mm", m.c4_mm},
         {"final_cost_mm2", m.report.final_cost},
         {"distance_to_kept_mm", ModelDistanceMm(kept, m)}});
  }
  const std::vector<DepthErrorModel> models = runs.Models();
  const DepthErrorModel mean = ConsensusMean(models);
  out["mean"] = {
      {"kept", mean_kept},
      {"c1_mm_at_kept_references", mean.c1_mm},
      {"c2", mean.c2},
      {"c3_mm", mean.c3_mm},
      {"c4_mm", mean.c4_mm},
      {"distance_to_kept_mm", ModelDistanceMm(kept, mean)},
      {"max_c1_change_one_run_left_out_mm", JackknifeMean(models).max_c1_change_mm},
      {"medoid_max_c1_change_one_run_left_out_mm", JackknifeMedoid(models).max_c1_change_mm}};
  return out;
}

void PrintConsensus(const IdentifyConsensusResult& runs, bool mean_kept) {
  const nlohmann::ordered_json j = ConsensusToJson(runs, mean_kept);
  std::cout << "  consensus of " << runs.subsets.size() + 1
            << " runs (each but the first without a tenth of the frames), the "
            << (mean_kept ? "runs' mean (docs/correction.md 2.16)"
                          : "medoid (docs/correction.md 2.9)")
            << " kept:\n";
  for (std::size_t i = 0; i < j["runs"].size(); ++i) {
    const nlohmann::ordered_json& r = j["runs"][i];
    std::cout << "    " << (i == runs.kept ? "* " : "  ") << "left out "
              << r["left_out"].get<std::string>() << ": C1 "
              << r["c1_mm_at_kept_references"].get<double>() << " mm, C3 "
              << r["c3_mm"].get<double>() << ", C4 " << r["c4_mm"].get<double>() << ", cost "
              << r["final_cost_mm2"].get<double>() << " mm^2, "
              << r["distance_to_kept_mm"].get<double>() << " mm from the medoid\n";
  }
  const nlohmann::ordered_json& mean = j["mean"];
  std::cout << "    " << (mean_kept ? "* " : "  ") << "the runs' mean: C1 "
            << mean["c1_mm_at_kept_references"].get<double>() << " mm, C3 "
            << mean["c3_mm"].get<double>() << ", C4 " << mean["c4_mm"].get<double>() << ", "
            << mean["distance_to_kept_mm"].get<double>()
            << " mm from the medoid; C1 moves by at most "
            << mean["max_c1_change_one_run_left_out_mm"].get<double>()
            << " mm with one run left out (the medoid's: "
            << mean["medoid_max_c1_change_one_run_left_out_mm"].get<double>() << " mm)\n";
  if (!runs.identified_again.empty()) {
    std::cout << "    " << runs.identified_again.size()
              << " run(s) identified again from the best run's first placement of the skin (their "
                 "own lay in another basin: docs/correction.md 2.13)\n";
  }
  if (!runs.restarted.empty()) {
    std::cout << "    " << runs.restarted.size()
              << " run(s) in another minimum identified again from the least-cost run's model, "
              << runs.restart_kept.size()
              << " of them kept the new answer (docs/correction.md 2.14)\n";
  }
}

}  // namespace tofnav
