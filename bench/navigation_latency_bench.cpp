// SPDX-License-Identifier: BSD-3-Clause
// Latency from frame arrival to RasToWorld on a client's socket: Navigator::Process, encoding,
// IgtlServer::Publish, loopback TCP, client parse. Frames of evd-usecase paced at 45 Hz. Arguments:
// headset 0 no headset display, 1 HeadsetDisplay to a fake remote scene, 2 the same server stalled;
// stream 0 the decoded frame is given, 1 it arrives as a ZDEPTH+RAW packet, 2 as a ZDEPTH+H265
// packet, 3 as a SAME+H265 packet (the hl2ss client's default profile), both at the client's
// default bitrate (decoding included in the latency).
#include <benchmark/benchmark.h>
#include <sys/socket.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <span>
#include <thread>

#include "navigation_e2e_case.hpp"
#include "tofnav/stream/headset_display.hpp"
#include "tofnav/stream/hl2ss_client.hpp"
#include "tofnav/stream/igtl_receiver.hpp"
#include "tofnav/stream/igtl_server.hpp"
#include "tofnav/stream/navigation_messages.hpp"
#include "tofnav/stream/socket.hpp"
#include "tofnav/stream_testing/fake_remote_scene_server.hpp"

namespace tofnav {
namespace {

using Clock = std::chrono::steady_clock;

/// A client on its own thread that stamps the arrival of every complete RasToWorld message.
class StampingClient {
 public:
  explicit StampingClient(int port) : socket_(ConnectTcp("127.0.0.1", port)) {
    thread_ = std::thread([this] { Run(); });
  }
  ~StampingClient() {
    ::shutdown(socket_.get(), SHUT_RDWR);  // wakes the blocked recv (a close alone does not)
    thread_.join();
    socket_.Close();
  }
  /// Waits for the next RasToWorld arrival after `count` earlier ones.
  Clock::time_point WaitFor(std::uint64_t count) {
    std::unique_lock lock(mutex_);
    ready_.wait(lock, [&] { return arrivals_ > count; });
    return last_;
  }
  std::uint64_t arrivals() {
    const std::lock_guard lock(mutex_);
    return arrivals_;
  }

 private:
  void Run() {
    IgtlReceiver receiver("bench client");
    std::uint8_t buffer[65536];
    while (true) {
      const ssize_t n = ::recv(socket_.get(), buffer, sizeof(buffer), 0);
      if (n <= 0) return;
      receiver.Feed(std::span(buffer, static_cast<std::size_t>(n)), [&](const IgtlFrame& f) {
        if (f.header.device_name != "RasToWorld") return;
        const std::lock_guard lock(mutex_);
        last_ = Clock::now();
        ++arrivals_;
        ready_.notify_all();
      });
    }
  }
  SocketFd socket_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::uint64_t arrivals_ = 0;
  Clock::time_point last_;
};

void BM_FrameToSocketLatency(benchmark::State& state) {
  const testing::EvdCase c = testing::MakeEvdCase(45, false);
  sim::Simulator simulator(c.scenario);
  std::vector<AhatFrame> frames;
  while (!simulator.done()) frames.push_back(simulator.Next().render.frame);
  // The packets the headset would send (the first is a key frame, so the replay loop can restart).
  const std::int64_t stream = state.range(1);
  Hl2ssAhatConfig config;
  config.profile_z = stream == 3 ? Hl2ssDepthProfile::kSame : Hl2ssDepthProfile::kZdepth;
  config.profile_ab = stream >= 2 ? Hl2ssVideoProfile::kH265Main : Hl2ssVideoProfile::kRaw;
  config.bitrate_bps = Hl2ssDefaultAhatBitrate(config.profile_z, config.profile_ab);
  config.encoder_options = Hl2ssDefaultEncoderOptions(config.profile_ab);
  std::vector<std::vector<std::uint8_t>> packets;
  if (stream > 0) {
    Hl2ssPacketEncoder encoder(config);
    for (const AhatFrame& f : frames) packets.push_back(encoder.Encode(f));
  }
  Hl2ssVideoDecoder video(config);
  Navigator navigator(simulator.camera(), c.navigation_case);
  IgtlServer server({.port = 0});
  StampingClient client(server.port());
  while (server.stats().clients == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::unique_ptr<FakeRemoteSceneServer> headset;
  std::unique_ptr<HeadsetDisplay> display;
  if (state.range(0) > 0) {
    headset = std::make_unique<FakeRemoteSceneServer>();
    headset->SetStalled(state.range(0) == 2);
    HeadsetDisplayOptions options;
    options.port = headset->port();
    display = std::make_unique<HeadsetDisplay>(c.navigation_case.plan, options);
  }
  // Replays the 45 frames forwards and backwards (time stamps shifted to keep increasing).
  std::vector<double> latency_ms;
  std::size_t i = 0;
  double shift_s = 0.0;
  auto next_frame_at = Clock::now();
  for (auto _ : state) {
    const std::size_t k = i % frames.size();
    if (k == 0 && i > 0)
      shift_s += 1.0 + frames.back().timestamp_s() - frames.front().timestamp_s();
    ++i;
    std::this_thread::sleep_until(next_frame_at);  // 45 Hz arrival
    next_frame_at += std::chrono::microseconds(22222);
    const std::uint64_t before = client.arrivals();
    const auto arrival = Clock::now();
    AhatFrame frame = stream == 0 ? frames[k]
                                  : *DecodeHl2ssPacket(config, packets[k], "bench",
                                                       stream >= 2 ? &video : nullptr);
    frame.host_ticks += static_cast<std::uint64_t>(shift_s / kSecondsPerHostTick);
    const NavigationState s = navigator.Process(frame);
    for (NamedMessage& m : EncodeNavigationFrame(s, c.navigation_case.plan)) {
      server.Publish(std::move(m.bytes));
    }
    if (display) display->Update(s);    // after publishing, as RunNavigationSession's on_state
    if (!s.world_from_image) continue;  // nothing to wait for
    const auto on_socket = client.WaitFor(before);
    const double ms = std::chrono::duration<double, std::milli>(on_socket - arrival).count();
    latency_ms.push_back(ms);
    state.SetIterationTime(ms * 1e-3);
  }
  std::sort(latency_ms.begin(), latency_ms.end());
  const auto at = [&](double q) {
    return latency_ms.empty() ? 0.0
                              : latency_ms[static_cast<std::size_t>(
                                    q * static_cast<double>(latency_ms.size() - 1))];
  };
  state.counters["median_ms"] = at(0.5);
  state.counters["p99_ms"] = at(0.99);
  state.counters["max_ms"] = at(1.0);
  state.counters["measured"] = static_cast<double>(latency_ms.size());
  state.counters["dropped"] = static_cast<double>(server.stats().messages_dropped);
  if (display) {
    const HeadsetDisplayStats h = display->stats();
    state.counters["display_lists"] = static_cast<double>(h.display_lists);
    state.counters["display_dropped"] = static_cast<double>(h.dropped);
  }
}
BENCHMARK(BM_FrameToSocketLatency)
    ->ArgNames({"headset", "stream"})  // headset 0 off, 1 on, 2 stalled server; stream: above
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({0, 3})
    ->UseManualTime()
    ->Iterations(900)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tofnav

BENCHMARK_MAIN();
