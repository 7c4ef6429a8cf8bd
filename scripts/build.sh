#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Configures and builds tofnav into build/<name>. Usage: scripts/build.sh <name> [cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
name=${1:-release}
shift || true
cmake -S . -B "build/$name" -G Ninja "$@" >/dev/null
ninja -C "build/$name"
