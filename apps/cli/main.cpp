// SPDX-License-Identifier: BSD-3-Clause
// tofnav command line: a table of subcommands and one try/catch.
#include <algorithm>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string_view>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "commands.hpp"

namespace {

struct Command {
  std::string_view name;
  std::string_view summary;
  int (*run)(int argc, char** argv);
};

constexpr Command kCommands[] = {
    {"demo", "the paper end to end on simulated sessions, with its figures beside ours",
     tofnav::RunDemo},
    {"info", "describe a recording, calibration, mesh or volume", tofnav::RunInfo},
    {"convert", "re-write a recording as hl2ss RAW/ZDEPTH or StreamRecorder", tofnav::RunConvert},
    {"simulate", "render a scenario into an hl2ss recording plus ground truth",
     tofnav::RunSimulate},
    {"skin", "extract the outer skin surface of a CT/MR volume as a mesh", tofnav::RunSkin},
    {"register", "register the CT skin to the reconstructed head (or to fiducials)",
     tofnav::RunRegister},
    {"track", "poses of retro-reflective tools in a recording (CSV or JSON)", tofnav::RunTrack},
    {"tool-define", "a tool's marker geometry from a recording of the tool", tofnav::RunToolDefine},
    {"pivot", "pivot calibration: an instrument's tip from a recording of it swung about a divot",
     tofnav::RunPivot},
    {"fit-marker-error", "f_rf, the retro-reflector range error, from linear-stage recordings",
     tofnav::RunFitMarkerError},
    {"identify", "identify the patient-specific depth-error model (Eq. 3-7)", tofnav::RunIdentify},
    {"correct", "apply a depth model to a recording (corrected recording or point clouds)",
     tofnav::RunCorrect},
    {"reconstruct", "fuse a recording into the head surface in the reference tool's frame",
     tofnav::RunReconstruct},
    {"evaluate", "compare results with ground truth (evaluate tracking | depth | reconstruction)",
     tofnav::RunEvaluate},
    {"navigate", "track the headframe, place the plan and stream it to 3D Slicer (OpenIGTLink)",
     tofnav::RunNavigate},
    {"verify", "check the registration before guidance: touch planned landmarks with the pointer",
     tofnav::RunVerify},
    {"serve", "serve a recording like the headset (hl2ss), with faults: rehearse a live session",
     tofnav::RunServe},
    {"report", "the evaluation report (self-contained HTML) of a tofnav demo directory",
     tofnav::RunReport},
};

// Every frame allocates its images afresh (a 512 x 512 frame and its truth are about 10 MB):
// glibc hands such blocks back to the kernel when they are freed, so the next frame's pages
// fault in and are zeroed again, a third of the simulator's time on a sparse scene. Keeping freed
// memory in the heap (up to 1 GiB above the top) makes them plain reuse; the figures do not
// change (docs/benchmarks.md "Allocation").
void KeepFreedMemory() {
#if defined(__GLIBC__)
  constexpr int kMmapThresholdBytes = 32 << 20;  // glibc's largest; larger blocks are mapped
  constexpr int kTrimThresholdBytes = 1 << 30;   // free memory kept above the heap's top
  mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes);
  mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes);
#endif
}

void PrintUsage() {
  std::cout << "usage: tofnav <subcommand> [options]   (tofnav <subcommand> --help; "
               "tofnav --version)\n\n";
  for (const Command& c : kCommands) std::cout << "  " << c.name << "\t" << c.summary << "\n";
}

}  // namespace

bool tofnav::IsCommandPath(const std::vector<std::string>& path) {
  const auto named = [&](const Command& c) { return !path.empty() && c.name == path[0]; };
  if (std::none_of(std::begin(kCommands), std::end(kCommands), named)) return false;
  return path.size() == 1 ||
         (path.size() == 2 && path[0] == "evaluate" && IsEvaluatorName(path[1]));
}

int main(int argc, char** argv) {
  KeepFreedMemory();
  if (argc == 2 && std::string_view(argv[1]) == "--version") {
    std::cout << "tofnav " << TOFNAV_VERSION << "\n";  // project(tofnav VERSION ...)
    return EXIT_SUCCESS;
  }
  if (argc < 2 || std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h") {
    PrintUsage();
    return argc < 2 ? EXIT_FAILURE : EXIT_SUCCESS;
  }
  for (const Command& c : kCommands) {
    if (c.name != argv[1]) continue;
    try {
      return c.run(argc - 1, argv + 1);
    } catch (const std::exception& e) {
      std::cerr << "tofnav " << c.name << ": error: " << e.what() << "\n";
      return EXIT_FAILURE;
    }
  }
  std::cerr << "tofnav: unknown subcommand '" << argv[1] << "'\n";
  PrintUsage();
  return EXIT_FAILURE;
}
