// SPDX-License-Identifier: BSD-3-Clause
// Reading hl2ss AHAT recordings from the page cache: frames per second for RAW and for the
// H.264 / H.265 profiles side by side (decoding included), and index build time. The synthetic
// recordings are the codec's worst case (high-frequency range and AB); `--recording=PATH`
// (repeatable) adds the same measurement on real or simulated recordings, e.g. a headset's own or
// `tofnav simulate --profile same+h265` (docs/benchmarks.md).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/recording/hl2ss_recording.hpp"

namespace tofnav {
namespace {

constexpr int kFrames = 200;

/// Writes (once per process) a recording of kFrames synthetic frames and returns its path.
std::filesystem::path TempPrefix() {
  return std::filesystem::temp_directory_path() /
         ("tofnav_hl2ss_bench_" + std::to_string(::getpid()) + "_");
}

std::filesystem::path Recording(Hl2ssDepthProfile profile_z,
                                Hl2ssVideoProfile profile_ab = Hl2ssVideoProfile::kRaw) {
  const auto path = TempPrefix().string() + std::to_string(static_cast<int>(profile_z)) + "_" +
                    std::to_string(static_cast<int>(profile_ab)) + ".bin";
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

// `live`: as a live stream decodes (one thread, each picture out of its own unit: ReadFrameWith
// and a decoder of our own), beside the recording's read-ahead (ReadFrame, two frame threads).
void ReadEveryFrame(benchmark::State& state, const std::filesystem::path& path, bool live = false) {
  const Hl2ssRecording recording(path);
  live = live && recording.config().profile_ab != Hl2ssVideoProfile::kRaw;
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::optional<Hl2ssVideoDecoder> video;
    if (live) video.emplace(recording.config());
    for (std::size_t i = 0; i < recording.frame_count(); ++i) {
      const AhatFrame frame = live ? recording.ReadFrameWith(i, *video) : recording.ReadFrame(i);
      benchmark::DoNotOptimize(frame.range_mm.data());
      bytes += 2 * frame.range_mm.size() * sizeof(std::uint16_t);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(recording.frame_count()));
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes));
  state.counters["per_frame"] = benchmark::Counter(
      static_cast<double>(recording.frame_count()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void ReadAllFrames(benchmark::State& state, Hl2ssDepthProfile profile_z,
                   Hl2ssVideoProfile profile_ab = Hl2ssVideoProfile::kRaw) {
  ReadEveryFrame(state, Recording(profile_z, profile_ab), state.range(0) != 0);
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

// Argument 0: the recording read ahead (ReadFrame); 1: decoded as a live stream is.
BENCHMARK(BM_ReadSameRaw)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadZdepthRaw)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadZdepthH265)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadZdepthH264)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadSameH265)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OpenAndIndexSameRaw)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace tofnav

int main(int argc, char** argv) {
  // --recording=PATH, before Google Benchmark sees the arguments: one more benchmark per file,
  // named after it.
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    static constexpr const char* kFlag = "--recording=";
    if (i > 0 && std::strncmp(argv[i], kFlag, std::strlen(kFlag)) == 0) {
      const std::filesystem::path path = argv[i] + std::strlen(kFlag);
      for (const bool live : {false, true}) {
        benchmark::RegisterBenchmark(
            ((live ? "BM_ReadRecordingLive/" : "BM_ReadRecording/") + path.string()).c_str(),
            [path, live](benchmark::State& state) { tofnav::ReadEveryFrame(state, path, live); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
    } else {
      rest.push_back(argv[i]);
    }
  }
  int rest_count = static_cast<int>(rest.size());
  benchmark::Initialize(&rest_count, rest.data());
  if (benchmark::ReportUnrecognizedArguments(rest_count, rest.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  // Remove the synthetic recordings written above (every profile pair).
  const std::string prefix = tofnav::TempPrefix().filename().string();
  std::error_code error;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::temp_directory_path(), error)) {
    if (entry.path().filename().string().starts_with(prefix)) {
      std::filesystem::remove(entry.path(), error);
    }
  }
  return 0;
}
