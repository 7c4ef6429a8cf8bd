// SPDX-License-Identifier: BSD-3-Clause
// OpenIGTLink server: several clients, bounded per-client queues, never blocks the publisher.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tofnav/stream/igtl_receiver.hpp"
#include "tofnav/stream/socket.hpp"

namespace tofnav {

struct IgtlServerOptions {
  std::string bind_address = "127.0.0.1";  // "0.0.0.0" to accept other hosts
  int port = 18944;                        // 0: ephemeral (tests); see IgtlServer::port()
  int max_clients = 8;                     // more are accepted and closed at once
  /// Per-client queue bound: beyond either, the oldest unsent message is dropped.
  std::size_t max_queued_messages = 256;
  std::size_t max_queued_bytes = std::size_t{64} << 20;
  IgtlReceiverOptions receive;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// Totals since the server started (a snapshot).
struct IgtlServerStats {
  std::uint64_t connections = 0;  // accepted and served
  std::uint64_t refused = 0;      // over max_clients
  std::uint64_t disconnects = 0;  // closed by the peer, by an error or by a framing error
  std::uint64_t framing_errors = 0;
  std::uint64_t published = 0;         // Publish() calls
  std::uint64_t messages_queued = 0;   // summed over clients
  std::uint64_t messages_sent = 0;     // fully written to a socket
  std::uint64_t messages_dropped = 0;  // dropped from a full queue
  std::uint64_t max_queue_depth = 0;   // highest per-client queue length seen
  std::uint64_t frames_received = 0;   // good CRC
  std::uint64_t v2_frames_received = 0;
  std::uint64_t crc_errors = 0;
  std::uint64_t malformed_v2 = 0;
  int clients = 0;                                      // connected now
  std::map<std::string, std::uint64_t> received_types;  // e.g. {"STATUS", 3}
};

/// Serves OpenIGTLink clients (3D Slicer connects as a client, as to PLUS). One I/O thread polls
/// the sockets; Publish() only appends to bounded queues and wakes it, so a slow or stalled client
/// loses its oldest messages instead of stalling the pipeline. Received messages are parsed by
/// IgtlReceiver (header v1 and v2, CRC) and ignored; a framing error closes that client only.
class IgtlServer {
 public:
  using Message = std::shared_ptr<const std::vector<std::uint8_t>>;

  /// Binds and starts the I/O thread; IoError when the address cannot be bound.
  explicit IgtlServer(const IgtlServerOptions& options = {});
  ~IgtlServer();
  IgtlServer(const IgtlServer&) = delete;
  IgtlServer& operator=(const IgtlServer&) = delete;

  int port() const { return port_; }
  /// Queues an encoded message for every connected client. Never blocks on a socket.
  void Publish(std::vector<std::uint8_t> message);
  /// A message every client gets on connecting (after the ones already set), replacing the one
  /// set earlier under `key` (e.g. the plan, the skin, a constant calibration transform).
  /// Also published to the clients connected now.
  void SetGreeting(const std::string& key, std::vector<std::uint8_t> message);
  IgtlServerStats stats() const;

 private:
  struct Client;
  void Run();
  void Accept();
  bool ReadFrom(Client& client);
  bool WriteTo(Client& client);
  void Enqueue(Client& client, const Message& message);
  void Wake();

  IgtlServerOptions options_;
  SocketFd listener_;
  SocketFd wake_;  // eventfd
  int port_ = 0;
  mutable std::mutex mutex_;  // guards clients_, greetings_, stats_
  std::vector<std::unique_ptr<Client>> clients_;
  std::vector<std::pair<std::string, Message>> greetings_;
  IgtlServerStats stats_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace tofnav
