// SPDX-License-Identifier: BSD-3-Clause
// Patient heads named by a scenario or on the command line: phantom, a skin mesh or a real CT.
#pragma once

#include <filesystem>
#include <string>

#include "tofnav/sim/head_phantom.hpp"
#include "tofnav/sim/patient.hpp"

namespace tofnav {

/// "phantom" (the built-in one, with `phantom` options), "mesh:<path>" (a closed skin mesh in CT
/// LPS mm, upright) or "ct:<path>" (any volume ReadVolume reads: the skin is extracted with the
/// CT defaults of ExtractSkin, the image's noise taken out of it by SmoothPhysicalSkin for the
/// rendered patient, and the simulator writes that CT as the pre-operative image).
/// Relative paths are taken from `base`. IoError for unreadable files, PreconditionError for a
/// spec of none of these forms.
sim::PatientHead LoadPatientHead(const std::string& spec, const std::filesystem::path& base = {},
                                 const sim::HeadPhantomOptions& phantom = {});

/// The volume path of a head source "ct:<path>" (as LoadPatientHead records it), or empty.
std::filesystem::path CtPathOfHeadSource(const std::string& source);

}  // namespace tofnav
