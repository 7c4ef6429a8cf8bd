// SPDX-License-Identifier: BSD-3-Clause
// Test helpers: hl2ss AHAT files assembled byte by byte from docs/ahat.md section 3.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace tofnav::hl2ss_test {

constexpr std::size_t kRawPlane = 2 * 512 * 512;

/// This process's scratch folder, on tmpfs when there is one: the writers fsync, and megabyte
/// files synced to a disk would dominate the run time of these tests.
inline std::filesystem::path ScratchRoot() {
  std::error_code error;
  const std::filesystem::path shm = "/dev/shm";
  const auto base =
      std::filesystem::is_directory(shm, error) ? shm : std::filesystem::temp_directory_path();
  return base / ("tofnav_hl2ss_test_" + std::to_string(::getpid()));
}

/// Removes the scratch folder once all tests have run.
class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code error;
    std::filesystem::remove_all(ScratchRoot(), error);
  }
};
inline ::testing::Environment* const kScratchCleanup =
    ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

/// `name` inside a fresh folder for the running test.
inline std::filesystem::path TempPath(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto dir = ScratchRoot() / info->name();
  std::filesystem::create_directories(dir);
  return dir / name;
}

/// Little-endian byte assembly, independent of io/binary.hpp and of the writer.
struct Bytes {
  std::vector<std::uint8_t> data;
  template <typename T>
  Bytes& Put(T value) {
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      data.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(value) >> (8 * i)));
    }
    return *this;
  }
  Bytes& PutF(float value) {
    std::uint32_t bits;
    std::memcpy(&bits, &value, 4);
    return Put(bits);
  }
  Bytes& Text(const std::string& text) {
    for (const char c : text) data.push_back(static_cast<std::uint8_t>(c));
    return *this;
  }
  Bytes& Append(const std::vector<std::uint8_t>& more) {
    data.insert(data.end(), more.begin(), more.end());
    return *this;
  }
};

/// Header + AHAT config: mode, SAME/ZDEPTH, RAW, one option (GOP 1).
inline Bytes Header(std::uint8_t mode, std::uint8_t profile_z = 0, std::uint16_t port = 3804,
                    std::uint8_t profile_ab = 255) {
  Bytes b;
  b.Text("HL2SSV23").Put<std::uint16_t>(port).Put<std::uint32_t>(6).Text("golden");
  b.Put<std::uint8_t>(mode).Put<std::uint8_t>(1).Put<std::uint8_t>(profile_z);
  b.Put<std::uint8_t>(profile_ab).Put<std::uint8_t>(255).Put<std::uint32_t>(12345678);
  b.Put<std::uint8_t>(1).Put<std::uint64_t>(10).Put<std::uint64_t>(1);
  return b;
}
/// Bytes of Header(): magic, port, user_len, "golden", config with one option.
constexpr std::uint64_t kHeaderBytes = 8 + 2 + 4 + 6 + 10 + 16;

inline std::uint16_t DepthAt(int seed, int u, int v) {
  if (v == 0 && u == 3) return 4093;  // low signal
  if (v == 0 && u == 4) return 4095;  // outside the illumination
  if (v == 0 && u == 5) return 4090;  // first invalid code
  if (v == 0 && u == 6) return 4089;  // last valid code
  return static_cast<std::uint16_t>((u + 7 * v + 100 * seed) % 1100);
}
inline std::uint16_t AbAt(int seed, int u, int v) {
  return static_cast<std::uint16_t>((3 * u + 5 * v + 1000 * seed) & 0xFFFF);
}

/// SAME+RAW AB blob: depth plane then AB plane, row-major.
inline std::vector<std::uint8_t> SameRawBlob(int seed) {
  Bytes b;
  for (int v = 0; v < 512; ++v) {
    for (int u = 0; u < 512; ++u) b.Put(DepthAt(seed, u, v));
  }
  for (int v = 0; v < 512; ++v) {
    for (int u = 0; u < 512; ++u) b.Put(AbAt(seed, u, v));
  }
  return b.data;
}

/// Rig -> world as a DirectX row-vector matrix: rotation 90 deg about z, t = (0.25, -0.5, 1.125) m.
/// Column form R = [[0,-1,0],[1,0,0],[0,0,1]]; the stored rows are the rows of R^T, then t, 1.
inline Bytes& PutPose(Bytes& b) {
  for (const float value :
       {0.f, 1.f, 0.f, 0.f, -1.f, 0.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.25f, -0.5f, 1.125f, 1.f}) {
    b.PutF(value);
  }
  return b;
}
inline Bytes& PutZeroPose(Bytes& b) {
  for (int i = 0; i < 16; ++i) b.PutF(0.0f);
  return b;
}

/// Current layout, mode 1: frame 0 (located), an empty packet, frame 1 (not located).
inline Bytes CurrentSameRawMode1() {
  Bytes b = Header(1);
  b.Put<std::uint64_t>(1000).Put<std::uint32_t>(16 + kRawPlane * 2);
  b.Put<std::uint32_t>(0).Put<std::uint32_t>(kRawPlane * 2).Append(SameRawBlob(0));
  PutPose(b.Put<std::uint64_t>(111'111'111));
  b.Put<std::uint64_t>(1500).Put<std::uint32_t>(16);  // size_ab == 0: skipped
  PutZeroPose(b.Put<std::uint32_t>(0).Put<std::uint32_t>(0).Put<std::uint64_t>(0));
  b.Put<std::uint64_t>(2000).Put<std::uint32_t>(16 + kRawPlane * 2);
  b.Put<std::uint32_t>(0).Put<std::uint32_t>(kRawPlane * 2).Append(SameRawBlob(1));
  PutZeroPose(b.Put<std::uint64_t>(222));
  return b;
}

}  // namespace tofnav::hl2ss_test
