// SPDX-License-Identifier: BSD-3-Clause
// Minimal POSIX TCP sockets for stream/: an owned descriptor, listen, connect, exact reads.
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace tofnav {

/// An owned file descriptor (closed on destruction); move-only.
class SocketFd {
 public:
  SocketFd() = default;
  explicit SocketFd(int fd) : fd_(fd) {}
  SocketFd(SocketFd&& other) noexcept : fd_(other.Release()) {}
  SocketFd& operator=(SocketFd&& other) noexcept;
  SocketFd(const SocketFd&) = delete;
  SocketFd& operator=(const SocketFd&) = delete;
  ~SocketFd() { Close(); }

  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  int Release();
  void Close();

 private:
  int fd_ = -1;
};

/// A listening TCP socket on `address` (IPv4 dotted or "localhost"), port 0 = ephemeral, with
/// SO_REUSEADDR. IoError naming "tcp://address:port" on failure.
SocketFd ListenTcp(const std::string& address, int port, int backlog = 8);
/// The port a bound socket listens on.
int LocalPort(const SocketFd& socket);
/// Connects with TCP_NODELAY (host name or IPv4); IoError on failure.
SocketFd ConnectTcp(const std::string& host, int port);
void SetNonBlocking(const SocketFd& socket);
void SetNoDelay(const SocketFd& socket);
/// Sets SO_RCVTIMEO and SO_SNDTIMEO [s] on a blocking socket (0 = wait for ever).
void SetTimeouts(const SocketFd& socket, double timeout_s);

/// Blocking exact read: true when all bytes arrived, false on a clean close before the first
/// byte; IoError on a close mid-read, a timeout or an error. `what` names the field in errors.
bool ReadExact(const SocketFd& socket, std::span<std::uint8_t> out, const std::string& source,
               const char* what);
/// Blocking write of every byte (MSG_NOSIGNAL); IoError on failure.
void WriteAll(const SocketFd& socket, std::span<const std::uint8_t> bytes,
              const std::string& source);

}  // namespace tofnav
