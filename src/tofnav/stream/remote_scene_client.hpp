// SPDX-License-Identifier: BSD-3-Clause
// A blocking client of hl2ss's remote Unity scene: push a command buffer, read one u32 result per
// command (docs/navigation.md, "Headset display"). Every wait is bounded by a timeout.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tofnav/stream/remote_scene_protocol.hpp"
#include "tofnav/stream/socket.hpp"

namespace tofnav {

/// "HOST" or "HOST:PORT" (default port kRemoteScenePort); IoError on an empty host or a bad port.
std::pair<std::string, int> ParseRemoteSceneEndpoint(const std::string& text);

class RemoteSceneClient {
 public:
  /// Connects within `timeout_s` (also the bound of every later send and result read); IoError
  /// naming "tcp://host:port" on failure or timeout.
  RemoteSceneClient(const std::string& host, int port, double timeout_s);

  /// Sends `commands` and reads their results in order; IoError on a timeout, a closed
  /// connection or a socket error (the client is then unusable).
  std::vector<std::uint32_t> Push(const RemoteSceneCommands& commands);
  const std::string& endpoint() const { return endpoint_; }

 private:
  std::string endpoint_;
  SocketFd socket_;
};

}  // namespace tofnav
