// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate suite: the robustness suite (docs/suite.md). Each case is simulated and run
// through the whole pipeline as a user would; one row of truth-checked figures per case.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <optional>
#include <set>
#include <system_error>

#include "config_json.hpp"
#include "consensus_option.hpp"
#include "evaluate.hpp"
#include "method_option.hpp"
#include "profile_option.hpp"
#include "suite_summary.hpp"
#include "tofnav/evaluation/demo_stages.hpp"
#include "tofnav/evaluation/suite_case.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/report/suite_report.hpp"

namespace tofnav {
namespace {

// A built-in suite name ("default", "smoke") or a path.
std::filesystem::path SuitePath(const std::string& name_or_path) {
  const std::filesystem::path builtin =
      std::filesystem::path(TOFNAV_SUITES_DIR) / (name_or_path + ".json");
  if (name_or_path.find('/') == std::string::npos && !name_or_path.ends_with(".json") &&
      std::filesystem::exists(builtin)) {
    return builtin;
  }
  return name_or_path;
}

std::size_t RunsToMake(const SuiteFile& suite, const std::set<std::string>& wanted,
                       std::size_t seeds) {
  const auto cases = static_cast<std::size_t>(
      std::count_if(suite.cases.begin(), suite.cases.end(),
                    [&](const SuiteCase& c) { return wanted.empty() || wanted.count(c.name); }));
  return cases * seeds;
}

// A run keeps its session in its folder: about 120 MB a case at the default suite's scale, 30 MB
// without the true range images (measured on the judged sets of session 58, whose disk filled).
// Warns, does not refuse: the figure is an estimate and a case may be smaller.
void WarnIfTheDiskIsSmall(const std::filesystem::path& out, std::size_t runs, bool drop) {
  constexpr std::uintmax_t kRunBytes = 120u << 20, kRunBytesWithoutRanges = 30u << 20;
  std::error_code error;
  const std::filesystem::space_info space = std::filesystem::space(out, error);
  const std::uintmax_t need = runs * (drop ? kRunBytesWithoutRanges : kRunBytes);
  if (error || space.available >= need) return;
  std::fprintf(stderr,
               "tofnav evaluate suite: warning: %zu run(s) need about %.0f MB in %s, %.0f MB "
               "free%s\n",
               runs, static_cast<double>(need) / 1e6, out.string().c_str(),
               static_cast<double>(space.available) / 1e6,
               drop ? "" : " (--drop-truth-ranges keeps about a quarter)");
}

int RunEvaluateSuite(int argc, char** argv) {
  CLI::App app{
      "The robustness suite: simulates every case of a suite file (scenario variations: heads, "
      "tools, occluders, surroundings, motion, drops, jitter, devices) and runs the whole "
      "pipeline on it as a user would, one row of figures against the truth per case "
      "(docs/suite.md)",
      "tofnav evaluate suite"};
  AddConfigOptions(app);
  std::string suite_name;
  std::filesystem::path out = "tofnav-suite";
  std::vector<std::string> only;
  std::optional<double> frames_scale;  // unset: the suite's
  bool json = false, quiet = false;
  std::size_t seeds = 1;
  int stability_subsets = 0;
  std::uint64_t seed_offset = 0;
  std::vector<std::string> stages;
  app.add_option("suite", suite_name, "suite file, or a built-in: default, smoke")->required();
  app.add_option("--out", out, "output folder: one folder per case, suite.json, suite.html");
  app.add_option("--only", only, "run only these cases (repeatable)");
  app.add_option("--frames-scale", frames_scale, "override the suite's frame scale")
      ->check(CLI::Range(0.05, 20.0));
  app.add_option("--seeds", seeds,
                 "run each case at this many seeds (its seed + offset + 0 .. K-1) and report the "
                 "spread: per case and over the suite, median and worst, runs meeting every line")
      ->check(CLI::Range(1, 1000));
  app.add_option("--seed-offset", seed_offset,
                 "added to every case's seed: a seed set nobody has looked at (e.g. the date)");
  app.add_option("--stability", stability_subsets,
                 "per case, identify again N times (0-10) without another tenth of the frames: "
                 "the largest C1 and head-median changes (docs/correction.md 2.4)")
      ->check(CLI::Range(0, 10));
  ConsensusFlags consensus;
  AddConsensusOptions(app, consensus);
  app.add_option("--stages", stages,
                 "run only these stages and those they need (marker_error, session, depth, "
                 "reconstruction, registration, tracking, guidance; e.g. tracking: 20 s a run); "
                 "the rows' acceptance then has those stages' lines");
  bool stage_per_case = false;
  app.add_flag("--stage-per-case", stage_per_case,
               "each case records its own f_rf stage (400 frames, its seed), as before session "
               "56 and as a suite file's \"stage\": \"per_case\" asks; default: one whole "
               "stage per device and seed, shared by the cases (docs/suite.md)");
  bool drop_truth_ranges = false;
  app.add_flag("--drop-truth-ranges", drop_truth_ranges,
               "delete each case's session/truth_range_f32.bin (the per-pixel true ranges, about "
               "90 MB of a case's 120) once its row is made: for long runs (--seeds) on a small "
               "disk; the row and every other file stay");
  app.add_flag("--json", json, "print suite.json to stdout (nothing else on stdout)");
  app.add_flag("-q,--quiet", quiet, "no per-case progress lines on stderr");
  std::string profile = "raw";
  std::optional<std::uint32_t> bitrate_bps;
  AddProfileOptions(app, profile, bitrate_bps);
  SuiteRunOptions run_options;
  AddMethodOption(app, run_options.method);
  TOFNAV_PARSE(app, argc, argv);
  if (!CheckConsensusOptions(consensus, stability_subsets, "tofnav evaluate suite"))
    return EXIT_FAILURE;
  run_options.consensus = consensus.consensus;
  run_options.consensus_mean = !consensus.medoid;
  const Hl2ssStreamProfile stream_profile = *ParseHl2ssStreamProfile(profile);
  try {
    run_options.stages = DemoStagesWithPrerequisites(stages);
  } catch (const std::invalid_argument& e) {
    std::cerr << "tofnav evaluate suite: --stages: " << e.what() << "\n";
    return EXIT_FAILURE;
  }
  const std::filesystem::path path = SuitePath(suite_name);
  const SuiteFile suite = ReadSuiteFile(path);
  const double scale = frames_scale.value_or(suite.frames_scale);
  const std::set<std::string> wanted(only.begin(), only.end());
  for (const std::string& name : wanted) {
    if (std::none_of(suite.cases.begin(), suite.cases.end(),
                     [&](const SuiteCase& c) { return c.name == name; })) {
      std::cerr << "tofnav evaluate suite: " << path.string() << " has no case '" << name << "'\n";
      return EXIT_FAILURE;
    }
  }
  std::filesystem::create_directories(out);
  WarnIfTheDiskIsSmall(out, RunsToMake(suite, wanted, seeds), drop_truth_ranges);
  const auto start = std::chrono::steady_clock::now();
  if (!json) {
    std::printf("%-24s %11s %6s %6s %6s %6s  %-26s %6s %12s %6s\n", "case", "track mm/deg", "depth",
                "recon", ">3mm%", "outl", "registration", "TRE", "entry/angle", "wall");
  }
  std::vector<SuiteJson> rows;
  std::size_t index = 0;
  for (const SuiteCase& c : suite.cases) {
    if (!wanted.empty() && !wanted.count(c.name)) continue;
    ++index;
    for (std::size_t k = 0; k < seeds; ++k) {
      SuiteCase run = c;
      run.seed = c.seed + seed_offset + k;
      const bool several = seeds > 1 || seed_offset != 0;  // one folder and label per seed
      const std::string label = several ? c.name + "@" + std::to_string(run.seed) : c.name;
      if (!quiet) std::cerr << "suite: " << label << " (" << index << ") ..." << std::endl;
      const std::filesystem::path dir =
          several ? out / c.name / ("seed" + std::to_string(run.seed)) : out / c.name;
      run_options.frames_scale = scale;
      run_options.stream_profile = stream_profile;
      run_options.bitrate_bps = bitrate_bps;
      run_options.stability_subsets = stability_subsets;
      if (suite.stage_per_device && !stage_per_case) {
        run_options.stage_folder = out / "stages";
        run_options.stage_seed = seed_offset + k + 1;
      }
      SuiteJson row = RunSuiteCase(run, dir, run_options);
      if (drop_truth_ranges) {
        std::error_code ignored;  // a case that failed before writing it has none
        std::filesystem::remove(dir / "session" / "truth_range_f32.bin", ignored);
      }
      row["name"] = label;
      row["case"] = c.name;
      row["seed"] = run.seed;
      rows.push_back(std::move(row));
      if (!json) {
        PrintRow(rows.back());
        std::fflush(stdout);
      }
    }
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  SuiteJson result{{"format", "tofnav-suite-result"},
                   {"name", suite.name},
                   {"suite_file", path.string()},
                   {"frames_scale", scale},
                   {"stream_profile", Hl2ssStreamProfileName(stream_profile)},
                   {"elapsed_s", elapsed_s},
                   {"seeds_per_case", seeds},
                   {"seed_offset", seed_offset},
                   {"summary", SuiteSummary(rows)}};
  if (seeds > 1) result["spread"] = SpreadOverSeeds(rows);
  result["rows"] = rows;
  result["options"] = EffectiveOptions(app);
  WriteFileAtomically(out / "suite.json", result.dump(2) + "\n");
  WriteSuiteHtml(out / "suite.json", out / "suite.html");
  if (json) {
    std::cout << result.dump(2) << "\n";
  } else {
    if (result.contains("spread")) PrintSpread(result["spread"], seeds);
    std::cout << "\nsummary: " << result["summary"].dump() << "\n"
              << "suite.json and suite.html in " << out.string() << " (" << elapsed_s << " s)\n";
  }
  const bool all_ran = std::all_of(rows.begin(), rows.end(), [](const SuiteJson& r) {
    // A refused registration is a result, not a failure to run.
    return r.at("ok").get<bool>() ||
           r.at("error").get<std::string>().starts_with("registration: registration refused");
  });
  return all_ran ? EXIT_SUCCESS : EXIT_FAILURE;
}

[[maybe_unused]] const bool kSuiteRegistered = RegisterEvaluator(
    {"suite", "the robustness suite: simulate and run every case of a suite file (docs/suite.md)",
     RunEvaluateSuite});

}  // namespace
}  // namespace tofnav
