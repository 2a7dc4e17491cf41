#!/usr/bin/env bash
# Regenerates the README's gallery pictures (docs/images/<scene>.png and render_<scene>.png) from
# the shipped scenes, so that every picture there can be made again.
#
#   scripts/make_gallery.sh [SCENE ...]     (default: every scene in the table below)
#
# Each scene runs into out/gallery/<scene> with the settings of its gallery row (frame count and
# --set overrides, listed below); the preview of its last frame becomes docs/images/<scene>.png
# and, for gases, smoke, liquids and cloth, `msim render --last` of the run (its own render keys:
# camera, lights, medium) docs/images/render_<scene>.png (2D scenes render as slabs). Needs the
# release build (make app).
# The whole table takes about 30 minutes on 2 cores, most of it the large crowds, the turbulent
# smoke and the hourglasses.
set -euo pipefail
cd "$(dirname "$0")/.."
msim=build/release/bin/msim
[[ -x $msim ]] || { echo "make_gallery: $msim is missing; run 'make app' first" >&2; exit 1; }

# scene | kind (render: preview and render; preview: preview only) | msim run options
gallery="
steam               | render  |
mushroom            | render  |
swirl_2d            | render  |
chimney_wind        | render  |
plume_3d            | render  |
plume_vortex_particles | preview | --frames 48
stream_vortex_particles | preview | --frames 48
smoke_sphere        | render  |
burning_log         | render  |
plume_2d            | render  |
obstacle_field      | render  |
moving_paddle_2d    | render  |
flow_past_circle    | render  |
smoke_turbulence    | preview | --frames 24
smoke_wake          | preview |
smoke_launch        | preview |
crowd_circle        | preview |
crowd_doorway       | preview |
crowd_building      | preview |
crowd_trade_show    | preview |
crowd_campsite      | preview |
crowd_mosque        | preview |
crowd_crossing      | preview |
crowd_mixed         | preview |
crowd_vehicle       | preview |
granular_hourglass  | preview | --frames 96
granular_hourglass_liquid | preview | --frames 96
granular_column     | preview | --frames 30 --set domain.resolution=40
granular_impacts    | preview | --set domain.resolution=50
granular_explosion  | preview | --frames 14 --set domain.resolution=40
dam_break_2d        | preview | --frames 10
dam_break_3d        | render  | --frames 10
drop_into_pool      | render  | --frames 15
wave_maker_2d       | preview | --frames 96
pour_glass          | render  | --frames 30
river_rapids        | render  | --frames 72
cloth_drape         | render  |
cloth_twist         | render  |
cloth_spinning_ball | render  |
cloth_leaves        | render  |
cloth_flag          | preview | --frames 40
solid_torus         | preview |
"

wanted=("$@")
selected() {
  [[ ${#wanted[@]} -eq 0 ]] && return 0
  local w
  for w in "${wanted[@]}"; do [[ $w == "$1" ]] && return 0; done
  return 1
}

mkdir -p docs/images out/gallery
while IFS='|' read -r scene kind options; do
  scene=$(echo "$scene" | xargs)
  kind=$(echo "$kind" | xargs)
  [[ -z $scene ]] && continue
  selected "$scene" || continue
  out=out/gallery/$scene
  echo "== $scene ($kind) $options"
  # shellcheck disable=SC2086  # the options are words
  $msim run "scenes/$scene.json" --out "$out" -q --set outputs.mp4=false $options
  last=$(ls "$out/png/${scene}"_*.png | sort | tail -1)
  cp "$last" "docs/images/$scene.png"
  if [[ $kind == render ]]; then
    rm -rf "$out/gallery_render"
    $msim render "$out" --last -q --out "$out/gallery_render"
    cp "$out/gallery_render/$(basename "${last%.png}").png" "docs/images/render_$scene.png"
  fi
  if [[ $kind == render ]]; then
    echo "   docs/images/$scene.png and docs/images/render_$scene.png"
  else
    echo "   docs/images/$scene.png"
  fi
done <<< "$gallery"
