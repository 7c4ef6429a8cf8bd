// SPDX-License-Identifier: BSD-3-Clause
// ustar index and writer against archives built byte by byte.
#include "tofnav/io/tar.hpp"

#include <gtest/gtest.h>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"

namespace tofnav {
namespace {

using testing::AppendEndBlocks;
using testing::AppendEntry;
using testing::Bytes;
using testing::HandHeader;
using testing::Reseal;
using testing::SetField;
using testing::TempDir;
using testing::ToBytes;

// Offset of the IoError thrown by `f`, or nullopt when it throws nothing.
template <typename F>
std::optional<std::uint64_t> ErrorOffset(F&& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const IoError& error) {
    if (message != nullptr) *message = error.what();
    return error.offset().value_or(~std::uint64_t{0});
  }
  return std::nullopt;
}

// Three entries: a 5-byte file, a directory, an empty file with an all-NUL size field (the
// recorder's Tar.cpp writes empty sizes that way), then the end blocks.
Bytes ThreeEntryArchive() {
  Bytes tar;
  AppendEntry(tar, HandHeader("1_ab.pgm", 5), ToBytes("hello"));
  AppendEntry(tar, HandHeader("sub/", 0, '5'), {});
  Bytes empty = HandHeader("notes.txt", 0);
  std::fill_n(empty.begin() + 124, 12, 0);
  Reseal(empty);
  AppendEntry(tar, empty, {});
  AppendEndBlocks(tar);
  return tar;
}

void ExpectThreeEntryIndex(const TarIndex& index) {
  ASSERT_EQ(index.entries.size(), 2U);
  EXPECT_EQ(index.entries[0].name, "1_ab.pgm");
  EXPECT_EQ(index.entries[0].header_offset, 0U);
  EXPECT_EQ(index.entries[0].data_offset, 512U);
  EXPECT_EQ(index.entries[0].size, 5U);
  EXPECT_EQ(index.entries[1].name, "notes.txt");
  EXPECT_EQ(index.entries[1].header_offset, 1536U);  // after 1 data block and the directory
  EXPECT_EQ(index.entries[1].data_offset, 2048U);
  EXPECT_EQ(index.entries[1].size, 0U);
  EXPECT_EQ(index.skipped_entries, 1U);
  EXPECT_EQ(index.end, TarEnd::kEndBlocks);
  EXPECT_EQ(index.end_offset, 2048U);
}

TEST(IndexTar, HandMadeArchiveInMemory) { ExpectThreeEntryIndex(IndexTar(ThreeEntryArchive())); }

TEST(IndexTar, HandMadeArchiveFromFile) {
  const TempDir dir("tar_file");
  testing::WriteBytes(dir.path() / "a.tar", ThreeEntryArchive());
  ExpectThreeEntryIndex(IndexTar(RandomAccessFile(dir.path() / "a.tar")));
}

TEST(IndexTar, AcceptsSignedChecksumAndJoinsPrefix) {
  Bytes header = HandHeader("caf\xc3\xa9.pgm", 0);  // bytes >= 0x80 make the two sums differ
  SetField(header, 345, "dir");
  Reseal(header, /*signed_sum=*/true);
  Bytes tar;
  AppendEntry(tar, header, {});
  const TarIndex index = IndexTar(tar);
  ASSERT_EQ(index.entries.size(), 1U);
  EXPECT_EQ(index.entries[0].name, "dir/caf\xc3\xa9.pgm");
}

TEST(IndexTar, BadChecksumNamesTheHeaderOffset) {
  Bytes tar;
  AppendEntry(tar, HandHeader("a", 5), ToBytes("hello"));
  Bytes header = HandHeader("b", 0);
  header[0] = 'c';  // changed after the checksum was computed
  AppendEntry(tar, header, {});
  std::string message;
  EXPECT_EQ(ErrorOffset([&] { IndexTar(tar, "x.tar"); }, &message), 1024U);
  EXPECT_NE(message.find("checksum"), std::string::npos) << message;
  EXPECT_NE(message.find("x.tar"), std::string::npos) << message;
}

TEST(IndexTar, MalformedSizeFieldsAreErrors) {
  const auto offset_with_size = [](std::string_view field, std::string* message) {
    Bytes tar;
    AppendEntry(tar, HandHeader("a", 5), ToBytes("hello"));
    Bytes header = HandHeader("b", 0);
    std::fill_n(header.begin() + 124, 12, 0);
    SetField(header, 124, field);
    Reseal(header);  // a valid checksum, so the size field itself is rejected
    AppendEntry(tar, header, {});
    return ErrorOffset([&] { IndexTar(tar); }, message);
  };
  std::string message;
  EXPECT_EQ(offset_with_size("00000000089", &message), 1024U);  // 8, 9 are not octal
  EXPECT_NE(message.find("size"), std::string::npos) << message;
  EXPECT_EQ(offset_with_size("0000 000005", &message), 1024U);  // digits after a terminator
  EXPECT_EQ(offset_with_size(std::string_view("\x80\0\0\1", 4), &message), 1024U);  // GNU base-256
}

TEST(IndexTar, MissingMagicIsAnError) {
  Bytes header = HandHeader("a", 0);
  std::fill_n(header.begin() + 257, 8, 0);  // a pre-POSIX (v7) header
  Reseal(header);
  EXPECT_EQ(ErrorOffset([&] { IndexTar(header); }), 0U);
}

TEST(IndexTar, SizeBeyondEndOfFile) {
  Bytes tar;
  AppendEntry(tar, HandHeader("a", 5), ToBytes("hello"));
  Bytes big = HandHeader("b", 600);
  tar.insert(tar.end(), big.begin(), big.end());
  tar.resize(tar.size() + 100, 7);  // only 100 of the 600 bytes
  std::string message;
  EXPECT_EQ(ErrorOffset([&] { IndexTar(tar, "x.tar", {.allow_truncated_tail = false}); }, &message),
            1024U);
  EXPECT_NE(message.find("600"), std::string::npos) << message;
  // The default treats it as a recorder killed mid-entry: the entry is dropped and reported.
  const TarIndex index = IndexTar(tar);
  ASSERT_EQ(index.entries.size(), 1U);
  EXPECT_EQ(index.end, TarEnd::kTruncatedEntry);
  EXPECT_EQ(index.dropped_name, "b");
  EXPECT_EQ(index.end_offset, 1024U);
}

TEST(IndexTar, TruncatedArchives) {
  Bytes full;
  AppendEntry(full, HandHeader("a", 5), ToBytes("hello"));
  AppendEntry(full, HandHeader("b", 3), ToBytes("abc"));
  const auto cut = [&full](std::size_t size) { return Bytes(full.begin(), full.begin() + size); };

  const TarIndex no_end_blocks = IndexTar(full);  // 2048 bytes, no zero blocks
  EXPECT_EQ(no_end_blocks.entries.size(), 2U);
  EXPECT_EQ(no_end_blocks.end, TarEnd::kEndOfFile);
  EXPECT_EQ(no_end_blocks.end_offset, 2048U);

  const TarIndex mid_header = IndexTar(cut(1024 + 100));
  EXPECT_EQ(mid_header.entries.size(), 1U);
  EXPECT_EQ(mid_header.end, TarEnd::kTruncatedHeader);
  EXPECT_EQ(mid_header.end_offset, 1024U);

  const TarIndex mid_entry = IndexTar(cut(1536 + 2));  // 2 of "abc"
  EXPECT_EQ(mid_entry.entries.size(), 1U);
  EXPECT_EQ(mid_entry.end, TarEnd::kTruncatedEntry);
  EXPECT_EQ(mid_entry.dropped_name, "b");

  const TarIndex padding_cut = IndexTar(cut(1536 + 3));  // data complete, padding missing
  ASSERT_EQ(padding_cut.entries.size(), 2U);
  EXPECT_EQ(padding_cut.end, TarEnd::kEndOfFile);

  Bytes end_blocks_cut = full;
  end_blocks_cut.resize(full.size() + 300, 0);  // killed while writing the end blocks
  EXPECT_EQ(IndexTar(end_blocks_cut).end, TarEnd::kEndBlocks);

  EXPECT_EQ(IndexTar(Bytes{}).end, TarEnd::kEndOfFile);
}

TEST(TarWriter, HeadersMatchTheHandBuiltLayout) {
  const TempDir dir("tar_writer");
  const Bytes first = ToBytes("hello");
  const Bytes second(512, 0xAB);  // exactly one block: no padding
  TarWriter writer(dir.path() / "w.tar");
  writer.Add("1_ab.pgm", first, 1700000000);
  writer.Add("1.pgm", second);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "w.tar"));  // only after Close()
  writer.Close();

  Bytes expected;
  AppendEntry(expected, HandHeader("1_ab.pgm", 5, '0', "0000644", 1700000000), first);
  AppendEntry(expected, HandHeader("1.pgm", 512), second);
  AppendEndBlocks(expected);
  const std::vector<std::uint8_t> written = ReadFileBytes(dir.path() / "w.tar");
  EXPECT_EQ(written, expected);  // byte for byte, checksums included

  const TarIndex index = IndexTar(RandomAccessFile(dir.path() / "w.tar"));
  ASSERT_EQ(index.entries.size(), 2U);
  EXPECT_EQ(index.entries[1].name, "1.pgm");
  EXPECT_EQ(index.entries[1].data_offset, 1536U);
  EXPECT_EQ(index.end, TarEnd::kEndBlocks);
}

TEST(TarWriter, RejectsBadNamesAndLeavesNothingWithoutClose) {
  const TempDir dir("tar_writer_bad");
  {
    TarWriter writer(dir.path() / "w.tar");
    EXPECT_THROW(writer.Add("", {}), PreconditionError);
    EXPECT_THROW(writer.Add(std::string(100, 'a'), {}), PreconditionError);
    EXPECT_NO_THROW(writer.Add(std::string(99, 'a'), {}));
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace tofnav
