// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: the three transform decoders (JSON, ITK .tfm, plain text) on arbitrary bytes;
// whatever decodes must encode and decode again.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "tofnav/casefile/transform_io.hpp"
#include "tofnav/io/io_error.hpp"

namespace {

std::span<const std::uint8_t> Bytes(const std::string& text) {
  return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  try {
    const tofnav::NamedTransform t = tofnav::DecodeTransformJson(bytes);
    tofnav::DecodeTransformJson(Bytes(tofnav::EncodeTransformJson(t)));
  } catch (const tofnav::IoError&) {
  }
  try {
    const tofnav::Rigid3d t = tofnav::DecodeItkTransform(bytes);
    tofnav::DecodeItkTransform(Bytes(tofnav::EncodeItkTransform(t)));
  } catch (const tofnav::IoError&) {
  }
  try {
    const tofnav::NamedTransform t = tofnav::DecodeTransformText(bytes);
    tofnav::DecodeTransformText(Bytes(tofnav::EncodeTransformText(t)));
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
