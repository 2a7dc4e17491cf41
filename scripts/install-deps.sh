#!/usr/bin/env bash
# Installs the Debian packages msim builds and runs with. Idempotent: packages already present
# are skipped, and apt-get is not touched at all when nothing is missing.
# Usage: scripts/install-deps.sh [--check]   (--check: only report what is missing; exit 1 if any)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config ccache
  libtbb-dev libeigen3-dev nlohmann-json3-dev libcli11-dev libspdlog-dev libfmt-dev
  libpng-dev libopenexr-dev libopenvdb-dev libboost-dev libboost-iostreams-dev libgtest-dev libgmock-dev libbenchmark-dev libkissfft-dev libxxhash-dev
  libopenmpi-dev openmpi-bin libhypre-dev  # MPI runs (msim/parallel): OpenMPI (BSD) and hypre (Apache-2.0 or MIT)
  ffmpeg
  libopenvdb-tools  # vdb_print: the tests check that OpenVDB's own tools read msim's frames
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
if [[ "${1:-}" == "--check" ]]; then
  echo "install-deps: missing: ${missing[*]}"
  exit 1
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
