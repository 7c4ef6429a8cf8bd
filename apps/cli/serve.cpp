// SPDX-License-Identifier: BSD-3-Clause
// `tofnav serve`: a recording served like a HoloLens 2 running hl2ss, with injected faults, to
// rehearse a live session (navigate, 3D Slicer, headset display) and to test it.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "commands.hpp"
#include "config_json.hpp"
#include "stop_signal.hpp"
#include "tofnav/stream/hl2ss_replay_server.hpp"

namespace tofnav {

int RunServe(int argc, char** argv) {
  CLI::App app{
      "Serve an hl2ss AHAT recording like the headset does (port 3804), optionally with "
      "faults: dropped, reset, stalled or truncated streams and server restarts",
      "tofnav serve"};
  AddConfigOptions(app);
  std::filesystem::path recording, calibration;
  Hl2ssReplayOptions options{.port = 3804, .loop = true};
  std::string faults;
  double duration_s = 0.0;
  bool once = false, fast = false, quiet = false, json = false;
  app.add_option("recording", recording, "hl2ss AHAT recording (.bin)")->required();
  app.add_option("--calibration", calibration,
                 "hl2ss calibration folder (unset: 'calibration' beside the recording)");
  app.add_option("--port", options.port, "port to listen on (hl2ss AHAT: 3804)");
  app.add_option("--bind", options.bind_address, "address to listen on (0.0.0.0: every interface)");
  app.add_option("--faults", faults,
                 "comma-separated faults: drop, reset, truncate, stall[:2s], restart[:3s], each "
                 "with :every=20s, :at=5s or :after=PACKETS, else drawn at random");
  app.add_option("--fault-interval-s", options.faults.mean_interval_s,
                 "mean time between faults drawn at random [s]");
  app.add_option("--seed", options.faults.seed, "seed of the random faults");
  app.add_flag("--once", once, "each connection plays the recording once from its start");
  app.add_flag("--fast", fast, "send as fast as the client reads (else the recorded pace)");
  app.add_option("--duration-s", duration_s, "stop after this wall time [s] (0: on Ctrl-C)");
  app.add_flag("-q,--quiet", quiet, "no event lines");
  app.add_flag("--json", json, "print the counts as JSON at the end");
  TOFNAV_PARSE(app, argc, argv);
  if (calibration.empty()) calibration = recording.parent_path() / "calibration";
  if (!faults.empty()) options.faults.faults = ParseReplayFaults(faults);
  options.loop = !once;
  options.realtime = !fast;
  options.on_event = [quiet](const ReplayEvent& e) {
    if (!quiet) std::fprintf(stderr, "tofnav serve: [%9.3f s] %s\n", e.elapsed_s, e.text.c_str());
  };

  StopOnSignal signals;
  const Hl2ssReplayServer server(recording, calibration, options);
  const auto started = std::chrono::steady_clock::now();
  const double unix_s =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::fprintf(stderr, "tofnav serve: hl2ss://%s:%d serving %s, %zu faults planned; Ctrl-C stops\n",
               options.bind_address.c_str(), server.port(), recording.string().c_str(),
               options.faults.faults.size());
  if (options.loop && options.realtime) {  // lets a receiver tell how old a pose is
    std::fprintf(stderr, "tofnav serve: clock: frame time %.6f s was due at unix time %.6f s\n",
                 server.first_timestamp_s(), unix_s);
  }
  while (!signals.stop()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - started;
    if (duration_s > 0.0 && elapsed.count() > duration_s) break;
  }
  const Hl2ssReplayStats s = server.stats();
  if (json) {
    std::cout << WithOptions(nlohmann::ordered_json{{"connections", s.connections},
                                                    {"calibrations_sent", s.calibrations_sent},
                                                    {"streams", s.streams},
                                                    {"refused", s.refused},
                                                    {"packets_sent", s.packets_sent},
                                                    {"faults", s.faults}},
                             app)
                     .dump(2)
              << "\n";
  } else if (!quiet) {
    std::cout << "served " << s.streams << " streams, " << s.packets_sent << " packets, "
              << s.faults << " faults injected\n";
  }
  return EXIT_SUCCESS;
}

}  // namespace tofnav
