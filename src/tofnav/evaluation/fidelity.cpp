// SPDX-License-Identifier: BSD-3-Clause
// `tofnav evaluate fidelity`: the rows and the experiments in order.
#include "tofnav/evaluation/fidelity.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/scenario/simulate.hpp"

namespace tofnav {
namespace {

constexpr double kFidelityBandFraction = 0.25;  // the band of a figure published without a spread

}  // namespace

FidelityRow MakeFidelityRow(std::string experiment, std::string figure, std::string source,
                            double published, std::optional<double> sd, double ours) {
  FidelityRow row;
  row.experiment = std::move(experiment);
  row.figure = std::move(figure);
  row.source = std::move(source);
  row.published = published;
  row.spread_published = sd.has_value();
  const double half = sd ? *sd : kFidelityBandFraction * std::abs(published);
  row.published_low = published - half;
  row.published_high = published + half;
  row.ours = ours;
  return row;
}

void SimulateForFidelity(const FidelityOptions& options, const sim::Scenario& scenario,
                         const std::filesystem::path& dir, const std::string& label,
                         std::uint64_t seed) {
  SimulateOptions simulate;
  simulate.seed = seed;
  simulate.progress = [&](std::size_t d, std::size_t t) {
    if (options.progress) options.progress(label, d, t);
  };
  if (!options.vary) {
    RunSimulation(scenario, dir, simulate);
    return;
  }
  sim::Scenario varied = scenario;
  options.vary(varied);
  RunSimulation(varied, dir, simulate);
}

const std::vector<std::string>& FidelityExperiments() {
  static const std::vector<std::string> names = {"tape", "markers", "materials", "phantoms",
                                                 "skin"};
  return names;
}

FidelityResult RunFidelity(const FidelityOptions& options) {
  FidelityResult result;
  result.details = nlohmann::ordered_json::object();
  const auto wanted = [&](const char* name) {
    return options.only.empty() ||
           std::find(options.only.begin(), options.only.end(), name) != options.only.end();
  };
  MarkerRangeModel frf;
  if (wanted("tape") || wanted("markers") || wanted("materials") || wanted("skin")) {
    FidelityTapeStage(options, result, frf);
    if (!wanted("tape")) result.rows.clear();  // run for its f_rf only
  }
  if (wanted("markers")) FidelitySttarMarkers(options, frf, result);
  if (wanted("materials")) FidelityMaterials(options, frf, result);
  if (wanted("phantoms")) FidelityPhantoms(options, result);
  if (wanted("skin")) FidelitySkinStudy(options, frf, result);
  return result;
}

}  // namespace tofnav
