// SPDX-License-Identifier: BSD-3-Clause
// Empty: the target that owns this file exists to build a precompiled header that the libraries
// or the unit tests reuse (cmake/tofnav_targets.cmake, TOFNAV_PCH).
