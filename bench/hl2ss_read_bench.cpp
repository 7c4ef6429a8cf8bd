// SPDX-License-Identifier: BSD-3-Clause
// Reading hl2ss AHAT recordings from the page cache: frames per second for RAW and for the
// H.264 / H.265 profiles side by side (decoding included), and index build time.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "tofnav/recording/hl2ss_recording.hpp"

namespace tofnav {
namespace {

constexpr int kFrames = 200;

/// Writes (once per process) a recording of kFrames synthetic frames and returns its path.
std::filesystem::path Recording(Hl2ssDepthProfile profile_z,
                                Hl2ssVideoProfile profile_ab = Hl2ssVideoProfile::kRaw) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto path = dir / ("tofnav_hl2ss_bench_" + std::to_string(::getpid()) + "_" +
                           std::to_string(static_cast<int>(profile_z)) + "_" +
                           std::to_string(static_cast<int>(profile_ab)) + ".bin");
  if (std::filesystem::exists(path)) return path;
  Hl2ssWriterOptions options;
  options.profile_z = profile_z;
  options.profile_ab = profile_ab;
  Hl2ssRecordingWriter writer(path, options);
  AhatFrame frame;
  frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
  frame.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
  for (int i = 0; i < kFrames; ++i) {
    for (int v = 0; v < kAhatHeight; ++v) {
      for (int u = 0; u < kAhatWidth; ++u) {
        // A smooth surface at 300..700 mm with a patch of invalid pixels, AB varying.
        const bool invalid = (u - 256) * (u - 256) + (v - 256) * (v - 256) > 250 * 250;
        frame.range_mm(u, v) = static_cast<std::uint16_t>(invalid ? 4095 : 300 + (u + v + i) % 400);
        frame.ab(u, v) = static_cast<std::uint16_t>((u * 13 + v * 7 + i) & 4095);
      }
    }
    frame.host_ticks = 222'222ULL * static_cast<std::uint64_t>(i);
    frame.world_from_rig = Rigid3d::Identity();
    writer.Append(frame);
  }
  writer.Close();
  return path;
}

void ReadAllFrames(benchmark::State& state, Hl2ssDepthProfile profile_z,
                   Hl2ssVideoProfile profile_ab = Hl2ssVideoProfile::kRaw) {
  const auto path = Recording(profile_z, profile_ab);
  const Hl2ssRecording recording(path);
  std::size_t bytes = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < recording.frame_count(); ++i) {
      const AhatFrame frame = recording.ReadFrame(i);
      benchmark::DoNotOptimize(frame.range_mm.data());
      bytes += 2 * frame.range_mm.size() * sizeof(std::uint16_t);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(recording.frame_count()));
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes));
}

void BM_ReadSameRaw(benchmark::State& state) { ReadAllFrames(state, Hl2ssDepthProfile::kSame); }
void BM_ReadZdepthRaw(benchmark::State& state) { ReadAllFrames(state, Hl2ssDepthProfile::kZdepth); }
void BM_ReadZdepthH265(benchmark::State& state) {
  ReadAllFrames(state, Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH265Main);
}
void BM_ReadZdepthH264(benchmark::State& state) {
  ReadAllFrames(state, Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH264Main);
}
void BM_ReadSameH265(benchmark::State& state) {
  ReadAllFrames(state, Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kH265Main);
}

void BM_OpenAndIndexSameRaw(benchmark::State& state) {
  const auto path = Recording(Hl2ssDepthProfile::kSame);
  for (auto _ : state) {
    const Hl2ssRecording recording(path);
    benchmark::DoNotOptimize(recording.frame_count());
  }
}

BENCHMARK(BM_ReadSameRaw)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadZdepthRaw)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadZdepthH265)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadZdepthH264)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadSameH265)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OpenAndIndexSameRaw)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace tofnav

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code error;  // remove the recordings written above
  for (const int profile : {0, 1}) {
    std::filesystem::remove(std::filesystem::temp_directory_path() /
                                ("tofnav_hl2ss_bench_" + std::to_string(::getpid()) + "_" +
                                 std::to_string(profile) + ".bin"),
                            error);
  }
  return 0;
}
