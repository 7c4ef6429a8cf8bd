// SPDX-License-Identifier: BSD-3-Clause
// HeadsetDisplay: latest-wins mailbox, sender thread, change detection and speech
// (docs/navigation.md, "Headset display").
#include "tofnav/stream/headset_display.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/stream/socket.hpp"

namespace tofnav {
namespace {

constexpr Rgba kNeverSent{-1.0f, -1.0f, -1.0f, -1.0f};
// Retries of a headset held by another client double from reconnect_interval_s up to this [s].
constexpr double kHeldMaxBackoffS = 8.0;

std::chrono::steady_clock::duration Duration(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(s));
}

bool Keyed(RemoteSceneCommandId id) {
  return id == RemoteSceneCommandId::kSetActive || id == RemoteSceneCommandId::kSetWorldTransform ||
         id == RemoteSceneCommandId::kSetColour || id == RemoteSceneCommandId::kSetText;
}

}  // namespace

void HeadsetDisplayOptions::Check() const {
  scene.Check();
  Require(!host.empty(), "HeadsetDisplayOptions.host must not be empty");
  Require(port >= 1 && port <= 65535, "HeadsetDisplayOptions.port must be in 1..65535");
  Require(min_move_mm >= 0.0 && min_turn_rad >= 0.0,
          "HeadsetDisplayOptions: min_move_mm and min_turn_rad must be >= 0");
  Require(io_timeout_s > 0.0 && expire_after_s > 0.0 && reconnect_interval_s >= 0.0 &&
              speech_interval_s >= 0.0,
          "HeadsetDisplayOptions: timeouts must be > 0 and intervals >= 0");
}

HeadsetDisplay::HeadsetDisplay(std::vector<Trajectory> plan, const HeadsetDisplayOptions& options)
    : plan_(std::move(plan)), options_(options) {
  options_.Check();
  thread_ = std::thread([this] { Run(); });
}

HeadsetDisplay::~HeadsetDisplay() { Close(); }

void HeadsetDisplay::Update(const NavigationState& state) {
  HeadsetScene scene = ComposeHeadsetScene(state, plan_, options_.scene, note_);
  std::vector<std::string> speech;
  SpeakOnChange(scene, state, speech);
  const std::lock_guard lock(mutex_);
  ++stats_.updates;
  if (mailbox_) {  // not taken yet: the newer scene wins, the words are kept
    ++stats_.dropped;
    speech.insert(speech.begin(), mailbox_->speech.begin(), mailbox_->speech.end());
  }
  mailbox_ = Post{std::move(scene), std::move(speech), Clock::now(), ++posted_};
  wake_.notify_one();
}

void HeadsetDisplay::SpeakOnChange(const HeadsetScene& scene, const NavigationState& state,
                                   std::vector<std::string>& speech) {
  const Clock::time_point now = Clock::now();
  const auto may_say = [&](std::optional<Clock::time_point>& said_at) {
    if (said_at && now - *said_at < Duration(options_.speech_interval_s)) return false;
    said_at = now;
    return true;
  };
  if (was_shown_ && !scene.shown && state.status == NavigationStatus::kReferenceLost &&
      may_say(said_lost_at_)) {
    speech.emplace_back("reference lost");
  }
  const GuidanceLevel level =
      scene.shown && !scene.settling ? scene.level : GuidanceLevel::kNoGuidance;
  if (level == GuidanceLevel::kOnTarget && last_level_ != GuidanceLevel::kOnTarget &&
      may_say(said_on_target_at_)) {
    speech.emplace_back("on target");
  }
  was_shown_ = scene.shown;
  last_level_ = level;
}

void HeadsetDisplay::Run() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    // Wakes for a post, or twice per expire_after_s to hide a scene no update refreshes.
    wake_.wait_for(lock, Duration(0.5 * options_.expire_after_s),
                   [&] { return stop_ || mailbox_.has_value(); });
    if (stop_) break;
    if (mailbox_) {
      Post post = std::move(*mailbox_);
      mailbox_.reset();
      const std::uint64_t sequence = post.sequence;
      lock.unlock();
      Handle(std::move(post));
      lock.lock();
      handled_sequence_ = std::max(handled_sequence_, sequence);
      handled_.notify_all();
      continue;
    }
    const bool visible =
        std::any_of(shown_.begin(), shown_.end(), [](const Hologram& h) { return h.visible; });
    if (!visible || expired_ ||
        Clock::now() - last_posted_at_ <= Duration(options_.expire_after_s)) {
      continue;
    }
    ++stats_.expired;
    Post hide{
        ComposeHeadsetScene(NavigationState{}, plan_, options_.scene), {}, last_posted_at_, 0};
    lock.unlock();
    Handle(std::move(hide));
    lock.lock();
    expired_ = true;
  }
  lock.unlock();
  RemoveHolograms();
}

void HeadsetDisplay::Handle(Post post) {
  const bool connecting = !client_;
  if (connecting) {  // at most one attempt per reconnect interval
    const Clock::time_point now = Clock::now();
    if (next_connect_at_ && now < *next_connect_at_) {
      const std::lock_guard lock(mutex_);
      ++stats_.dropped;
      return;
    }
    next_connect_at_ = now + Duration(options_.reconnect_interval_s);
  }
  if (post.sequence != 0) {
    last_posted_at_ = post.posted_at;
    expired_ = false;
  }
  // The pose's age when it reaches the headset: never show one older than max_pose_age_s.
  const double age_s =
      post.scene.pose_age_s + std::chrono::duration<double>(Clock::now() - post.posted_at).count();
  if (post.scene.shown && age_s > options_.scene.max_pose_age_s) {
    post.scene = ComposeHeadsetScene(NavigationState{}, plan_, options_.scene);
    const std::lock_guard lock(mutex_);
    ++stats_.too_old;
  }
  // One display list, so that the plugin shows the whole change in one of its frames. On
  // connecting it also clears what an earlier run left and creates every hologram, each set up
  // right after its creation through the plugin's last-key target mode (docs/navigation.md 6).
  RemoteSceneCommands c;
  c.BeginDisplayList();
  std::vector<Hologram> next;
  std::vector<std::size_t> created_at;  // command index of each hologram's creation
  if (connecting) {
    c.RemoveAll();
    c.SetTargetMode(1);
    for (const Hologram& want : post.scene.holograms) {
      created_at.push_back(c.count());
      if (want.shape == HologramShape::kText) {
        c.CreateText();
      } else {
        c.CreatePrimitive(want.shape == HologramShape::kSphere ? UnityPrimitive::kSphere
                                                               : UnityPrimitive::kCylinder);
      }
      Hologram created = want;  // created inactive, nothing sent yet
      created.visible = false;
      created.colour = kNeverSent;
      next.push_back(created);
      AppendChanges(c, 0, created, want, next.back());
    }
    c.SetTargetMode(0);
  } else {
    next = shown_;
    for (std::size_t s = 0; s < next.size(); ++s) {
      AppendChanges(c, keys_[s], shown_[s], post.scene.holograms[s], next[s]);
    }
  }
  // Words wait for the speech probe after a first connect: a `say` the app cannot answer would
  // leave the whole display list unanswered.
  const bool speak_now = speech_probed_ && !speech_off_;
  if (speak_now) {
    for (const std::string& words : post.speech) c.Say(words);
  }
  c.EndDisplayList();
  if (!connecting && c.count() == 2) {
    const std::lock_guard lock(mutex_);
    ++stats_.unchanged;
    return;
  }
  bool answered = false;
  try {
    if (connecting) {
      client_ =
          std::make_unique<RemoteSceneClient>(options_.host, options_.port, options_.io_timeout_s);
    }
    // Recorded before the push: once the plugin has the display list the holograms are on the
    // headset, even if this process dies before the answer comes back.
    const Hologram& panel = next[TextPanelSlot(plan_.size())];
    if (panel.visible) last_panel_ = panel;
    created_any_ = true;
    ReportShown(true);
    const std::vector<std::uint32_t> results = client_->Push(c);
    answered = true;
    for (std::size_t i = 0; i < results.size(); ++i) {
      if (Keyed(c.ids()[i]) && results[i] == 0) {
        throw IoError(client_->endpoint(), std::nullopt,
                      "command " + std::to_string(static_cast<std::uint32_t>(c.ids()[i])) +
                          " was rejected (the scene was reset?)");
      }
    }
    if (connecting) {
      keys_.clear();
      for (const std::size_t at : created_at) keys_.push_back(results[at]);
      if (std::find(keys_.begin(), keys_.end(), 0u) != keys_.end()) {
        throw IoError(client_->endpoint(), std::nullopt, "the headset could not create a hologram");
      }
    }
  } catch (const std::exception& e) {
    if (connecting) {
      // Connected, then no answer: the plugin serves one client at a time.
      const bool unanswered = client_ != nullptr && !answered;
      client_.reset();
      keys_.clear();
      if (unanswered) {  // retried ever less often (not a reconnect loop) until it is free
        held_backoff_s_ =
            std::min(held_backoff_s_ > 0.0 ? 2.0 * held_backoff_s_ : options_.reconnect_interval_s,
                     kHeldMaxBackoffS);
        next_connect_at_ = Clock::now() + Duration(held_backoff_s_);
      }
      if (unanswered && !second_client_noticed_) {
        second_client_noticed_ = true;
        char line[256];
        std::snprintf(line, sizeof line,
                      "the headset accepted the connection but answered nothing within %g s: "
                      "another client (a second tofnav, hl2ss's viewer) holds its remote scene; "
                      "retrying after %g s, then ever less often (at most every %g s)",
                      options_.io_timeout_s, options_.reconnect_interval_s, kHeldMaxBackoffS);
        Notice(line);
      }
      const std::lock_guard lock(mutex_);
      ++stats_.connect_failures;
      ++stats_.dropped;
      stats_.last_error = e.what();
      return;
    }
    Disconnect(e.what());
    const std::lock_guard lock(mutex_);
    ++stats_.dropped;
    return;
  }
  shown_ = std::move(next);
  {
    const std::lock_guard lock(mutex_);
    if (connecting) {
      ++stats_.connections;
      stats_.connected = true;
      held_backoff_s_ = 0.0;
    }
    if (post.scene.shown) {
      stats_.max_shown_pose_age_s = std::max(stats_.max_shown_pose_age_s, age_s);
    }
    ++stats_.display_lists;
    stats_.commands += c.count();
    stats_.spoken += speak_now ? post.speech.size() : 0;
  }
  if (connecting && !speech_probed_)
    ProbeSpeech(speak_now ? std::vector<std::string>{} : post.speech);
}

void HeadsetDisplay::ReportShown(bool anything) {
  if (options_.on_shown) options_.on_shown(HeadsetShown{anything, last_panel_});
}

void HeadsetDisplay::ProbeSpeech(const std::vector<std::string>& held) {
  speech_probed_ = true;
  RemoteSceneCommands probe;
  probe.Say("");
  try {
    client_->Push(probe);
    if (!held.empty()) {
      RemoteSceneCommands words;
      for (const std::string& w : held) words.Say(w);
      client_->Push(words);
      const std::lock_guard lock(mutex_);
      stats_.spoken += held.size();
    }
  } catch (const IoError& e) {
    // Only an unanswered `say` means an app without speech; a connection that closed or failed
    // is a lost headset (probed again on the next connect).
    const auto* network = dynamic_cast<const NetworkError*>(&e);
    if (network == nullptr || network->failure() != NetworkFailure::kTimeout) {
      speech_probed_ = false;
      Disconnect(e.what());
      return;
    }
    speech_off_ = true;
    Disconnect(e.what());
    next_connect_at_.reset();  // reconnect with the next update, without speech
    {
      const std::lock_guard lock(mutex_);
      stats_.speech_available = false;
    }
    Notice(
        "the headset app does not answer 'say' (no text-to-speech component): speech is off, "
        "the panel's text only");
  }
}

void HeadsetDisplay::Notice(const std::string& what) {
  {
    const std::lock_guard lock(mutex_);
    stats_.notices.push_back(what);
  }
  if (options_.on_notice) options_.on_notice(what);
}

void HeadsetDisplay::AppendChanges(RemoteSceneCommands& c, std::uint32_t key, const Hologram& have,
                                   const Hologram& want, Hologram& next) const {
  if (!HologramChanged(have, want, options_.min_move_mm, options_.min_turn_rad)) return;
  if (!want.visible) {
    if (have.visible) c.SetActive(key, false);
    next.visible = false;
    return;
  }
  const bool moved =
      !have.visible || HologramMoved(have, want, options_.min_move_mm, options_.min_turn_rad);
  if (moved) c.SetWorldTransform(key, HologramTransform(want, options_.scene.up_in_world));
  if (want.shape == HologramShape::kText) {
    if (want.text != have.text || !(want.colour == have.colour)) {
      c.SetText(key, options_.scene.font_size, want.colour, want.text);
    }
  } else if (!(want.colour == have.colour)) {
    c.SetColour(key, want.colour);
  }
  if (!have.visible) c.SetActive(key, true);
  next = want;
  if (!moved) {  // keep what the headset shows, so small drifts add up to a send
    next.a_in_world = have.a_in_world;
    next.b_in_world = have.b_in_world;
  }
}

void HeadsetDisplay::Disconnect(const std::string& error) {
  client_.reset();
  keys_.clear();
  shown_.clear();
  next_connect_at_ = Clock::now() + Duration(options_.reconnect_interval_s);
  const std::lock_guard lock(mutex_);
  ++stats_.disconnects;
  stats_.connected = false;
  stats_.last_error = error;
}

void HeadsetDisplay::RemoveHolograms() {
  if (!client_) return;
  RemoteSceneCommands c;
  c.BeginDisplayList();
  for (const std::uint32_t key : keys_) c.Remove(key);
  c.EndDisplayList();
  try {
    client_->Push(c);
  } catch (const IoError& e) {
    Disconnect(e.what());
    return;
  }
  client_.reset();
  created_any_ = false;
  ReportShown(false);
  const std::lock_guard lock(mutex_);
  stats_.connected = false;
}

void HeadsetDisplay::Close() {
  {
    const std::lock_guard lock(mutex_);
    if (stop_ && !thread_.joinable()) return;
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  const std::lock_guard lock(mutex_);
  stats_.cleared = !created_any_;
  handled_sequence_ = posted_;
  handled_.notify_all();
}

bool HeadsetDisplay::WaitUntilHandled(double timeout_s) {
  std::unique_lock lock(mutex_);
  return handled_.wait_for(lock, Duration(timeout_s), [&] { return handled_sequence_ >= posted_; });
}

HeadsetDisplayStats HeadsetDisplay::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace tofnav
