#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The main job: installs the Debian packages, builds Release, then runs `tofnav demo`, the paper
# end to end on the real head CT of Debian's invesalius-examples (the synthetic head without it):
# f_rf, identification, reconstruction, registration, tracking and guidance, the paper's tables
# beside ours, every artefact and report.html in the output folder (docs/demo.md).
# Usage: scripts/demo.sh [output folder] [tofnav demo options...] (default folder: out/demo)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
shift || true
scripts/setup.sh
scripts/build.sh release -DCMAKE_BUILD_TYPE=Release >/dev/null
build/release/apps/cli/tofnav demo --out "$out" "$@"
