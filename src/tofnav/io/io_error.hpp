// SPDX-License-Identifier: BSD-3-Clause
// The one exception type of io/: names the file, the byte offset and what was expected.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace tofnav {

class IoError : public std::runtime_error {
 public:
  /// "<path>: at byte <offset>: <message>" (the offset part only when given).
  IoError(const std::filesystem::path& path, std::optional<std::uint64_t> offset,
          const std::string& message);
  const std::filesystem::path& path() const { return path_; }
  std::optional<std::uint64_t> offset() const { return offset_; }

 private:
  std::filesystem::path path_;
  std::optional<std::uint64_t> offset_;
};

}  // namespace tofnav
