// SPDX-License-Identifier: BSD-3-Clause
// NavigationStoppedCommands and its push (docs/navigation.md 6.6).
#include "tofnav/stream/headset_stop.hpp"

#include <chrono>
#include <thread>

#include "tofnav/io/io_error.hpp"

namespace tofnav {

RemoteSceneCommands NavigationStoppedCommands(const std::optional<Hologram>& last_panel,
                                              const std::string& text,
                                              const HeadsetSceneOptions& scene) {
  constexpr Rgba kStoppedRed{1.0f, 0.2f, 0.15f, 1.0f};
  RemoteSceneCommands c;
  c.BeginDisplayList();
  c.RemoveAll();
  if (last_panel) {
    Hologram notice = *last_panel;
    notice.text = text;
    c.SetTargetMode(1);  // each command below acts on the object just created
    c.CreateText();
    c.SetWorldTransform(0, HologramTransform(notice, scene.up_in_world));
    c.SetText(0, scene.font_size, kStoppedRed, notice.text);
    c.SetActive(0, true);
    c.SetTargetMode(0);
  }
  c.EndDisplayList();
  return c;
}

void ShowNavigationStopped(const HeadsetDisplayOptions& options,
                           const std::optional<Hologram>& last_panel, const std::string& text,
                           double give_up_after_s) {
  const RemoteSceneCommands c = NavigationStoppedCommands(last_panel, text, options.scene);
  const auto give_up_at =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(give_up_after_s);
  for (;;) {
    try {
      RemoteSceneClient client(options.host, options.port, options.io_timeout_s);
      const std::vector<std::uint32_t> results = client.Push(c);
      for (std::size_t i = 0; i < results.size(); ++i) {
        if (results[i] == 0) {  // every command of this list answers 1 or a key on success
          throw IoError(client.endpoint(), std::nullopt,
                        "the headset refused the 'navigation stopped' panel (command " +
                            std::to_string(static_cast<std::uint32_t>(c.ids()[i])) + ")");
        }
      }
      return;
    } catch (const IoError&) {
      if (std::chrono::steady_clock::now() >= give_up_at) throw;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
}

}  // namespace tofnav
