// SPDX-License-Identifier: BSD-3-Clause
// Minimal POSIX TCP sockets for stream/: an owned descriptor, listen, connect, exact reads.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "tofnav/io/io_error.hpp"

namespace tofnav {

/// What went wrong on a connection, as the user needs to know it (docs/navigation.md).
enum class NetworkFailure {
  kRefused,      // nothing listens at that address and port
  kUnreachable,  // the network cannot reach the host, or it does not answer
  kClosed,       // the peer closed the connection
  kTruncated,    // the connection closed inside a message
  kReset,        // the peer reset the connection
  kTimeout,      // nothing arrived within the receive timeout
  kOther,
};

/// An IoError whose path is the peer ("tcp://host:port", "hl2ss://host:port") and whose message
/// says what was being done and what happened, in words (never a bare system error text).
class NetworkError : public IoError {
 public:
  NetworkError(const std::string& peer, NetworkFailure failure, const std::string& message)
      : IoError(peer, std::nullopt, message), failure_(failure) {}
  NetworkFailure failure() const { return failure_; }

 private:
  NetworkFailure failure_;
};

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
/// Connects with TCP_NODELAY (host name or IPv4); NetworkError on failure. `timeout_s` > 0 bounds
/// the wait for the host to answer (0: the system's, minutes on a dead Wi-Fi).
SocketFd ConnectTcp(const std::string& host, int port, double timeout_s = 0.0);
void SetNonBlocking(const SocketFd& socket);
void SetNoDelay(const SocketFd& socket);
/// SO_LINGER with a zero time: closing sends a reset (TCP RST) instead of a normal close.
void SetResetOnClose(const SocketFd& socket);
/// Sets SO_RCVTIMEO and SO_SNDTIMEO [s] on a blocking socket (0 = wait for ever).
void SetTimeouts(const SocketFd& socket, double timeout_s);

/// Blocking exact read: true when all bytes arrived, false on a clean close before the first
/// byte; NetworkError on a close mid-read (kTruncated), a timeout or an error, naming `source`
/// and `what` (the field being read).
bool ReadExact(const SocketFd& socket, std::span<std::uint8_t> out, const std::string& source,
               const char* what);
/// Blocking write of every byte (MSG_NOSIGNAL); NetworkError on failure.
void WriteAll(const SocketFd& socket, std::span<const std::uint8_t> bytes,
              const std::string& source);

}  // namespace tofnav
