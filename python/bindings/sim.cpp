// SPDX-License-Identifier: BSD-3-Clause
// The simulator: run a built-in or file scenario into a folder (RunSimulation), list built-ins.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "convert.hpp"
#include "defines.hpp"
#include "tofnav/scenario/scenario_json.hpp"
#include "tofnav/scenario/simulate.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav::python {
namespace {

Hl2ssStreamProfile ProfileFromString(const std::string& profile) {
  if (const auto parsed = ParseHl2ssStreamProfile(profile)) return *parsed;
  throw py::value_error("profile must be one of " + Hl2ssStreamProfileChoices() + ", not '" +
                        profile + "'");
}

py::dict Simulate(const std::string& scenario, const std::filesystem::path& out_dir,
                  std::optional<std::int64_t> frames, std::optional<std::uint64_t> seed,
                  const std::string& profile, bool truth_depth, bool from_json_text) {
  const SimulateOptions options{.frames = frames,
                                .seed = seed,
                                .profile = ProfileFromString(profile),
                                .truth_depth = truth_depth};
  SimulateResult result;
  {
    py::gil_scoped_release release;
    sim::Scenario loaded = from_json_text ? ParseScenarioJson(scenario, out_dir / "scenario.json")
                                          : LoadScenario(scenario);
    result = RunSimulation(std::move(loaded), out_dir, options);
  }
  py::dict out;
  out["frames"] = result.frames;
  out["dropped_slots"] = result.dropped_slots;
  out["duration_s"] = result.duration_s;
  py::list files;
  for (const std::filesystem::path& file : result.files) files.append(file.string());
  out["files"] = files;
  return out;
}

}  // namespace

void DefineSim(py::module_& m) {
  m.def("simulate", &Simulate, py::arg("scenario"), py::arg("out_dir"),
        py::arg("frames") = py::none(), py::arg("seed") = py::none(), py::arg("profile") = "raw",
        py::arg("truth_depth") = false, py::arg("json_text") = false,
        "render a scenario (built-in name or scenario file; with json_text=True the scenario "
        "JSON itself) into out_dir as `tofnav simulate` does; returns frames, dropped_slots, "
        "duration_s and files");
  m.def("builtin_scenarios", &sim::BuiltinScenarioNames);
  m.def("builtin_scenario_summary", &sim::BuiltinScenarioSummary, py::arg("name"));
}

}  // namespace tofnav::python
