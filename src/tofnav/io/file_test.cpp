// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/io/file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

std::filesystem::path TempDir() {
  auto dir =
      std::filesystem::temp_directory_path() / ("tofnav_file_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(AtomicFileWriter, AbandonedWriteLeavesOriginalIntact) {
  const auto path = TempDir() / "keep.txt";
  WriteFileAtomically(path, std::string("good"));
  {
    AtomicFileWriter writer(path);
    writer.Write(std::string("half"));
    // destroyed without Commit()
  }
  const auto bytes = ReadFileBytes(path);
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()), "good");
  for (const auto& entry : std::filesystem::directory_iterator(path.parent_path())) {
    EXPECT_THAT(entry.path().filename().string(), ::testing::Not(::testing::HasSubstr(".tmp-")));
  }
}

TEST(RandomAccessFile, ShortReadNamesFileAndOffset) {
  const auto path = TempDir() / "short.bin";
  WriteFileAtomically(path, std::string(10, 'x'));
  const RandomAccessFile file(path);
  EXPECT_EQ(file.size(), 10u);
  try {
    file.ReadAt(6, 8, "packet header");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), 10u);
    EXPECT_THAT(e.what(), ::testing::HasSubstr("short.bin"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("packet header"));
  }
}

TEST(ByteReader, EndianAndBounds) {
  const std::vector<std::uint8_t> bytes = {0x01, 0x02, 0x03, 0x04, 0xAA};
  ByteReader reader(bytes, "mem", 100);
  EXPECT_EQ(reader.Le<std::uint16_t>("a"), 0x0201);
  EXPECT_EQ(reader.Be<std::uint16_t>("b"), 0x0304);
  try {
    reader.Le<std::uint32_t>("field");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), 104u);
  }
  ByteWriter writer;
  writer.Be<std::uint16_t>(0x0102);
  writer.Le<std::uint16_t>(0x0102);
  EXPECT_EQ(writer.bytes(), (std::vector<std::uint8_t>{1, 2, 2, 1}));
}

}  // namespace
}  // namespace tofnav
