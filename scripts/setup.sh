#!/usr/bin/env bash
# Install DepoTwin's dependencies from Debian 12 packages. Idempotent: installs only what
# is missing (running `apt-get update` first in that case). Nothing is downloaded from
# elsewhere and nothing is vendored.
set -euo pipefail

packages=(
  cmake g++ make pkg-config
  libmujoco-dev libqhull-dev libgl-dev   # MuJoCo 2.2.2 (+ what its CMake config needs)
  libeigen3-dev libosmesa6-dev
  libgtest-dev libbenchmark-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev liblemon-dev
  libassimp-dev                          # STL import (toolpath/stl)
  libembree-dev                          # ray casting onto a part's surface (toolpath/surface_projection)
  libfcl-dev                             # arm-to-part clearance (collision/)
  zlib1g-dev                             # PNG writing (core/png)
  libstb-dev                             # tests read the PNGs back with stb_image
  gnuplot-nox                            # plots (pngcairo terminal, headless)
  fonts-dejavu-core                      # fonts for plot and image text
  ffmpeg                                 # run.mp4 (render/video: raw frames piped to its H.264 encoder)
  libglfw3-dev                           # the `view` window (viewer/)
  xvfb xauth                             # the viewer's screenshot test runs under xvfb-run
  libsqlite3-dev                         # sweep results (results.sqlite)
  parallel                               # sweeps through GNU parallel (sweep --emit parallel)
  slurmctld slurmd slurm-client munge    # sweeps on Slurm arrays; scripts/slurm-local.sh
  clang libclang-rt-14-dev               # sanitizer build and libFuzzer targets (scripts/sanitize.sh, fuzz.sh)
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
  "${missing[@]}"
echo "setup: done"
