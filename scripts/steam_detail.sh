#!/usr/bin/env bash
# How curled the default scene's steam is: the share of its render's spectral energy above half the
# Nyquist frequency (`msim detail`), above the cup, against two references on the same camera and
# frame (480 x 640, frame 96):
#   smooth  - the steam scene before it had App. 6.C's turbulent wind: no wind, density and
#             temperature diffusion 2e-5 m^2/s, default lights, extinction 25;
#   no wind - today's scene with its turbulent wind removed (everything else unchanged).
#
#   scripts/steam_detail.sh [OUT]        (default OUT: out/steam_detail; about a minute on 2 cores)
#
# Needs the release build (make app).
set -euo pipefail
cd "$(dirname "$0")/.."
msim=build/release/bin/msim
[[ -x $msim ]] || { echo "steam_detail: $msim is missing; run 'make app' first" >&2; exit 1; }
out=${1:-out/steam_detail}
crop=(--crop 60 40 420 520)  # above the cup, inside the picture's steam column
scene=scenes/steam.json
quiet=(--set outputs.mp4=false --set outputs.png=false)

run() {  # name, msim run options...
  local name=$1
  shift
  echo "steam_detail: running $name" >&2
  "$msim" run "$scene" --out "$out/$name" "${quiet[@]}" "$@" >"$out/$name.log" 2>&1 ||
    { echo "steam_detail: the $name run failed; see $out/$name.log" >&2; exit 1; }
}

mkdir -p "$out"
run default
run no_wind --set 'winds=[]'
run smooth --set 'winds=[]' --set gas.density.diffusion=2e-5 --set gas.temperature.diffusion=2e-5 \
  --set 'render={"enabled": true, "frames": "last", "medium": {"extinction": 25.0}, "camera": {"width": 480, "height": 640}}'

share() { "$msim" detail "${crop[@]}" "$out/$1/render/steam_0096.png" | awk '{print $1}'; }
default=$(share default)
no_wind=$(share no_wind)
smooth=$(share smooth)
awk -v d="$default" -v n="$no_wind" -v s="$smooth" 'BEGIN {
  printf "fine-detail share above the cup (render, frame 96, crop 60 40 420 520)\n"
  printf "  default scene      %.3e\n", d
  printf "  without its wind   %.3e   default / this = %.1fx\n", n, d / n
  printf "  smooth reference   %.3e   default / this = %.1fx\n", s, d / s
}'
