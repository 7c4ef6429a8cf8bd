// SPDX-License-Identifier: BSD-3-Clause
// tofnav demo: the paper's figures (Li et al., tables and text cited per key) and the printed
// tables, ours beside theirs.
#include <cmath>
#include <cstdio>
#include <string>

#include "tofnav/evaluation/demo_stages.hpp"

namespace tofnav {
namespace {

double Number(const DemoJson& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
}

// "stage: ok (3.1 s)" or "stage: FAILED (...)" and whether to print its rows.
bool Heading(const DemoJson& demo, const char* stage, const char* title) {
  const DemoJson& s = demo["stages"][stage];
  std::printf("\n== %s (%s, %.1f s)\n", title, stage, Number(s, "elapsed_s"));
  if (!s.value("ok", false)) std::printf("   FAILED: %s\n", s.value("error", "").c_str());
  return s.contains("acceptance") || s.value("ok", false);
}

void PrintAcceptance(const DemoJson& s) {
  if (!s.contains("acceptance")) return;
  for (const DemoJson& a : s["acceptance"]) {
    std::printf("   acceptance %-34s %9.3f %s %-7g %s\n", a["figure"].get<std::string>().c_str(),
                a["value"].get<double>(), a["op"].get<std::string>().c_str(),
                a["limit"].get<double>(), a["met"].get<bool>() ? "met" : "MISSED");
  }
}

// The paper's method on the same session (demo --method both): its stage, or null.
const DemoJson* PaperMethodStage(const DemoJson& demo, const char* stage) {
  if (!demo.contains("paper_method")) return nullptr;
  const DemoJson& s = demo["paper_method"]["stages"];
  return s.contains(stage) ? &s[stage] : nullptr;
}

// "   paper's method (our data): FAILED: ..." and false when the stage failed or did not run.
bool PaperMethodHeading(const DemoJson* s) {
  if (s == nullptr) return false;
  if (s->value("ok", false)) return true;
  std::printf("   paper's method, our data: FAILED: %s\n", s->value("error", "").c_str());
  return false;
}

// tofnav's figure over the paper method's (below 1: tofnav's error is smaller).
double Ratio(double ours, double theirs) { return theirs != 0.0 ? ours / theirs : std::nan(""); }

}  // namespace

DemoJson PaperFigures() {
  return {
      {"source",
       "Li et al., EVD surgical guidance with retro-reflective tool tracking and spatial "
       "reconstruction using head-mounted AR (shared/paper)"},
      {"marker_error", {{"note", "Sec. III-A.1 fits f_rf; the paper gives no bias figure"}}},
      {"depth",
       {{"before_median_mm", 7.64},
        {"before_iqr_mm", 5.36},
        {"after_median_mm", 1.08},
        {"after_iqr_mm", 1.41},
        {"reduction_percent", 85.86},
        {"photopolymer",
         {{"before_median_mm", 13.19}, {"after_median_mm", 0.89}, {"reduction_percent", 93.25}}},
        {"human_skin_before_mean_mm", 7.58},
        {"where", "Table I, head phantom H (nylon; photopolymer apart), Sec. IV-A text"}}},
      {"reconstruction",
       {{"median_mm", 0.46},
        {"iqr_mm", 0.42},
        {"photopolymer", {{"median_mm", 0.56}, {"iqr_mm", 0.61}}},
        {"sheep_head", {{"median_mm", 0.79}, {"iqr_mm", 1.06}}},
        {"where", "Table II, head phantom H (nylon; photopolymer and sheep head apart)"}}},
      {"registration", {{"note", "not reported apart: it is inside the guidance error"}}},
      {"tracking",
       {{"note", "no tracking table; Sec. II cites 0.76 mm for depth-based tool tracking"}}},
      {"guidance",
       {{"entry_median_mm", 2.09},
        {"entry_sd_mm", 0.16},
        {"angle_median_deg", 2.97},
        {"angle_sd_deg", 0.91},
        {"where", "Sec. V: mean +- sd over five surgeons' k-wire injections (hands included)"}}}};
}

void PrintDemoTables(const DemoJson& demo) {
  const DemoJson& st = demo["stages"];
  const DemoJson& paper = demo["paper"];
  std::printf("tofnav demo: head %s, seed %d, %.1f s\n", demo["head"].get<std::string>().c_str(),
              demo["seed"].get<int>(), demo["elapsed_s"].get<double>());
  if (Heading(demo, "marker_error", "f_rf: marker-centre range bias, 300-700 mm")) {
    const DemoJson& s = st["marker_error"];
    std::printf("   %d stage frames: max |bias| without f_rf %.3f mm, with f_rf %.3f mm\n",
                s.value("frames", 0), Number(s, "bias_before_max_abs_mm"),
                Number(s, "bias_after_max_abs_mm"));
    PrintAcceptance(s);
  }
  if (Heading(demo, "session", "patient session (evd-usecase)")) {
    const DemoJson& s = st["session"];
    std::printf("   %d frames (%.1f s of recording)\n", s.value("frames", 0),
                Number(s, "recording_duration_s"));
  }
  if (Heading(demo, "depth", "depth error [mm] before/after correction (Table I)")) {
    const DemoJson& s = st["depth"];
    const DemoJson& p = paper["depth"];
    if (s.contains("model")) {
      std::printf("   model %s: C1 %.3f mm, C2 %.5f, C3 %.3f mm/rad, C4 %.3f mm\n",
                  s["model"]["name"].get<std::string>().c_str(), Number(s["model"], "C1_mm"),
                  Number(s["model"], "C2"), Number(s["model"], "C3_mm_per_rad"),
                  Number(s["model"], "C4_mm"));
      const DemoJson& cyclic = s["model"].value("cyclic_error", DemoJson::object());
      if (Number(cyclic, "amplitude_mm") > 0.0) {
        std::printf("   sensor's cyclic error fitted: %.3f mm at period %.1f mm, phase %.3f rad\n",
                    Number(cyclic, "amplitude_mm"), Number(cyclic, "period_mm"),
                    Number(cyclic, "phase_rad"));
      }
    }
    if (s.contains("stability")) {
      std::printf(
          "   stability: C1 moves by at most %.3f mm when a tenth of the frames is left out "
          "(%zu subsets; issue 40's limit 0.1 mm), the head's corrected median by %.3f mm\n",
          Number(s["stability"], "max_C1_change_mm"), s["stability"]["runs"].size(),
          Number(s["stability"], "max_head_after_median_change_mm"));
      if (s["stability"].contains("consensus")) {
        const DemoJson& c = s["stability"]["consensus"];
        std::printf(
            "   consensus: the medoid of the %zu runs (%s); with one run left out it moves "
            "C1 by at most %.3f mm, the head's median by %.3f mm\n",
            s["stability"]["runs"].size() + 1, c["kept"].get<std::string>().c_str(),
            Number(c, "max_C1_change_mm"), Number(c, "max_head_after_median_change_mm"));
        if (c.contains("mean")) {
          const DemoJson& m = c["mean"];
          std::printf(
              "   the runs' mean (docs/correction.md 2.16; %s): with one run left out it moves C1 "
              "by at most %.3f mm, the head's median by %.3f mm\n",
              m.value("kept", false) ? "kept" : "reported, not kept", Number(m, "max_C1_change_mm"),
              Number(m, "max_head_after_median_change_mm"));
        }
      }
    }
    std::printf("   %-22s %9s %8s %6s %8s %6s %9s\n", "object", "pixels", "before", "IQR", "after",
                "IQR", "reduction");
    for (const DemoJson& o : s.value("objects", DemoJson::array())) {
      const bool target = o.value("target", false);
      std::printf("   %-22s %9d %8.2f %6.2f %8.2f %6.2f ", o["name"].get<std::string>().c_str(),
                  o["pixels"].get<int>(), Number(o, "before_median_mm"), Number(o, "before_iqr_mm"),
                  Number(o, "after_median_mm"), Number(o, "after_iqr_mm"));
      // The head model on another material is shown for reference: worse is expected there.
      if (target) {
        std::printf("%8.1f%%  <- head\n", Number(o, "reduction_percent"));
      } else {
        std::printf("     (not the head: model not meant for it)\n");
      }
    }
    std::printf(
        "   %-22s %9s %8.2f %6.2f %8.2f %6.2f %8.1f%%  (nylon H; photopolymer %.2f -> "
        "%.2f, %.1f%%)\n",
        "paper, head phantom", "", Number(p, "before_median_mm"), Number(p, "before_iqr_mm"),
        Number(p, "after_median_mm"), Number(p, "after_iqr_mm"), Number(p, "reduction_percent"),
        Number(p["photopolymer"], "before_median_mm"), Number(p["photopolymer"], "after_median_mm"),
        Number(p["photopolymer"], "reduction_percent"));
    if (const DemoJson* m = PaperMethodStage(demo, "depth"); PaperMethodHeading(m)) {
      for (const DemoJson& o : m->value("objects", DemoJson::array())) {
        if (!o.value("target", false)) continue;
        double ours = std::nan("");
        for (const DemoJson& t : s.value("objects", DemoJson::array()))
          if (t.value("target", false)) ours = Number(t, "after_median_mm");
        std::printf(
            "   %-22s %9s %8.2f %6.2f %8.2f %6.2f %8.1f%%  (C1 %.3f mm, C2 %.5f, C3 %.3f mm/rad; "
            "|after| tofnav / paper's method %.2f)\n",
            "paper's method, ours", "", Number(o, "before_median_mm"), Number(o, "before_iqr_mm"),
            Number(o, "after_median_mm"), Number(o, "after_iqr_mm"), Number(o, "reduction_percent"),
            Number((*m)["model"], "C1_mm"), Number((*m)["model"], "C2"),
            Number((*m)["model"], "C3_mm_per_rad"),
            Ratio(std::abs(ours), std::abs(Number(o, "after_median_mm"))));
      }
    }
    PrintAcceptance(s);
  }
  if (Heading(demo, "reconstruction", "reconstruction error [mm] vs the true skin (Table II)")) {
    const DemoJson& s = st["reconstruction"];
    const DemoJson& p = paper["reconstruction"];
    std::printf("   ours: head median %.3f, IQR %.3f, p95 %.3f (%d frames fused, %.1f mm voxels)\n",
                Number(s, "median_mm"), Number(s, "iqr_mm"), Number(s, "p95_mm"),
                s.value("frames_fused", 0), Number(s, "voxel_mm"));
    std::printf(
        "   paper: nylon head %.2f (IQR %.2f), photopolymer %.2f (%.2f), sheep %.2f (%.2f)\n",
        Number(p, "median_mm"), Number(p, "iqr_mm"), Number(p["photopolymer"], "median_mm"),
        Number(p["photopolymer"], "iqr_mm"), Number(p["sheep_head"], "median_mm"),
        Number(p["sheep_head"], "iqr_mm"));
    if (const DemoJson* m = PaperMethodStage(demo, "reconstruction"); PaperMethodHeading(m)) {
      std::printf(
          "   paper's method, our data: head median %.3f, IQR %.3f, p95 %.3f, %.2f %% beyond 3 mm "
          "(%d frames fused; median tofnav / paper's method %.2f)\n",
          Number(*m, "median_mm"), Number(*m, "iqr_mm"), Number(*m, "p95_mm"),
          Number(*m, "beyond_3mm_percent"), m->value("frames_fused", 0),
          Ratio(Number(s, "median_mm"), Number(*m, "median_mm")));
    }
    PrintAcceptance(s);
  }
  if (Heading(demo, "registration", "registration of the CT skin (true TRE at the targets)")) {
    const DemoJson& s = st["registration"];
    std::printf(
        "   %s: RMSE %.3f mm, inliers %.2f; TRE mean %.3f max %.3f mm; rotation %.3f deg, "
        "translation %.3f mm\n",
        s.value("accepted", false) ? "accepted" : "REFUSED", Number(s, "rmse_mm"),
        Number(s, "inlier_fraction"), Number(s, "tre_mm"), Number(s, "tre_max_mm"),
        Number(s, "rotation_error_deg"), Number(s, "translation_error_mm"));
    if (const DemoJson* m = PaperMethodStage(demo, "registration"); PaperMethodHeading(m)) {
      std::printf(
          "   paper's method, our data: ICP from a hand placement %.2f mm off at the targets: "
          "RMSE %.3f mm; TRE mean %.3f max %.3f mm; rotation %.3f deg (TRE tofnav / paper's "
          "method %.2f)\n",
          Number(*m, "start_tre_mm"), Number(*m, "rmse_mm"), Number(*m, "tre_mm"),
          Number(*m, "tre_max_mm"), Number(*m, "rotation_error_deg"),
          Ratio(Number(s, "tre_mm"), Number(*m, "tre_mm")));
    }
    PrintAcceptance(s);
  }
  if (Heading(demo, "tracking", "tool tracking with f_rf")) {
    const DemoJson& s = st["tracking"];
    std::printf("   %-16s %6s %8s %21s %21s %6s\n", "tool", "frames", "tracked", "raw RMS mm / deg",
                "filtered mm / deg", "wrong");
    for (const DemoJson& t : s.value("tools", DemoJson::array())) {
      std::printf("   %-16s %6d %7.1f%% %10.3f / %8.3f %10.3f / %8.3f %6d\n",
                  t["name"].get<std::string>().c_str(), t["frames"].get<int>(),
                  Number(t, "tracked_percent"), Number(t, "position_rms_mm"),
                  Number(t, "rotation_rms_deg"), Number(t, "filtered_position_rms_mm"),
                  Number(t, "filtered_rotation_rms_deg"), t["wrong_identities"].get<int>());
    }
    if (const DemoJson* m = PaperMethodStage(demo, "tracking"); PaperMethodHeading(m)) {
      std::printf("   paper's method, our data (no pose filter: its output is the raw pose):\n");
      for (const DemoJson& t : m->value("tools", DemoJson::array())) {
        std::printf("   %-16s %6d %7.1f%% %10.3f / %8.3f %10s   %8s %6d\n",
                    t["name"].get<std::string>().c_str(), t["frames"].get<int>(),
                    Number(t, "tracked_percent"), Number(t, "position_rms_mm"),
                    Number(t, "rotation_rms_deg"), "", "", t["wrong_identities"].get<int>());
      }
    }
    std::printf("   paper: %s\n", paper["tracking"]["note"].get<std::string>().c_str());
    PrintAcceptance(s);
  }
  if (Heading(demo, "guidance", "guidance: placed plan vs truth, all trajectories")) {
    const DemoJson& s = st["guidance"];
    const DemoJson& p = paper["guidance"];
    std::printf(
        "   ours: entry median %.3f mm (p95 %.3f), angle median %.3f deg (p95 %.3f), %d "
        "placed frames\n",
        Number(s, "entry_median_mm"), Number(s, "entry_p95_mm"), Number(s, "angle_median_deg"),
        Number(s, "angle_p95_deg"), s.value("placed_frames", 0));
    if (const auto i = s.find("instrument"); i != s.end() && i->contains("error")) {
      std::printf("   instrument beside the headframe: not judged (%s)\n",
                  (*i)["error"].get<std::string>().c_str());
    } else if (i != s.end() && i->is_object()) {
      const DemoJson& t = *i;
      std::printf(
          "   instrument beside the headframe: shown in %d frames, %d on another tool's markers; "
          "tip error median %.3f mm, max %.3f\n",
          t.value("shown_frames", 0), t.value("wrong_identities", 0),
          Number(t, "tip_error_median_mm"), Number(t, "tip_error_max_mm"));
    }
    std::printf(
        "   paper: entry %.2f +- %.2f mm, angle %.2f +- %.2f deg (surgeons' hands "
        "included)\n",
        Number(p, "entry_median_mm"), Number(p, "entry_sd_mm"), Number(p, "angle_median_deg"),
        Number(p, "angle_sd_deg"));
    if (const DemoJson* m = PaperMethodStage(demo, "guidance"); PaperMethodHeading(m)) {
      std::printf(
          "   paper's method, our data: entry median %.3f mm (p95 %.3f), angle median %.3f deg "
          "(p95 %.3f); tofnav / paper's method %.2f and %.2f\n",
          Number(*m, "entry_median_mm"), Number(*m, "entry_p95_mm"), Number(*m, "angle_median_deg"),
          Number(*m, "angle_p95_deg"),
          Ratio(Number(s, "entry_median_mm"), Number(*m, "entry_median_mm")),
          Ratio(Number(s, "angle_median_deg"), Number(*m, "angle_median_deg")));
    }
    PrintAcceptance(s);
  }
  // Where the run spent its time (also demo.json: stages.<name>.elapsed_s and elapsed_s).
  const double total_s = demo["elapsed_s"].get<double>();
  double stages_s = 0.0;
  std::printf("\n== time: %.1f s in all:", total_s);
  for (const auto& [name, stage] : st.items()) {
    if (!stage.contains("elapsed_s")) continue;
    stages_s += Number(stage, "elapsed_s");
    std::printf(" %s %.1f s,", name.c_str(), Number(stage, "elapsed_s"));
  }
  if (demo.contains("paper_method")) {
    double paper_s = 0.0;
    for (const auto& [name, stage] : demo["paper_method"]["stages"].items())
      paper_s += Number(stage, "elapsed_s");
    stages_s += paper_s;
    std::printf(" the paper's method %.1f s,", paper_s);
  }
  std::printf(" the rest (the head, the report) %.1f s\n", total_s - stages_s);
}

}  // namespace tofnav
