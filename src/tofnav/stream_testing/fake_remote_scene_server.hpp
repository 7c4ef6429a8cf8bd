// SPDX-License-Identifier: BSD-3-Clause
// A loopback stand-in for hl2ss's remote Unity scene (tests, benchmarks, figures): decodes every
// command, keeps the scene, answers like the plugin (docs/navigation.md, "Headset display").
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tofnav/stream/remote_scene_protocol.hpp"
#include "tofnav/stream/socket.hpp"

namespace tofnav {

struct FakeSceneObject {
  bool is_text = false;
  UnityPrimitive primitive = UnityPrimitive::kSphere;
  bool active = false;  // created inactive, as the plugin does
  UnityTransform transform;
  Rgba colour;
  float font_size = 0.0f;
  std::string text;
};

/// The scene as a wearer would see it after the last complete display list.
struct FakeRemoteScene {
  std::map<std::uint32_t, FakeSceneObject> objects;  // by key
  std::vector<std::uint32_t> created;                // every key handed out, in order
  std::vector<std::string> spoken;
  std::uint64_t display_lists = 0;
  std::uint64_t frame = 0;  // the plugin frame that ran the last display list (frame mode)
};

struct FakeRemoteSceneStats {
  std::uint64_t connections = 0;
  std::uint64_t commands = 0;
  std::uint64_t rejected = 0;                // answered 0: unknown key, short payload, unknown id
  std::uint64_t frames = 0;                  // plugin frames run (frame mode)
  std::uint64_t connection_first_frame = 0;  // the frame that ran the connection's first command
};

/// How closely the stand-in behaves like the real plugin over time.
struct FakeRemoteSceneOptions {
  /// 0: every command is run as it arrives (instant). > 0: the plugin's Unity frame loop: one
  /// command per frame outside a display list; inside one, every command already received, in
  /// the same frame (docs/navigation.md, "Headset display"). The real plugin runs at 60 Hz.
  double frame_rate_hz = 0.0;
  /// false: the app has no text-to-speech component, so `say` throws in the plugin and neither
  /// it nor any later command of the connection is answered.
  bool say_answers = true;
};

/// One client at a time, as the plugin: a second connection waits unanswered until the first
/// ends. Nothing is destroyed on disconnect. Keys are handed out as the plugin does (Unity
/// instance ids: negative ints as u32, never 0).
class FakeRemoteSceneServer {
 public:
  explicit FakeRemoteSceneServer(int port = 0, const FakeRemoteSceneOptions& options = {});
  ~FakeRemoteSceneServer();
  FakeRemoteSceneServer(const FakeRemoteSceneServer&) = delete;
  FakeRemoteSceneServer& operator=(const FakeRemoteSceneServer&) = delete;

  int port() const { return port_; }
  FakeRemoteScene scene() const;
  FakeRemoteSceneStats stats() const;
  /// A stalled server accepts connections but reads nothing and answers nothing (from the next
  /// command on: the thread is woken so that it stops reading at once).
  void SetStalled(bool stalled);
  /// Closes the current connection (a headset that drops off the network).
  void DropClient();
  /// Called on the server thread with the scene after every display list.
  void SetOnDisplayList(std::function<void(const FakeRemoteScene&)> callback);
  /// Waits until `count` display lists have completed; false on timeout.
  bool WaitForDisplayLists(std::uint64_t count, double timeout_s) const;

 private:
  void Run();
  void Wake();
  std::uint32_t Process(const RemoteSceneCommand& command);
  void Commit(bool end_of_display_list);
  /// Runs `command`, appends its reply to `replies` (none once the connection is mute).
  void RunCommand(const RemoteSceneCommand& command, std::vector<std::uint8_t>& replies);

  FakeRemoteSceneOptions options_;
  SocketFd listener_;
  SocketFd wake_;  // eventfd
  int port_ = 0;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  FakeRemoteScene committed_;
  FakeRemoteSceneStats stats_;
  std::function<void(const FakeRemoteScene&)> on_display_list_;
  bool stalled_ = false;
  bool drop_ = false;
  std::atomic<bool> stop_{false};
  // Server thread only.
  FakeRemoteScene working_;
  bool in_display_list_ = false;
  bool use_last_key_ = false;
  std::uint32_t last_key_ = 0;
  bool mute_ = false;  // a failed say: nothing more is answered on this connection
  std::deque<RemoteSceneCommand> pending_;  // frame mode: received, waiting for a frame
  std::uint64_t frame_ = 0;
  std::int32_t next_instance_id_ = -1200;
  std::thread thread_;
};

/// A loopback port nothing listens on: one a stand-in had, now closed (an absent headset).
int ClosedLoopbackPort();

}  // namespace tofnav
