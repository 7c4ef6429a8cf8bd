// SPDX-License-Identifier: BSD-3-Clause
// RemoteSceneClient: one TCP connection to the Unity plugin's message queue, bounded waits.
#include "tofnav/stream/remote_scene_client.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/stream/hl2ss_client.hpp"

namespace tofnav {
namespace {

[[noreturn]] void FailSocketCall(const std::string& where, const std::string& what, int error) {
  throw IoError(where, std::nullopt, what + ": " + std::strerror(error));
}

// A TCP connection made within timeout_s (a non-blocking connect, then poll): an absent headset
// costs at most the timeout, never the kernel's minutes.
SocketFd ConnectWithin(const std::string& host, int port, double timeout_s,
                       const std::string& where) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found);
      rc != 0 || found == nullptr) {
    throw IoError(where, std::nullopt, std::string("cannot resolve host: ") + gai_strerror(rc));
  }
  SocketFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd.valid()) {
    ::freeaddrinfo(found);
    FailSocketCall(where, "socket", errno);
  }
  SetNonBlocking(fd);
  const int rc = ::connect(fd.get(), found->ai_addr, found->ai_addrlen);
  const int connect_errno = errno;
  ::freeaddrinfo(found);
  if (rc != 0 && connect_errno != EINPROGRESS) FailSocketCall(where, "connect", connect_errno);
  if (rc != 0) {
    pollfd p{fd.get(), POLLOUT, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::ceil(timeout_s * 1000.0)));
    if (ready == 0) throw IoError(where, std::nullopt, "connect timed out");
    if (ready < 0) FailSocketCall(where, "poll", errno);
    int error = 0;
    socklen_t size = sizeof(error);
    ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &error, &size);
    if (error != 0) FailSocketCall(where, "connect", error);
  }
  const int flags = ::fcntl(fd.get(), F_GETFL, 0);
  ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK);
  SetNoDelay(fd);
  SetTimeouts(fd, timeout_s);
  return fd;
}

}  // namespace

std::pair<std::string, int> ParseRemoteSceneEndpoint(const std::string& text) {
  std::optional<Hl2ssEndpoint> e;
  try {
    e = ParseHl2ssUri("hl2ss://" + text);
  } catch (const std::invalid_argument&) {
  }
  if (!e || e->host.empty()) {
    throw IoError(text, std::nullopt, "expected HOST[:PORT] with a port in 1..65535");
  }
  const bool has_port = text.find(':') != std::string::npos;
  return {e->host, has_port ? e->port : kRemoteScenePort};
}

RemoteSceneClient::RemoteSceneClient(const std::string& host, int port, double timeout_s)
    : endpoint_("tcp://" + host + ":" + std::to_string(port) + " (remote Unity scene)") {
  socket_ = ConnectWithin(host, port, timeout_s, endpoint_);
}

std::vector<std::uint32_t> RemoteSceneClient::Push(const RemoteSceneCommands& commands) {
  if (commands.empty()) return {};
  WriteAll(socket_, commands.bytes(), endpoint_);
  std::vector<std::uint8_t> raw(4 * commands.count());
  if (!ReadExact(socket_, raw, endpoint_, "command results")) {
    throw IoError(endpoint_, std::nullopt, "the headset closed the connection");
  }
  ByteReader reader(raw, endpoint_);
  std::vector<std::uint32_t> results(commands.count());
  for (std::uint32_t& r : results) r = reader.Le<std::uint32_t>("result");
  return results;
}

}  // namespace tofnav
