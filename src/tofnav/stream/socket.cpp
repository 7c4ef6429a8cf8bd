// SPDX-License-Identifier: BSD-3-Clause
// POSIX TCP helpers; every failure is an IoError naming the endpoint and errno's text.
#include "tofnav/stream/socket.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

std::string Endpoint(const std::string& host, int port) {
  return "tcp://" + host + ":" + std::to_string(port);
}

[[noreturn]] void Fail(const std::string& where, const std::string& what) {
  throw IoError(where, std::nullopt, what + ": " + std::strerror(errno));
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
  if (!fd.valid()) Fail(where, "socket");
  const int one = 1;
  ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&bind_to), sizeof(bind_to)) != 0) {
    Fail(where, "bind");
  }
  if (::listen(fd.get(), backlog) != 0) Fail(where, "listen");
  return fd;
}

int LocalPort(const SocketFd& socket) {
  sockaddr_in address{};
  socklen_t size = sizeof(address);
  if (::getsockname(socket.get(), reinterpret_cast<sockaddr*>(&address), &size) != 0) {
    Fail("<socket>", "getsockname");
  }
  return ntohs(address.sin_port);
}

SocketFd ConnectTcp(const std::string& host, int port) {
  const std::string where = Endpoint(host, port);
  if (port <= 0 || port > 65535) throw IoError(where, std::nullopt, "port outside 1..65535");
  const sockaddr_in to = Resolve(host, port);
  SocketFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd.valid()) Fail(where, "socket");
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&to), sizeof(to)) != 0) {
    Fail(where, "connect");
  }
  SetNoDelay(fd);
  return fd;
}

void SetNonBlocking(const SocketFd& socket) {
  const int flags = ::fcntl(socket.get(), F_GETFL, 0);
  if (flags < 0 || ::fcntl(socket.get(), F_SETFL, flags | O_NONBLOCK) != 0) {
    Fail("<socket>", "fcntl O_NONBLOCK");
  }
}

void SetNoDelay(const SocketFd& socket) {
  const int one = 1;
  ::setsockopt(socket.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
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
      throw IoError(source, std::nullopt,
                    std::string("connection closed inside the ") + what + " (" +
                        std::to_string(done) + " of " + std::to_string(out.size()) + " bytes)");
    } else if (errno != EINTR) {
      Fail(source, std::string("receiving the ") + what);
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
    } else if (n < 0 && errno != EINTR) {
      Fail(source, "send");
    }
  }
}

}  // namespace tofnav
