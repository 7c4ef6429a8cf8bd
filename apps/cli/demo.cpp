// SPDX-License-Identifier: BSD-3-Clause
// tofnav demo: the paper end to end on simulated sessions of the embedded head, every artefact
// and DIR/demo.json (docs/demo.md, the contract: DEMO_SCHEMA in docs/demo.md).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "config_json.hpp"
#include "consensus_option.hpp"
#include "profile_option.hpp"
#include "progress.hpp"
#include "tofnav/evaluation/demo_stages.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/report/report.hpp"
#include "tofnav/sim/multipath.hpp"

namespace tofnav {
namespace {

constexpr const char* kCraniumCt = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";

}  // namespace

int RunDemo(int argc, char** argv) {
  CLI::App app{
      "The paper end to end on simulated sessions of the embedded head: f_rf, patient-specific "
      "depth model, reconstruction, registration, tracking and guidance, with the paper's "
      "figures beside ours (docs/demo.md)",
      "tofnav demo"};
  AddConfigOptions(app);
  std::filesystem::path out = "tofnav-demo";
  std::string head;
  double frames_scale = 1.0;
  std::uint64_t seed = 1;
  bool json = false, quiet = false;
  app.add_option("--out", out, "output folder (created)");
  app.add_option("--head", head,
                 std::string("patient head: phantom, mesh:<skin.ply> or ct:<volume> (unset: ct:") +
                     kCraniumCt + " when installed, else phantom)");
  app.add_option("--frames-scale", frames_scale,
                 "scale every stage's frame count (1: 160 stage + 600 session frames; 3+: closer "
                 "to the paper's 1000-frame sessions, slower)")
      ->check(CLI::Range(0.05, 20.0));
  app.add_option("--seed", seed, "random seed of the simulations");
  const double default_multipath_gain = sim::MultipathOptions{}.gain;
  double multipath_gain = default_multipath_gain;
  app.add_option("--multipath-gain", multipath_gain,
                 "one-bounce multipath of the simulations: the simulator's calibrated default "
                 "(docs/simulator.md 10), 0 off (the friendlier conditions of the earlier "
                 "figures, docs/demo.md)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  std::string profile = "raw";
  std::optional<std::uint32_t> bitrate_bps;
  AddProfileOptions(app, profile, bitrate_bps);
  int stability_subsets = 0;
  app.add_option("--stability", stability_subsets,
                 "identify again N times (0-10), each without another tenth of the frames, and "
                 "report how far C1 moves (issue 40; about 25 s each)")
      ->check(CLI::Range(0, 10));
  ConsensusFlags consensus;
  AddConsensusOptions(app, consensus);
  std::string method = "tofnav";
  app.add_option("--method", method,
                 "tofnav, paper (the paper's method as published, docs/paper_method.md) or both "
                 "(tofnav's, then the paper's on the same session: the tables' third column; "
                 "about a minute more)")
      ->check(CLI::IsMember({"tofnav", "paper", "both"}));
  app.add_flag("--json", json, "print demo.json to stdout (nothing else on stdout)");
  app.add_flag("-q,--quiet", quiet, "no progress bars");
  TOFNAV_PARSE(app, argc, argv);
  if (!CheckConsensusOptions(consensus, stability_subsets, "tofnav demo")) return EXIT_FAILURE;

  DemoContext ctx;
  ctx.stability_subsets = stability_subsets;
  ctx.consensus = consensus.consensus;
  ctx.consensus_mean = !consensus.medoid;
  ctx.method = method == "paper" ? Method::kPaper : Method::kTofnav;
  ctx.out = out;
  ctx.seed = seed;
  ctx.quiet = quiet || json;
  ctx.stream_profile = *ParseHl2ssStreamProfile(profile);
  ctx.bitrate_bps = bitrate_bps;
  ScaleDemoFrames(ctx, frames_scale);
  if (multipath_gain != default_multipath_gain) {
    ctx.vary_stage = ctx.vary_session = [multipath_gain](sim::Scenario& s) {
      s.render.multipath.gain = multipath_gain;
    };
  }
  ctx.head = !head.empty()                         ? head
             : std::filesystem::exists(kCraniumCt) ? std::string("ct:") + kCraniumCt
                                                   : "phantom";
  std::unique_ptr<ProgressBar> bar;
  std::string bar_label;
  ctx.progress = [&](const std::string& label, std::size_t done, std::size_t total) {
    if (label != bar_label || !bar) {
      bar = std::make_unique<ProgressBar>("demo: " + label, ctx.quiet);
      bar_label = label;
    }
    bar->Update(done, total);
  };
  std::filesystem::create_directories(out);
  const auto start = std::chrono::steady_clock::now();
  DemoJson demo{{"format", "tofnav-demo"},
                {"version", 1},
                {"tofnav_version", TOFNAV_VERSION},
                {"head", ctx.head},
                {"seed", seed},
                {"frames_scale", frames_scale},
                {"multipath_gain", multipath_gain},
                {"method", method},
                {"elapsed_s", 0.0},
                {"stages", DemoJson::object()}};
  demo["stages"] = RunDemoStages(ctx, [&] {
    bar.reset();
    bar_label.clear();
  });
  bool all_ok = true;
  for (const auto& [name, stage] : demo["stages"].items())
    all_ok = all_ok && stage["ok"].get<bool>();
  if (method == "both") {  // the paper's method on the same session; its failures are figures
    demo["paper_method"] = {{"stages", RunDemoPaperMethod(ctx, [&] {
                               bar.reset();
                               bar_label.clear();
                             })}};
  }
  demo["elapsed_s"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  demo["paper"] = PaperFigures();
  demo["options"] = EffectiveOptions(app);
  WriteFileAtomically(out / "demo.json", demo.dump(2) + "\n");
  try {
    WriteHtmlReport(out, out / "report.html");
  } catch (const std::exception& e) {  // the figures are in demo.json; say why the page is not
    std::cerr << "tofnav demo: report.html not written: " << e.what() << "\n";
    all_ok = false;
  }
  if (json) {
    std::cout << demo.dump(2) << "\n";
  } else {
    PrintDemoTables(demo);
    std::cout << "\nartefacts, demo.json and report.html in " << out.string() << "\n";
  }
  return all_ok ? EXIT_SUCCESS : EXIT_FAILURE;
}

}  // namespace tofnav
