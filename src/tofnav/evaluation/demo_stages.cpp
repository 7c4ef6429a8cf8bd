// SPDX-License-Identifier: BSD-3-Clause
// The demo's driver: the frame counts of a run at a scale, the acceptance rows and the stages run
// in order (docs/demo.md).
#include "tofnav/evaluation/demo_stages.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <stdexcept>

#include "tofnav/imaging/skin.hpp"
#include "tofnav/scenario/patient_head.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {

const TriangleMesh& DemoSkin(DemoContext& ctx) {
  const std::filesystem::path ct = ctx.session_dir / "ct.nrrd";
  if (!ctx.skin || ctx.skin_of != ct) {
    ctx.skin = ExtractSkin(ReadVolume(ct)).mesh;
    ctx.skin_of = ct;
  }
  return *ctx.skin;
}

DemoJson Acceptance(const std::string& figure, double value, const std::string& op, double limit) {
  const bool met = op == "<=" ? value <= limit : value >= limit;
  return {{"figure", figure}, {"value", value}, {"op", op}, {"limit", limit}, {"met", met}};
}

void ScaleDemoFrames(DemoContext& ctx, double scale) {
  const auto scaled = [&](double n, double floor) {
    return static_cast<std::int64_t>(std::max(floor, std::round(n * scale)));
  };
  constexpr double kSessionSlots = 600.0;  // evd-usecase frames at scale 1
  // Four stage runs of at least 100 frames each, at any scale: the tape's entrance gain comes from
  // the runs' offsets against each other, and each run's offset from its frames' image-only poses.
  // At 20 frames a run the gain scattered 1.0-2.4 mm/rad over seven suite cases (the tape's is 1.85
  // on 1800 frames) and a disc tool's range with it: 0.37-0.46 mm tracking RMS where 0.16 mm had
  // been; at 100 frames a run, 1.73-1.98 over five seeds (docs/tracking.md 4).
  ctx.stage_frames = scaled(400.0, 400.0);
  ctx.session_frames = scaled(kSessionSlots, 60.0);
  // A shorter session keeps the whole headset motion (every n-th slot) rather than its first
  // seconds: identification and fusion need the views, not the frame rate (docs/suite.md).
  ctx.session_slot_stride = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(
             std::round(kSessionSlots / static_cast<double>(ctx.session_frames))));
  ctx.depth_eval_frames = static_cast<int>(scaled(24.0, 6.0));
}

namespace {

struct DemoStage {
  const char* name;
  void (*run)(DemoContext&, DemoJson&);
};
constexpr DemoStage kDemoStages[] = {{"marker_error", RunDemoMarkerError},
                                     {"session", RunDemoSession},
                                     {"depth", RunDemoDepth},
                                     {"reconstruction", RunDemoReconstruction},
                                     {"registration", RunDemoRegistration},
                                     {"tracking", RunDemoTracking},
                                     {"guidance", RunDemoGuidance}};

// The stages from `first` on, in order (a failed stage is recorded and the next ones run).
DemoJson RunStagesFrom(DemoContext& ctx, std::string_view first,
                       const std::function<void()>& after_stage) {
  DemoJson all = DemoJson::object();
  bool started = false;
  for (const DemoStage& s : kDemoStages) {
    started = started || first == s.name;
    if (!started || (!ctx.stages.empty() && !ctx.stages.count(s.name))) continue;
    DemoJson stage{{"ok", true}, {"error", ""}, {"elapsed_s", 0.0}};
    const auto stage_start = std::chrono::steady_clock::now();
    try {
      if (std::string(s.name) == "session" && !ctx.patient_head) {
        ctx.patient_head = LoadPatientHead(ctx.head);
      }
      s.run(ctx, stage);
    } catch (const std::exception& e) {
      stage["ok"] = false;
      stage["error"] = e.what();
    }
    if (after_stage) after_stage();
    stage["elapsed_s"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - stage_start).count();
    all[s.name] = stage;
    if (!ctx.quiet && ::isatty(STDERR_FILENO) == 1) {  // a line per stage on a terminal
      std::cerr << "demo: " << (ctx.method == Method::kPaper ? "paper's method, " : "") << s.name
                << (stage["ok"].get<bool>() ? " ok" : " FAILED") << " ("
                << stage["elapsed_s"].get<double>() << " s)"
                << (stage["ok"].get<bool>() ? "" : ": " + stage["error"].get<std::string>())
                << "\n";
    }
  }
  return all;
}

// The stages each stage reads the results of (DemoContext's fields).
std::vector<std::string> Prerequisites(const std::string& stage) {
  if (stage == "depth" || stage == "tracking") return {"marker_error", "session"};
  if (stage == "reconstruction") return {"depth"};
  if (stage == "registration") return {"reconstruction"};
  if (stage == "guidance") return {"registration", "tracking"};
  return {};
}

}  // namespace

std::vector<std::string> DemoStageNames() {
  std::vector<std::string> names;
  for (const DemoStage& s : kDemoStages) names.emplace_back(s.name);
  return names;
}

std::set<std::string> DemoStagesWithPrerequisites(std::span<const std::string> wanted) {
  const std::vector<std::string> known = DemoStageNames();
  std::set<std::string> stages;
  std::vector<std::string> open(wanted.begin(), wanted.end());
  while (!open.empty()) {
    const std::string stage = open.back();
    open.pop_back();
    if (std::find(known.begin(), known.end(), stage) == known.end()) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      throw std::invalid_argument("unknown stage '" + stage + "' (stages: " + list + ")");
    }
    if (!stages.insert(stage).second) continue;
    for (std::string& p : Prerequisites(stage)) open.push_back(std::move(p));
  }
  return stages;
}

DemoJson RunDemoStages(DemoContext& ctx, const std::function<void()>& after_stage) {
  return RunStagesFrom(ctx, kDemoStages[0].name, after_stage);
}

DemoJson RunDemoPaperMethod(const DemoContext& ctx, const std::function<void()>& after_stage) {
  DemoContext paper = ctx;
  paper.method = Method::kPaper;
  paper.frf = ctx.range_only_frf;  // Eq. (1) as published: the range alone
  paper.out = ctx.out / "paper_method";
  paper.stability_subsets = 0;
  paper.depth_model.reset();
  paper.surface.reset();
  paper.tool_from_image.reset();
  std::filesystem::create_directories(paper.out);
  return RunStagesFrom(paper, "depth", after_stage);
}

}  // namespace tofnav
