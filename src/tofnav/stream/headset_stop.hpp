// SPDX-License-Identifier: BSD-3-Clause
// The headset after navigation ended without clearing it: every hologram removed and one red
// "NAVIGATION STOPPED" panel where the guidance panel was (docs/navigation.md 6.6).
#pragma once

#include <optional>
#include <string>

#include "tofnav/stream/headset_display.hpp"

namespace tofnav {

/// The display list that replaces whatever the remote scene shows: remove-all, then (when
/// `last_panel` is known) one red text panel in its place saying `text`.
RemoteSceneCommands NavigationStoppedCommands(const std::optional<Hologram>& last_panel,
                                              const std::string& text,
                                              const HeadsetSceneOptions& scene);

/// Connects to the headset of `options` and pushes NavigationStoppedCommands, trying again until
/// `give_up_after_s` has passed (the plugin takes the next client once it has seen the last one
/// go). IoError naming the endpoint when it never answered.
void ShowNavigationStopped(const HeadsetDisplayOptions& options,
                           const std::optional<Hologram>& last_panel, const std::string& text,
                           double give_up_after_s = 2.0);

}  // namespace tofnav
