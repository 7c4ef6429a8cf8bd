// SPDX-License-Identifier: BSD-3-Clause
// Test-only OpenIGTLink client written against Debian's libopenigtlink 1.11 (as a v1 peer).
#pragma once

#include <igtlClientSocket.h>
#include <igtlMessageHeader.h>
#include <igtlStringMessage.h>
#include <igtlTransformMessage.h>

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <thread>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav::testing {

/// One message as 1.11 decodes it: type, device name and, for TRANSFORM and STRING, the content
/// (unpacked with the CRC check on).
struct ReceivedMessage {
  std::string type;
  std::string device_name;
  bool crc_ok = false;
  std::optional<Rigid3d> transform;
  std::string text;
};

class IgtlTestClient {
 public:
  explicit IgtlTestClient(int port) : socket_(igtl::ClientSocket::New()) {
    connected_ = socket_->ConnectToServer("127.0.0.1", port) == 0;
    socket_->SetReceiveTimeout(5000);  // a hang fails the test instead of blocking it
  }
  ~IgtlTestClient() { socket_->CloseSocket(); }
  bool connected() const { return connected_; }

  void Send(const std::vector<std::uint8_t>& bytes) {
    socket_->Send(bytes.data(), static_cast<int>(bytes.size()));
  }

  /// The next message; nullopt on close or timeout.
  std::optional<ReceivedMessage> Receive() {
    igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
    header->InitPack();
    if (socket_->Receive(header->GetPackPointer(), header->GetPackSize()) !=
        header->GetPackSize()) {
      return std::nullopt;
    }
    header->Unpack();
    ReceivedMessage out;
    out.type = header->GetDeviceType();
    out.device_name = header->GetDeviceName();
    if (out.type == "TRANSFORM") {
      igtl::TransformMessage::Pointer m = igtl::TransformMessage::New();
      if (!ReadBody(header, m)) return std::nullopt;
      out.crc_ok = (m->Unpack(1) & igtl::MessageHeader::UNPACK_BODY) != 0;
      igtl::Matrix4x4 matrix;
      m->GetMatrix(matrix);
      Eigen::Matrix4d e = Eigen::Matrix4d::Identity();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) e(r, c) = matrix[r][c];
      }
      out.transform = Rigid3d::FromMatrix(e, 1e-3);
    } else if (out.type == "STRING") {
      igtl::StringMessage::Pointer m = igtl::StringMessage::New();
      if (!ReadBody(header, m)) return std::nullopt;
      out.crc_ok = (m->Unpack(1) & igtl::MessageHeader::UNPACK_BODY) != 0;
      out.text = m->GetString();
    } else {
      igtl::MessageBase::Pointer m = igtl::MessageBase::New();
      if (!ReadBody(header, m)) return std::nullopt;
      out.crc_ok = true;
    }
    return out;
  }

  /// Receives until `match` accepts a message (at most `limit` messages).
  std::optional<ReceivedMessage> ReceiveUntil(
      const std::function<bool(const ReceivedMessage&)>& match, int limit = 10000) {
    for (int i = 0; i < limit; ++i) {
      auto m = Receive();
      if (!m) return std::nullopt;
      if (match(*m)) return m;
    }
    return std::nullopt;
  }

 private:
  template <typename M>
  bool ReadBody(igtl::MessageHeader::Pointer& header, M& message) {
    message->SetMessageHeader(header);
    message->AllocatePack();
    const int size = message->GetPackBodySize();
    return size == 0 || socket_->Receive(message->GetPackBodyPointer(), size) == size;
  }

  igtl::ClientSocket::Pointer socket_;
  bool connected_ = false;
};

/// Polls `done` every millisecond, for up to ~10 s (generous: a condition, not a timing check).
inline bool WaitFor(const std::function<bool()>& done) {
  for (int i = 0; i < 10000; ++i) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return done();
}

}  // namespace tofnav::testing
