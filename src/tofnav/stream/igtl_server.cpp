// SPDX-License-Identifier: BSD-3-Clause
// IgtlServer: poll() loop over the listener, an eventfd and non-blocking client sockets.
#include "tofnav/stream/igtl_server.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <deque>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {

struct IgtlServer::Client {
  Client(SocketFd socket, std::uint64_t id, const IgtlReceiverOptions& receive)
      : fd(std::move(socket)), receiver("igtl client " + std::to_string(id), receive) {}
  SocketFd fd;
  IgtlReceiver receiver;
  IgtlReceiverCounters counted;  // already added to the server's stats
  std::deque<Message> queue;
  std::size_t queued_bytes = 0;
  std::size_t head_offset = 0;  // bytes of queue.front() already sent
  bool broken = false;          // a send failed: close on the I/O thread
};

void IgtlServerOptions::Check() const {
  Require(port >= 0 && port <= 65535, "IgtlServerOptions.port must be in 0..65535");
  Require(max_clients >= 1, "IgtlServerOptions.max_clients must be >= 1");
  Require(max_queued_messages >= 1, "IgtlServerOptions.max_queued_messages must be >= 1");
  Require(max_queued_bytes >= 1, "IgtlServerOptions.max_queued_bytes must be >= 1");
  receive.Check();
}

IgtlServer::IgtlServer(const IgtlServerOptions& options) : options_(options) {
  options_.Check();
  listener_ = ListenTcp(options_.bind_address, options_.port);
  SetNonBlocking(listener_);
  port_ = LocalPort(listener_);
  wake_ = SocketFd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  if (!wake_.valid()) throw IoError("igtl server", std::nullopt, "eventfd failed");
  thread_ = std::thread([this] { Run(); });
}

IgtlServer::~IgtlServer() {
  stop_ = true;
  Wake();
  if (thread_.joinable()) thread_.join();
}

void IgtlServer::Wake() {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_.get(), &one, sizeof(one));
}

IgtlServerStats IgtlServer::stats() const {
  const std::lock_guard lock(mutex_);
  IgtlServerStats s = stats_;
  s.clients = static_cast<int>(clients_.size());
  return s;
}

void IgtlServer::Publish(std::vector<std::uint8_t> message) {
  const auto shared = std::make_shared<const std::vector<std::uint8_t>>(std::move(message));
  const std::lock_guard lock(mutex_);
  ++stats_.published;
  for (const auto& client : clients_) Enqueue(*client, shared);
}

void IgtlServer::SetGreeting(const std::string& key, std::vector<std::uint8_t> message) {
  const auto shared = std::make_shared<const std::vector<std::uint8_t>>(std::move(message));
  const std::lock_guard lock(mutex_);
  bool replaced = false;
  for (auto& [k, m] : greetings_) {
    if (k == key) {
      m = shared;
      replaced = true;
    }
  }
  if (!replaced) greetings_.emplace_back(key, shared);
  for (const auto& client : clients_) Enqueue(*client, shared);
}

// Called with mutex_ held.
void IgtlServer::Enqueue(Client& client, const Message& message) {
  if (client.broken) return;
  while (client.queue.size() >= options_.max_queued_messages ||
         client.queued_bytes + message->size() > options_.max_queued_bytes) {
    // Drop the oldest message not already on its way (a partly sent one must be finished).
    const std::size_t victim = client.head_offset > 0 ? 1 : 0;
    if (victim >= client.queue.size()) break;
    client.queued_bytes -= client.queue[victim]->size();
    client.queue.erase(client.queue.begin() + static_cast<std::ptrdiff_t>(victim));
    ++stats_.messages_dropped;
  }
  const bool was_idle = client.queue.empty();
  client.queue.push_back(message);
  client.queued_bytes += message->size();
  ++stats_.messages_queued;
  stats_.max_queue_depth = std::max<std::uint64_t>(stats_.max_queue_depth, client.queue.size());
  // Try at once (non-blocking): the message reaches the socket without a thread hop.
  if (was_idle && !WriteTo(client)) client.broken = true;
  if (!client.queue.empty() || client.broken) Wake();
}

// Called with mutex_ held. False on a socket error.
bool IgtlServer::WriteTo(Client& client) {
  while (!client.queue.empty()) {
    const std::vector<std::uint8_t>& m = *client.queue.front();
    const ssize_t n = ::send(client.fd.get(), m.data() + client.head_offset,
                             m.size() - client.head_offset, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return true;
      if (errno == EINTR) continue;
      return false;
    }
    client.head_offset += static_cast<std::size_t>(n);
    if (client.head_offset == m.size()) {
      client.queued_bytes -= m.size();
      client.queue.pop_front();
      client.head_offset = 0;
      ++stats_.messages_sent;
    }
  }
  return true;
}

void IgtlServer::Accept() {
  while (true) {
    SocketFd fd(::accept4(listener_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (!fd.valid()) return;  // EAGAIN: no more pending
    SetNoDelay(fd);
    const std::lock_guard lock(mutex_);
    if (static_cast<int>(clients_.size()) >= options_.max_clients) {
      ++stats_.refused;
      continue;  // closed by SocketFd
    }
    ++stats_.connections;
    clients_.push_back(
        std::make_unique<Client>(std::move(fd), stats_.connections, options_.receive));
    for (const auto& [key, message] : greetings_) Enqueue(*clients_.back(), message);
  }
}

// False when the client must be closed.
bool IgtlServer::ReadFrom(Client& client) {
  std::array<std::uint8_t, 65536> buffer;
  std::vector<std::string> types;  // of the good frames read now, counted under the lock
  bool keep = true;
  while (keep) {
    const ssize_t n = ::recv(client.fd.get(), buffer.data(), buffer.size(), MSG_DONTWAIT);
    if (n == 0) keep = false;
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    if (n < 0) keep = false;
    if (!keep) break;
    try {
      client.receiver.Feed(std::span(buffer).first(static_cast<std::size_t>(n)),
                           [&](const IgtlFrame& f) { types.push_back(f.header.type); });
    } catch (const IoError&) {
      const std::lock_guard lock(mutex_);
      ++stats_.framing_errors;
      keep = false;
    }
  }
  {
    const std::lock_guard lock(mutex_);
    const IgtlReceiverCounters& c = client.receiver.counters();
    stats_.frames_received += c.frames - client.counted.frames;
    stats_.v2_frames_received += c.v2_frames - client.counted.v2_frames;
    stats_.crc_errors += c.crc_errors - client.counted.crc_errors;
    stats_.malformed_v2 += c.malformed_v2 - client.counted.malformed_v2;
    client.counted = c;
    for (const std::string& type : types) ++stats_.received_types[type];
  }
  return keep;
}

void IgtlServer::Run() {
  std::vector<pollfd> fds;
  std::vector<Client*> polled;
  while (!stop_) {
    fds.assign({{listener_.get(), POLLIN, 0}, {wake_.get(), POLLIN, 0}});
    polled.clear();
    {
      const std::lock_guard lock(mutex_);
      for (const auto& c : clients_) {
        const auto events = static_cast<short>(POLLIN | (c->queue.empty() ? 0 : POLLOUT));
        fds.push_back({c->fd.get(), events, 0});
        polled.push_back(c.get());
      }
    }
    if (::poll(fds.data(), fds.size(), 500) < 0 && errno != EINTR) break;
    if ((fds[1].revents & POLLIN) != 0) {
      std::uint64_t count;
      [[maybe_unused]] const ssize_t n = ::read(wake_.get(), &count, sizeof(count));
    }
    for (std::size_t i = 0; i < polled.size(); ++i) {
      Client& c = *polled[i];
      const short revents = fds[i + 2].revents;
      bool keep = true;
      if ((revents & (POLLIN | POLLHUP | POLLERR)) != 0) keep = ReadFrom(c);
      const std::lock_guard lock(mutex_);
      if (keep && (revents & POLLOUT) != 0) keep = WriteTo(c);
      if (!keep) c.broken = true;
    }
    {
      const std::lock_guard lock(mutex_);
      for (auto it = clients_.begin(); it != clients_.end();) {
        if ((*it)->broken) {
          ++stats_.disconnects;
          it = clients_.erase(it);
        } else {
          ++it;
        }
      }
    }
    if ((fds[0].revents & POLLIN) != 0) Accept();
  }
}

}  // namespace tofnav
