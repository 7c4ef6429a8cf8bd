// SPDX-License-Identifier: BSD-3-Clause
// `tofnav navigate`: recording or live hl2ss -> Navigator -> OpenIGTLink (3D Slicer), CSV, status.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "config_json.hpp"
#include "navigate_live.hpp"
#include "navigate_support.hpp"
#include "profile_option.hpp"
#include "stop_signal.hpp"
#include "supervisor.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/casefile/markups_read.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/pipeline/navigation_csv.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/stream/headset_display.hpp"
#include "tofnav/stream/hl2ss_client.hpp"
#include "tofnav/stream/live_link.hpp"
#include "tofnav/stream/navigation_messages.hpp"
#include "tofnav/stream/navigation_session.hpp"
#include "tofnav/stream/verify_messages.hpp"

namespace tofnav {
namespace {

// `tofnav navigate`, or with `verify_only` `tofnav verify`: the landmark check, then exit.
int RunNavigation(int argc, char** argv, bool verify_only) {
  CLI::App app{verify_only
                   ? "Accuracy check before guidance: touch the planned landmarks with the "
                     "tracked pointer; each landmark's error against the registration"
                   : "Intra-operative navigation: track the headframe, place the plan (Eq. 8), "
                     "stream to 3D Slicer over OpenIGTLink",
               verify_only ? "tofnav verify" : "tofnav navigate"};
  AddConfigOptions(app);
  std::string input;
  std::filesystem::path calibration, tool_path, registration, plan_path, instrument_path, out;
  std::filesystem::path marker_error_path, landmarks_path;
  LandmarkCheckOptions check_options;
  std::filesystem::path skin_path, surface_path;
  std::string trajectory, bind = "127.0.0.1", profile = "zdepth+h265", hololens;
  std::optional<std::uint32_t> bitrate_bps;
  int igtl_port = 18944;
  bool realtime = false, loop = false, quiet = false, json = false, no_igtl = false;
  bool no_supervisor = false;
  std::size_t inject_abort_after_frames = 0;
  double duration_s = 0.0;
  std::optional<double> sample_offset;
  LiveLinkOptions link;
  app.add_option("input", input,
                 "hl2ss recording (.bin), StreamRecorder folder, or hl2ss://HOST[:PORT] (3816)")
      ->required();
  app.add_option("--calibration", calibration,
                 "hl2ss calibration folder (live: Mode 2 when absent)");
  app.add_option("--tool", tool_path, "reference tool JSON (headframe)")->required();
  app.add_option("--registration", registration, "tool_from_image (.json, .tfm, .txt)")->required();
  app.add_option("--plan", plan_path, "planned trajectories (.mrk.json, .fcsv)")
      ->required(!verify_only);
  if (verify_only) {
    app.add_option("--pointer", instrument_path, "pivot-calibrated pointer (tool JSON with tip_mm)")
        ->required();
    app.add_option("--landmarks", landmarks_path,
                   "landmarks planned in the image, touched in file order (.mrk.json, .fcsv)")
        ->required();
  } else {
    app.add_option("--instrument", instrument_path, "tracked instrument JSON with tip_mm");
    app.add_option("--verify", landmarks_path,
                   "first check the registration: touch these landmarks with the instrument "
                   "(.mrk.json, .fcsv; docs/navigation.md 7)");
  }
  app.add_option("--pass-mm", check_options.pass_mm,
                 "verify: a landmark passes within this error [mm]")
      ->check(CLI::PositiveNumber);
  app.add_option("--still-s", check_options.still_time_s,
                 "verify: the tip resting this long is a touch [s]")
      ->check(CLI::PositiveNumber);
  app.add_option("--still-radius-mm", check_options.still_radius_mm,
                 "verify: ... 80 % of its positions this close to their median [mm]")
      ->check(CLI::Range(0.1, 20.0));
  app.add_option("--marker-error", marker_error_path,
                 "f_rf curve (tofnav fit-marker-error) applied to marker ranges (Eq. 2)");
  app.add_option("--trajectory", trajectory, "trajectory the instrument is guided along (name)");
  app.add_option("--skin", skin_path, "CT skin mesh in image (sent as POLYDATA SkinRas)");
  app.add_option("--surface", surface_path, "reconstructed head in tool (POLYDATA HeadSurface)");
  app.add_option("--igtl-port", igtl_port, "OpenIGTLink server port (3D Slicer connects)");
  app.add_option("--igtl-bind", bind, "address to listen on (0.0.0.0: every interface)");
  app.add_flag("--no-igtl", no_igtl, "do not start the OpenIGTLink server");
  app.add_option("--hololens", hololens,
                 "show the plan on the headset: hl2ss remote Unity scene HOST[:PORT] (3816)");
  app.add_flag("--no-supervisor", no_supervisor,
               "with --hololens: run in one process (debuggers); a crash or kill -9 then leaves "
               "the last holograms on the headset");
  app.add_option("--inject-abort-after-frames", inject_abort_after_frames)->group("");
  app.add_option("--sample-offset", sample_offset, "calibration table sample offset (0 or 0.5)");
  AddProfileOptions(app, profile, bitrate_bps);
  app.add_flag("--realtime", realtime, "replay a recording at its recorded pace");
  app.add_flag("--loop", loop, "replay a recording again and again (soak tests)");
  app.add_option("--duration-s", duration_s, "stop after this wall time [s] (0: at the end)");
  app.add_option("--stall-timeout-s", link.stall_timeout_s,
                 "live: no frame for this long is a stalled stream, reconnected [s]");
  app.add_option("--give-up-after-s", link.give_up_after_s,
                 "live: exit (status 3) after this long without frames [s] (0: never)");
  app.add_option("--out", out, "per-frame CSV (status, poses, plan, guidance)");
  app.add_flag("-q,--quiet", quiet, "no live status line");
  app.add_flag("--json", json, "print the summary as JSON");
  NavigatorOptions navigator_options;
  bool no_pose_check = false;
  app.add_flag("--no-pose-check", no_pose_check,
               "use every reference pose (no check against its recent world poses)");
  bool no_filter = false;
  app.add_flag("--no-filter", no_filter,
               "place the plan on each frame's raw reference pose (no pose filter; "
               "docs/navigation.md 1)");
  double settled_sd_deg = navigator_options.settled_rotation_sd_rad * kRadToDeg;
  app.add_option("--settled-sd-deg", settled_sd_deg,
                 "the reference is SETTLING until its filtered orientation's expected RMS error "
                 "is at most this [deg] (docs/navigation.md 1)")
      ->check(CLI::PositiveNumber);
  TOFNAV_PARSE(app, argc, argv);
  navigator_options.settled_rotation_sd_rad = settled_sd_deg * kDegToRad;
  navigator_options.check_pose_jumps = !no_pose_check;
  navigator_options.tracking.filter_enabled = !no_filter;
  HeadsetDisplayOptions headset;
  if (!hololens.empty()) std::tie(headset.host, headset.port) = ParseRemoteSceneEndpoint(hololens);
  // The headset's one-time notices (no speech, another client): one line each, as they happen.
  headset.on_notice = [](const std::string& line) {
    std::cerr << "tofnav navigate: headset: " << line << "\n";
  };
  // With a headset, the work runs in a child process that this one watches: whatever ends it,
  // the headset is cleared (docs/navigation.md 6.6). Before any thread starts.
  std::unique_ptr<SharedHeadsetRecord> left_on_headset;
  if (!hololens.empty() && !no_supervisor) {
    left_on_headset = std::make_unique<SharedHeadsetRecord>();
    SharedHeadsetRecord* record = left_on_headset.get();
    const std::optional<int> status = RunAsSupervisedWorker(
        [&](const WorkerEnd& end) { return ClearAfterWorker(end, record->Read(), headset); });
    if (status) return *status;
    headset.on_shown = [record](const HeadsetShown& shown) { record->Write(shown); };
  }

  NavigationCase c;
  c.reference = ReadToolJson(tool_path);
  c.tool_from_image = ReadToolFromImage(registration);
  if (!plan_path.empty()) c.plan = ReadTrajectories(plan_path);
  if (!instrument_path.empty()) c.instrument = ReadToolJson(instrument_path);
  if (!marker_error_path.empty()) c.marker_range = ReadMarkerRangeJson(marker_error_path).model;
  std::optional<LandmarkCheck> check;  // docs/navigation.md 7
  if (!landmarks_path.empty()) {
    if (verify_only && !c.instrument->tip_in_tool) {
      throw std::runtime_error("--pointer " + instrument_path.string() +
                               " has no pivot-calibrated tip (tip_mm): calibrate it with "
                               "tofnav pivot first");
    }
    if (!c.instrument || !c.instrument->tip_in_tool) {
      throw std::runtime_error("--verify needs --instrument with a pivot-calibrated tip (tip_mm)");
    }
    check.emplace(ReadLandmarks(landmarks_path), c.tool_from_image, *c.instrument->tip_in_tool,
                  check_options);
  }

  std::unique_ptr<FrameSource> source;
  std::optional<AhatCalibration> camera_calibration;
  const std::optional<Hl2ssEndpoint> endpoint = ParseHl2ssUri(input);
  std::optional<std::vector<std::uint8_t>> device_calibration;  // checked on every reconnect
  if (endpoint) {
    link.Check();
    if (calibration.empty()) device_calibration = DownloadHl2ssCalibrationBytes(*endpoint);
    camera_calibration = device_calibration ? DecodeHl2ssMode2(*device_calibration,
                                                               Hl2ssUri(*endpoint), sample_offset)
                                            : ReadHl2ssCalibration(calibration, sample_offset);
  } else {
    auto recording = OpenAhatRecording(input);
    camera_calibration = recording->calibration();
    if (!calibration.empty()) camera_calibration = ReadHl2ssCalibration(calibration, sample_offset);
    if (!camera_calibration)
      throw std::runtime_error("--calibration is required for hl2ss recordings");
    source =
        std::make_unique<RecordingFrameSource>(std::move(recording), ReplayOptions{realtime, loop});
  }
  Navigator navigator(AhatCamera(*camera_calibration), c, navigator_options);
  if (!trajectory.empty()) {
    int index = -1;
    for (std::size_t i = 0; i < c.plan.size(); ++i) {
      if (c.plan[i].name == trajectory) index = static_cast<int>(i);
    }
    if (index < 0) throw std::runtime_error("no trajectory named '" + trajectory + "' in the plan");
    navigator.SelectTrajectory(index);
  }
  std::unique_ptr<IgtlServer> server;
  if (!no_igtl) {
    server =
        std::make_unique<IgtlServer>(IgtlServerOptions{.bind_address = bind, .port = igtl_port});
    std::optional<TriangleMesh> skin, surface;
    if (!skin_path.empty()) skin = ReadMesh(skin_path);
    if (!surface_path.empty()) surface = ReadMesh(surface_path);
    SetNavigationGreetings(*server, navigator, skin, surface);
    if (check) {
      const NamedMessage landmarks = EncodeLandmarksGreeting(check->landmarks());
      server->SetGreeting(landmarks.device_name, landmarks.bytes);
    }
  }
  std::unique_ptr<HeadsetDisplay> display;  // docs/navigation.md, "Headset display"
  if (!hololens.empty()) display = std::make_unique<HeadsetDisplay>(c.plan, headset);
  // The check's line leads the panel (above the first landmark when there is no plan) and goes
  // to Slicer; each touch is a line on stdout.
  const auto publish_check = [&](double timestamp_s) {
    if (display) display->SetPanelNote({check->StatusLine(), check->landmarks().front().in_image});
    if (server) {
      for (NamedMessage& m : EncodeLandmarkCheck(*check, timestamp_s)) server->Publish(m.bytes);
    }
  };
  if (check) publish_check(0.0);
  std::optional<AtomicFileWriter> csv;
  if (!out.empty()) {
    csv.emplace(out);
    csv->Write(NavigationCsvHeader());
  }
  const bool status_line = !quiet && !json && ::isatty(STDERR_FILENO) != 0;
  auto last_draw = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  const auto started = std::chrono::steady_clock::now();
  std::size_t frames_seen = 0;
  NavigationState last;  // the last frame's state: NO_STREAM states continue it
  const auto on_state = [&](const NavigationState& s) {
    if (csv && s.status != NavigationStatus::kNoStream) csv->Write(NavigationCsvRow(s, c.plan));
    if (display) display->Update(s);  // a NO_STREAM state carries no pose: the holograms hide
    if (s.status != NavigationStatus::kNoStream) {
      ++frames_seen;
      last = s;
    }
    const auto now = std::chrono::steady_clock::now();
    if (status_line && now - last_draw > std::chrono::milliseconds(100)) {
      last_draw = now;
      std::string line = NavigationStatusLine(s, c.plan);
      if (server) line += " | clients " + std::to_string(server->stats().clients);
      // Rate, and time left when the run has a set duration (a stream has no frame count).
      const double elapsed_s = std::chrono::duration<double>(now - started).count();
      char rate[64];
      std::snprintf(rate, sizeof rate, " | %zu frames %.1f/s", frames_seen,
                    elapsed_s > 0.0 ? static_cast<double>(frames_seen) / elapsed_s : 0.0);
      line += rate;
      if (duration_s > 0.0) {
        std::snprintf(rate, sizeof rate, " %.0f s left", std::max(0.0, duration_s - elapsed_s));
        line += rate;
      }
      std::fprintf(stderr, "\r\033[K%s", line.substr(0, 200).c_str());
    }
  };
  StopOnSignal signals;  // Ctrl-C: stop, save the CSV and say so
  std::atomic<bool>& stop = signals.stop();
  bool timed_out = false;
  const auto on_frame = [&](const NavigationState& s) {
    on_state(s);
    if (check && !check->done()) {
      if (const std::optional<LandmarkTouch> touch = check->Add(s)) {
        if (!json) std::cout << TouchLine(*check, *touch) << std::endl;
        publish_check(s.timestamp_s);
        if (check->done() && !json) std::cout << check->StatusLine() << std::endl;
        if (check->done() && verify_only) stop = true;
      }
    }
    if (inject_abort_after_frames > 0 && frames_seen >= inject_abort_after_frames) InjectedAbort();
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - started;
    if (duration_s > 0.0 && elapsed.count() > duration_s) stop = timed_out = true;
  };
  LiveHl2ssSource* live = nullptr;
  if (endpoint) {
    // Link down: say so, one CSV row per change, NavigationStatus NO_STREAM and no transform.
    const Hl2ssStreamProfile stream_profile = *ParseHl2ssStreamProfile(profile);
    if (stream_profile.profile_z == Hl2ssDepthProfile::kSame &&
        stream_profile.profile_ab != Hl2ssVideoProfile::kRaw) {
      std::fprintf(stderr, "tofnav navigate: warning: %s\n",
                   LossyDepthWarning(stream_profile).c_str());
    }
    auto live_source =
        MakeLiveSource(*endpoint, stream_profile, bitrate_bps, link, std::move(device_calibration),
                       &stop, [&](const LinkReport& r) {
                         ReportLink(r, status_line);
                         if (r.up) return;
                         const NavigationState s = NoStreamState(last, r.down_s);
                         if (csv && r.changed) csv->Write(NavigationCsvRow(s, c.plan));
                         if (server) PublishNavigationState(*server, s, navigator);
                         on_frame(s);
                       });
    live = live_source.get();
    source = std::move(live_source);
  }
  const NavigationSessionStats stats =
      RunNavigationSession(*source, navigator, server.get(), on_frame, &stop);
  if (status_line) std::fprintf(stderr, "\n");
  if (display) display->Close();  // removes the holograms
  if (csv) csv->Commit();
  const std::string reason = signals.signalled() ? signals.Reason()
                             : timed_out         ? "stopped after --duration-s"
                             : live != nullptr   ? live->failure()
                                                 : "";
  if (!reason.empty() && (live != nullptr || signals.signalled())) {
    std::fprintf(stderr, "tofnav navigate: %s\n", reason.c_str());
  }
  nlohmann::ordered_json summary{{"source", source->description()},
                                 {"frames", stats.frames},
                                 {"tracking", stats.tracking},
                                 {"holding", stats.holding},
                                 {"reference_lost", stats.reference_lost},
                                 {"no_world_pose", stats.no_world_pose},
                                 {"duration_s", stats.last_timestamp_s - stats.first_timestamp_s},
                                 {"dropped", DroppedJson(stats)},
                                 {"low_rate_frames", stats.low_rate_frames}};
  if (stats.first_low_rate_s) {
    summary["first_low_rate_after_s"] = *stats.first_low_rate_s - stats.first_timestamp_s;
  }
  summary["settling_frames"] = stats.settling_frames;
  if (stats.settled_s) summary["settled_after_s"] = *stats.settled_s - stats.first_timestamp_s;
  if (server) {
    const IgtlServerStats s = server->stats();
    summary["igtl"] = {{"port", server->port()},
                       {"connections", s.connections},
                       {"messages_sent", s.messages_sent},
                       {"messages_dropped", s.messages_dropped},
                       {"frames_received", s.frames_received},
                       {"crc_errors", s.crc_errors}};
  }
  if (live != nullptr) summary["link"] = LinkSummary(live->stats());
  if (check) summary["verify"] = LandmarkCheckJson(*check);
  if (display) {
    const HeadsetDisplayStats h = display->stats();
    summary["hololens"] = {{"connections", h.connections},
                           {"display_lists", h.display_lists},
                           {"dropped", h.dropped},
                           {"disconnects", h.disconnects},
                           {"connect_failures", h.connect_failures},
                           {"speech_available", h.speech_available},
                           {"notices", h.notices},
                           {"last_error", h.last_error}};
  }
  if (json) {
    std::cout << WithOptions(summary, app).dump(2) << "\n";
  } else if (!quiet) {
    std::cout << "navigated " << stats.frames << " frames: " << stats.tracking << " tracking, "
              << stats.holding << " holding, " << stats.reference_lost << " reference lost, "
              << stats.no_world_pose << " without head pose\n";
    PrintDropped(stats);
    if (stats.settling_frames > 0) {
      std::cout << stats.settling_frames
                << " frames placed while the reference was SETTLING (its orientation not yet "
                   "averaged to "
                << settled_sd_deg << " deg)\n";
    }
    if (stats.low_rate_frames > 0) {
      std::cout << stats.low_rate_frames
                << " frames at LOW_RATE (under 15 Hz for over 1 s: the headset's camera throttles "
                   "without a hand in view)\n";
    }
  }
  if (check && !check->done() && !quiet) {
    std::cerr << "tofnav " << (verify_only ? "verify" : "navigate") << ": " << check->StatusLine()
              << ": the check ended with " << check->touches().size() << " of "
              << check->landmarks().size() << " landmarks touched\n";
  }
  if (live != nullptr && !live->failure().empty() && !signals.signalled() && !timed_out) {
    return kExitGaveUp;
  }
  return verify_only && !check->passed() ? kExitVerifyFailed : EXIT_SUCCESS;
}

}  // namespace

int RunNavigate(int argc, char** argv) { return RunNavigation(argc, argv, false); }

int RunVerify(int argc, char** argv) { return RunNavigation(argc, argv, true); }

}  // namespace tofnav
