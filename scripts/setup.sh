#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs the Debian 12 packages tofnav needs (only the missing ones). Idempotent.
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config
  libeigen3-dev libtbb-dev libzstd-dev zlib1g-dev libcli11-dev nlohmann-json3-dev libembree-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-14 clang-format-14 libclang-rt-14-dev
  libgdcm-dev                                    # io/: DICOM series
  libopenigtlink-dev                             # stream/: OpenIGTLink (1.11)
  libnanoflann-dev                               # registration/: KD-tree
  libavcodec-dev libavutil-dev                   # recording/: hl2ss H.264/H.265 AHAT (libx264/libx265)
  python3-av                                     # tests/: the PyAV oracle for the H26x profiles
  python3-numpy python3-nibabel python3-pydicom  # tests/volume_oracle.py
  python3-dev pybind11-dev python3-pytest        # python/: bindings and their tests
  invesalius-examples mricron-data               # real head CT/MR read by tests, never committed
  chromium                                       # tests/report_chromium_test.sh (headless)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "tofnav setup: installing ${missing[*]}" >&2
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "tofnav setup: need root or sudo to install packages" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
