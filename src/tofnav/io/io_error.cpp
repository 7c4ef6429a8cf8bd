// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

std::string Compose(const std::filesystem::path& path, std::optional<std::uint64_t> offset,
                    const std::string& message) {
  std::string text = path.string();
  if (offset) text += ": at byte " + std::to_string(*offset);
  return text + ": " + message;
}

}  // namespace

IoError::IoError(const std::filesystem::path& path, std::optional<std::uint64_t> offset,
                 const std::string& message)
    : std::runtime_error(Compose(path, offset, message)), path_(path), offset_(offset) {}

}  // namespace tofnav
