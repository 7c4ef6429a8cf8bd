// SPDX-License-Identifier: BSD-3-Clause
// In-situ guidance on the headset: ComposeHeadsetScene per frame, sent to hl2ss's remote Unity
// scene by a background thread (docs/navigation.md, "Headset display").
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "tofnav/stream/headset_scene.hpp"
#include "tofnav/stream/remote_scene_client.hpp"

namespace tofnav {

/// What the headset may be showing once the last push has arrived: what a supervisor needs to
/// clean up after a process that ended without Close (docs/navigation.md 6.6).
struct HeadsetShown {
  bool anything = false;          // this run's holograms exist on the headset (hidden or not)
  std::optional<Hologram> panel;  // the text panel where it was last visible, if ever
};

struct HeadsetDisplayOptions {
  std::string host = "127.0.0.1";
  int port = kRemoteScenePort;
  HeadsetSceneOptions scene;
  double min_move_mm = 0.1;        // smaller moves of a hologram are not sent
  double min_turn_rad = 0.001745;  // 0.1 deg
  double io_timeout_s = 0.5;       // bound of a connect, a push and its results
  double reconnect_interval_s = 1.0;
  double speech_interval_s = 2.0;  // the same phrase is not repeated sooner
  /// No Update() for this long [s] (the navigation loop stalled): the holograms hide, so the
  /// wearer never sees a pose older than this.
  double expire_after_s = 0.1;
  /// Called once per notice, on the sender thread: the headset cannot speak, or another client
  /// holds the remote scene (one line each, for the user; docs/navigation.md 6.4).
  std::function<void(const std::string&)> on_notice;
  /// Called on the sender thread before every push (what the headset may show from then on, even
  /// if this process dies before the answer), and after Close removed the holograms (anything
  /// false): a supervisor's record of what is left to clear.
  std::function<void(const HeadsetShown&)> on_shown;
  void Check() const;  // throws PreconditionError naming the bad field
};

struct HeadsetDisplayStats {
  std::uint64_t updates = 0;        // Update() calls
  std::uint64_t display_lists = 0;  // pushes of changed holograms
  std::uint64_t commands = 0;       // commands pushed (all kinds)
  std::uint64_t unchanged = 0;      // updates with nothing to send
  std::uint64_t dropped = 0;        // updates replaced by a newer one or lost while disconnected
  std::uint64_t expired = 0;        // scenes hidden because no update came for expire_after_s
  std::uint64_t too_old = 0;        // scenes hidden because their pose aged past max_pose_age_s
  /// Largest age of a shown pose when its display list was built (just before the push): the
  /// state's reference age plus the time since Update() [s]; never above max_pose_age_s.
  double max_shown_pose_age_s = 0.0;
  std::uint64_t connections = 0;
  std::uint64_t connect_failures = 0;
  std::uint64_t disconnects = 0;  // a push or its results failed or timed out
  std::uint64_t spoken = 0;
  bool connected = false;
  bool speech_available = true;  // false once the speech probe went unanswered
  bool cleared = false;          // Close removed this run's holograms (or none were created)
  std::string last_error;
  std::vector<std::string> notices;  // each said once (on_notice)
};

/// Shows the plan and the instrument on the headset. Update() composes the frame's scene and
/// leaves it in a one-slot mailbox (the latest wins); a sender thread connects (and reconnects
/// every reconnect_interval_s), creates the holograms, and pushes only what changed, as one
/// display list per update. Update never waits on the network, so a slow or absent headset only
/// loses updates. Holograms hide when the pose is not fresh and when no update came for
/// expire_after_s; speech says "reference lost" and "on target" once per change.
class HeadsetDisplay {
 public:
  HeadsetDisplay(std::vector<Trajectory> plan, const HeadsetDisplayOptions& options);
  ~HeadsetDisplay();
  HeadsetDisplay(const HeadsetDisplay&) = delete;
  HeadsetDisplay& operator=(const HeadsetDisplay&) = delete;

  /// Called once per frame on the navigation thread; cheap and non-blocking.
  void Update(const NavigationState& state);
  /// Lines above the panel's from the next Update on (navigation thread; tofnav verify).
  void SetPanelNote(PanelNote note) { note_ = std::move(note); }
  /// Removes the holograms (one push, bounded by io_timeout_s) and stops the sender. Idempotent.
  void Close();
  /// Waits until every update so far has been handled (sent, found unchanged, or dropped); for
  /// tests and tools. False on timeout.
  bool WaitUntilHandled(double timeout_s);
  HeadsetDisplayStats stats() const;

 private:
  using Clock = std::chrono::steady_clock;
  struct Post {
    HeadsetScene scene;
    std::vector<std::string> speech;
    Clock::time_point posted_at;
    std::uint64_t sequence = 0;
  };
  void Run();
  void Handle(Post post);
  /// The commands that take the headset's hologram `key` from `have` to `want`; `next` becomes
  /// what it will show (key 0 in the plugin's last-key target mode).
  void AppendChanges(RemoteSceneCommands& c, std::uint32_t key, const Hologram& have,
                     const Hologram& want, Hologram& next) const;
  void Disconnect(const std::string& error);
  /// Says `what` once through on_notice and records it.
  void Notice(const std::string& what);
  /// After the first connect: one empty `say`, then the words `held` back for it; unanswered,
  /// speech is off (and the connection, which the plugin no longer answers, is made again).
  void ProbeSpeech(const std::vector<std::string>& held);
  void RemoveHolograms();
  /// Reports what the headset may show now through on_shown.
  void ReportShown(bool anything);
  void SpeakOnChange(const HeadsetScene& scene, const NavigationState& state,
                     std::vector<std::string>& speech);

  std::vector<Trajectory> plan_;
  HeadsetDisplayOptions options_;
  // Navigation thread only.
  PanelNote note_;
  bool was_shown_ = false;
  bool speech_probed_ = false;  // sender thread
  bool speech_off_ = false;
  bool second_client_noticed_ = false;
  double held_backoff_s_ = 0.0;  // sender thread: the retry delay while another client holds it
  GuidanceLevel last_level_ = GuidanceLevel::kNoGuidance;
  std::optional<Clock::time_point> said_lost_at_, said_on_target_at_;
  // Shared, guarded by mutex_.
  mutable std::mutex mutex_;
  std::condition_variable wake_, handled_;
  std::optional<Post> mailbox_;
  std::uint64_t posted_ = 0, handled_sequence_ = 0;
  bool stop_ = false;
  HeadsetDisplayStats stats_;
  // Sender thread only.
  std::unique_ptr<RemoteSceneClient> client_;
  std::optional<Clock::time_point> next_connect_at_;
  std::vector<std::uint32_t> keys_;     // per slot, valid while connected
  std::vector<Hologram> shown_;         // what the headset shows per slot
  Clock::time_point last_posted_at_{};  // of the scene shown
  bool expired_ = false;
  std::optional<Hologram> last_panel_;  // the text panel where it was last visible
  bool created_any_ = false;            // holograms made by this run may be on the headset
  std::thread thread_;
};

}  // namespace tofnav
