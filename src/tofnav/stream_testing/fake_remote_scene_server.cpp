// SPDX-License-Identifier: BSD-3-Clause
// FakeRemoteSceneServer: poll() over the listener, an eventfd and one client; commands are
// applied like the Unity plugin applies them (docs/navigation.md, "Headset display").
#include "tofnav/stream_testing/fake_remote_scene_server.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>

#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr const char* kSource = "fake remote scene";

Rgba ReadColour(ByteReader& r) {
  Rgba c;
  c.r = r.Le<float>("r");
  c.g = r.Le<float>("g");
  c.b = r.Le<float>("b");
  c.a = r.Le<float>("a");
  return c;
}

}  // namespace

FakeRemoteSceneServer::FakeRemoteSceneServer(int port, const FakeRemoteSceneOptions& options)
    : options_(options) {
  listener_ = ListenTcp("127.0.0.1", port);
  port_ = LocalPort(listener_);
  wake_ = SocketFd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  if (!wake_.valid()) throw IoError(kSource, std::nullopt, "eventfd failed");
  thread_ = std::thread([this] { Run(); });
}

FakeRemoteSceneServer::~FakeRemoteSceneServer() {
  stop_ = true;
  Wake();
  thread_.join();
}

FakeRemoteScene FakeRemoteSceneServer::scene() const {
  const std::lock_guard lock(mutex_);
  return committed_;
}

FakeRemoteSceneStats FakeRemoteSceneServer::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

void FakeRemoteSceneServer::SetStalled(bool stalled) {
  {
    const std::lock_guard lock(mutex_);
    stalled_ = stalled;
  }
  Wake();  // the poll in progress must not read the client any more
}

void FakeRemoteSceneServer::Wake() {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_.get(), &one, sizeof(one));
}

void FakeRemoteSceneServer::DropClient() {
  {
    const std::lock_guard lock(mutex_);
    drop_ = true;
  }
  Wake();
}

void FakeRemoteSceneServer::SetOnDisplayList(std::function<void(const FakeRemoteScene&)> callback) {
  const std::lock_guard lock(mutex_);
  on_display_list_ = std::move(callback);
}

bool FakeRemoteSceneServer::WaitForDisplayLists(std::uint64_t count, double timeout_s) const {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                           [&] { return committed_.display_lists >= count; });
}

void FakeRemoteSceneServer::Commit(bool end_of_display_list) {
  std::function<void(const FakeRemoteScene&)> callback;
  {
    const std::lock_guard lock(mutex_);
    if (end_of_display_list) working_.frame = frame_;
    committed_ = working_;
    callback = on_display_list_;
  }
  // The callback first: a waiter woken by the count then sees what the callback recorded.
  if (callback && end_of_display_list) callback(working_);
  changed_.notify_all();
}

std::uint32_t FakeRemoteSceneServer::Process(const RemoteSceneCommand& command) {
  ByteReader r(command.payload, kSource);
  const auto key_of = [&]() -> FakeSceneObject* {
    const std::uint32_t key = r.Le<std::uint32_t>("key");
    const auto found = working_.objects.find(use_last_key_ ? last_key_ : key);
    return found == working_.objects.end() ? nullptr : &found->second;
  };
  const auto add = [&](FakeSceneObject object) {
    const auto key = static_cast<std::uint32_t>(next_instance_id_);
    next_instance_id_ -= 2;
    working_.objects[key] = std::move(object);
    working_.created.push_back(key);
    last_key_ = key;
    return key;
  };
  try {
    switch (static_cast<RemoteSceneCommandId>(command.id)) {
      case RemoteSceneCommandId::kCreatePrimitive: {
        const std::uint32_t type = r.Le<std::uint32_t>("type");
        FakeSceneObject o;
        o.primitive = type <= 4 ? static_cast<UnityPrimitive>(type) : UnityPrimitive::kQuad;
        return add(o);
      }
      case RemoteSceneCommandId::kCreateText: {
        FakeSceneObject o;
        o.is_text = true;
        return add(o);
      }
      case RemoteSceneCommandId::kSetActive: {
        FakeSceneObject* o = key_of();
        if (o == nullptr) return 0;
        o->active = r.Le<std::uint32_t>("state") != 0;
        return 1;
      }
      case RemoteSceneCommandId::kSetWorldTransform: {
        FakeSceneObject* o = key_of();
        if (o == nullptr) return 0;
        float f[10];
        for (float& v : f) v = r.Le<float>("transform");
        o->transform.position_m = {f[0], f[1], f[2]};
        o->transform.rotation = Eigen::Quaternionf(f[6], f[3], f[4], f[5]);
        o->transform.scale = {f[7], f[8], f[9]};
        return 1;
      }
      case RemoteSceneCommandId::kSetColour: {
        FakeSceneObject* o = key_of();
        if (o == nullptr) return 0;
        o->colour = ReadColour(r);
        return 1;
      }
      case RemoteSceneCommandId::kSetText: {
        FakeSceneObject* o = key_of();
        if (o == nullptr || !o->is_text) return 0;
        o->font_size = r.Le<float>("font size");
        o->colour = ReadColour(r);
        const auto bytes = r.Take(r.remaining(), "text");
        o->text.assign(bytes.begin(), bytes.end());
        return 1;
      }
      case RemoteSceneCommandId::kSay:
        working_.spoken.emplace_back(command.payload.begin(), command.payload.end());
        return 1;
      case RemoteSceneCommandId::kRemove: {
        const std::uint32_t key = r.Le<std::uint32_t>("key");
        return working_.objects.erase(use_last_key_ ? last_key_ : key) > 0 ? 1 : 0;
      }
      case RemoteSceneCommandId::kRemoveAll:
        working_.objects.clear();
        return 1;
      case RemoteSceneCommandId::kBeginDisplayList:
        in_display_list_ = true;
        return 1;
      case RemoteSceneCommandId::kEndDisplayList:
        in_display_list_ = false;
        ++working_.display_lists;
        return 1;
      case RemoteSceneCommandId::kSetTargetMode:
        use_last_key_ = r.Le<std::uint32_t>("mode") != 0;
        return 1;
    }
  } catch (const IoError&) {  // a short payload: the plugin answers 0
  }
  return 0;
}

void FakeRemoteSceneServer::RunCommand(const RemoteSceneCommand& c,
                                       std::vector<std::uint8_t>& replies) {
  if (mute_) return;
  if (c.id == static_cast<std::uint32_t>(RemoteSceneCommandId::kSay) && !options_.say_answers) {
    mute_ = true;  // the plugin's handler threw: no reply, now or later
    return;
  }
  const std::uint32_t result = Process(c);
  for (int byte = 0; byte < 4; ++byte) {  // little-endian u32
    replies.push_back(static_cast<std::uint8_t>(result >> (8 * byte)));
  }
  {
    const std::lock_guard lock(mutex_);
    ++stats_.commands;
    if (result == 0) ++stats_.rejected;
    if (stats_.connection_first_frame == 0) stats_.connection_first_frame = frame_;
  }
  if (!in_display_list_) {
    Commit(c.id == static_cast<std::uint32_t>(RemoteSceneCommandId::kEndDisplayList));
  }
}

void FakeRemoteSceneServer::Run() {
  using Clock = std::chrono::steady_clock;
  const bool framed = options_.frame_rate_hz > 0.0;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(framed ? 1.0 / options_.frame_rate_hz : 1.0));
  Clock::time_point next_frame = Clock::now() + period;
  SocketFd client;
  std::vector<std::uint8_t> received;
  std::uint8_t buffer[65536];
  while (!stop_) {
    bool stalled = false;
    {
      const std::lock_guard lock(mutex_);
      stalled = stalled_;
      if (drop_) client.Close();
      drop_ = false;
    }
    // One client at a time: while one is connected, the next waits in the listen backlog.
    pollfd fds[3] = {{client.valid() ? -1 : listener_.get(), POLLIN, 0},
                     {wake_.get(), POLLIN, 0},
                     {-1, POLLIN, 0}};
    if (client.valid() && !stalled) fds[2].fd = client.get();
    int timeout_ms = stalled ? 20 : 200;
    if (framed) {
      timeout_ms = static_cast<int>(std::clamp<std::int64_t>(
          std::chrono::duration_cast<std::chrono::milliseconds>(next_frame - Clock::now()).count(),
          0, timeout_ms));
    }
    if (::poll(fds, 3, timeout_ms) < 0 && errno != EINTR) break;
    if (framed && Clock::now() >= next_frame) {  // one Unity frame of the plugin
      next_frame = std::max(next_frame + period, Clock::now());
      ++frame_;
      {
        const std::lock_guard lock(mutex_);
        stats_.frames = frame_;
      }
      std::vector<std::uint8_t> replies;
      if (!stalled && !pending_.empty()) {
        do {
          RunCommand(pending_.front(), replies);
          pending_.pop_front();
        } while (in_display_list_ && !pending_.empty());
      }
      try {
        if (client.valid() && !replies.empty()) WriteAll(client, replies, kSource);
      } catch (const IoError&) {
        client.Close();
      }
    }
    if ((fds[1].revents & POLLIN) != 0) {
      std::uint64_t count = 0;
      [[maybe_unused]] const ssize_t n = ::read(wake_.get(), &count, sizeof(count));
    }
    if ((fds[0].revents & POLLIN) != 0) {
      SocketFd accepted(::accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC));
      if (accepted.valid()) {
        client = std::move(accepted);  // the plugin's disconnect message: reset the modes
        received.clear();
        pending_.clear();
        in_display_list_ = use_last_key_ = mute_ = false;
        const std::lock_guard lock(mutex_);
        ++stats_.connections;
        stats_.connection_first_frame = 0;
      }
    }
    if (fds[2].fd < 0 || (fds[2].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
    {
      const std::lock_guard lock(mutex_);
      if (stalled_) continue;  // stalled while polling
    }
    const ssize_t n = ::recv(client.get(), buffer, sizeof(buffer), 0);
    if (n <= 0) {
      client.Close();
      continue;
    }
    received.insert(received.end(), buffer, buffer + n);
    std::vector<std::uint8_t> results;
    try {
      for (RemoteSceneCommand& c : TakeRemoteSceneCommands(received, kSource)) {
        if (framed) {
          pending_.push_back(std::move(c));
        } else {
          RunCommand(c, results);
        }
      }
      if (!results.empty()) WriteAll(client, results, kSource);
    } catch (const IoError&) {
      client.Close();
    }
  }
}

int ClosedLoopbackPort() {
  const FakeRemoteSceneServer gone;
  return gone.port();
}

}  // namespace tofnav
