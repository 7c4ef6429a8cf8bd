// SPDX-License-Identifier: BSD-3-Clause
// POSIX TCP helpers; every failure is a NetworkError naming the peer, the action and its meaning.
#include "tofnav/stream/socket.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace tofnav {
namespace {

std::string Endpoint(const std::string& host, int port) {
  return "tcp://" + host + ":" + std::to_string(port);
}

/// The receive timeout of a socket [s] (0: none).
double ReceiveTimeoutS(int fd) {
  timeval tv{};
  socklen_t size = sizeof(tv);
  if (::getsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, &size) != 0) return 0.0;
  return static_cast<double>(tv.tv_sec) + static_cast<double>(tv.tv_usec) * 1e-6;
}

/// Throws a NetworkError for `error` (an errno) met while doing `action` with `peer`.
[[noreturn]] void Fail(const std::string& peer, const std::string& action, int error,
                       double timeout_s = 0.0) {
  NetworkFailure failure = NetworkFailure::kOther;
  std::string meaning;
  switch (error) {
    case ECONNREFUSED:
      failure = NetworkFailure::kRefused;
      meaning = "connection refused: nothing listens on that port (is the server running?)";
      break;
    case ETIMEDOUT:
    case EHOSTUNREACH:
    case ENETUNREACH:
    case EHOSTDOWN:
    case ENETDOWN:
      failure = NetworkFailure::kUnreachable;
      meaning = "the host cannot be reached (network down, wrong address or device off)";
      break;
    case ECONNRESET:
      failure = NetworkFailure::kReset;
      meaning = "the peer reset the connection";
      break;
    case EPIPE:
      failure = NetworkFailure::kClosed;
      meaning = "the peer closed the connection";
      break;
    case EAGAIN:
      failure = NetworkFailure::kTimeout;
      char text[96];
      std::snprintf(text, sizeof text, "nothing arrived for %.1f s (the peer stopped sending)",
                    timeout_s);
      meaning = text;
      break;
    default:
      meaning = std::string("system error: ") + std::strerror(error);
  }
  throw NetworkError(peer, failure, action + ": " + meaning);
}

sockaddr_in Resolve(const std::string& host, int port) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const int rc = getaddrinfo(host.c_str(), nullptr, &hints, &found);
  if (rc != 0 || found == nullptr) {
    throw IoError(Endpoint(host, port), std::nullopt,
                  std::string("cannot resolve host: ") + gai_strerror(rc));
  }
  sockaddr_in address{};
  std::memcpy(&address, found->ai_addr, sizeof(address));
  freeaddrinfo(found);
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  return address;
}

}  // namespace

SocketFd& SocketFd::operator=(SocketFd&& other) noexcept {
  if (this != &other) {
    Close();
    fd_ = other.Release();
  }
  return *this;
}

int SocketFd::Release() {
  const int fd = fd_;
  fd_ = -1;
  return fd;
}

void SocketFd::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

SocketFd ListenTcp(const std::string& address, int port, int backlog) {
  const std::string where = Endpoint(address, port);
  if (port < 0 || port > 65535) throw IoError(where, std::nullopt, "port outside 0..65535");
  const sockaddr_in bind_to = Resolve(address, port);
  SocketFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd.valid()) Fail(where, "creating a socket", errno);
  const int one = 1;
  ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&bind_to), sizeof(bind_to)) != 0) {
    Fail(where, "binding (is another program using the port?)", errno);
  }
  if (::listen(fd.get(), backlog) != 0) Fail(where, "listening", errno);
  return fd;
}

int LocalPort(const SocketFd& socket) {
  sockaddr_in address{};
  socklen_t size = sizeof(address);
  if (::getsockname(socket.get(), reinterpret_cast<sockaddr*>(&address), &size) != 0) {
    Fail("<socket>", "reading the bound port", errno);
  }
  return ntohs(address.sin_port);
}

SocketFd ConnectTcp(const std::string& host, int port, double timeout_s) {
  const std::string where = Endpoint(host, port);
  if (port <= 0 || port > 65535) throw IoError(where, std::nullopt, "port outside 1..65535");
  const sockaddr_in to = Resolve(host, port);
  SocketFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd.valid()) Fail(where, "creating a socket", errno);
  const int flags = ::fcntl(fd.get(), F_GETFL, 0);
  if (timeout_s > 0.0) ::fcntl(fd.get(), F_SETFL, flags | O_NONBLOCK);
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&to), sizeof(to)) != 0) {
    if (errno != EINPROGRESS || timeout_s <= 0.0) Fail(where, "connecting", errno);
    // Bounded wait for the handshake; the outcome is in SO_ERROR.
    pollfd p{fd.get(), POLLOUT, 0};
    int ready = 0;
    do {
      ready = ::poll(&p, 1, static_cast<int>(std::ceil(timeout_s * 1e3)));
    } while (ready < 0 && errno == EINTR);
    if (ready == 0) Fail(where, "connecting", ETIMEDOUT);
    int error = 0;
    socklen_t size = sizeof(error);
    ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &error, &size);
    if (ready < 0 || error != 0) Fail(where, "connecting", ready < 0 ? errno : error);
  }
  if (timeout_s > 0.0) ::fcntl(fd.get(), F_SETFL, flags);
  SetNoDelay(fd);
  return fd;
}

void SetNonBlocking(const SocketFd& socket) {
  const int flags = ::fcntl(socket.get(), F_GETFL, 0);
  if (flags < 0 || ::fcntl(socket.get(), F_SETFL, flags | O_NONBLOCK) != 0) {
    Fail("<socket>", "making the socket non-blocking", errno);
  }
}

void SetNoDelay(const SocketFd& socket) {
  const int one = 1;
  ::setsockopt(socket.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
}

void SetResetOnClose(const SocketFd& socket) {
  const linger abort{.l_onoff = 1, .l_linger = 0};
  ::setsockopt(socket.get(), SOL_SOCKET, SO_LINGER, &abort, sizeof(abort));
}

void SetTimeouts(const SocketFd& socket, double timeout_s) {
  timeval tv{};
  tv.tv_sec = static_cast<time_t>(std::floor(timeout_s));
  tv.tv_usec = static_cast<suseconds_t>((timeout_s - std::floor(timeout_s)) * 1e6);
  ::setsockopt(socket.get(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  ::setsockopt(socket.get(), SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof(tv));
}

bool ReadExact(const SocketFd& socket, std::span<std::uint8_t> out, const std::string& source,
               const char* what) {
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::recv(socket.get(), out.data() + done, out.size() - done, 0);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n == 0) {
      if (done == 0) return false;
      throw NetworkError(source, NetworkFailure::kTruncated,
                         std::string("receiving the ") + what +
                             ": the peer closed the connection inside it (" + std::to_string(done) +
                             " of " + std::to_string(out.size()) + " bytes)");
    } else if (errno != EINTR) {
      const int error = errno == EWOULDBLOCK ? EAGAIN : errno;
      Fail(source, std::string("receiving the ") + what, error, ReceiveTimeoutS(socket.get()));
    }
  }
  return true;
}

void WriteAll(const SocketFd& socket, std::span<const std::uint8_t> bytes,
              const std::string& source) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::send(socket.get(), bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      throw NetworkError(source, NetworkFailure::kTimeout,
                         "sending: the peer stopped reading (send timeout)");
    } else if (n < 0 && errno != EINTR) {
      Fail(source, "sending", errno);
    }
  }
}

}  // namespace tofnav
