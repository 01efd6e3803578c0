#!/usr/bin/env bash
# Regenerates docs/gallery.md and its stills (docs/gallery/NAME.png, 480x270): builds the
# `flurry` tool only, runs each built-in sample headless to a frame that shows it, and keeps
# that frame. No display needed (the renderer starts its own Xvfb). About a minute on 2 cores.
# `bash scripts/gallery.sh NAME...` renders only those stills (docs/gallery.md is rewritten whole).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release >/dev/null 2>&1
cmake --build --preset release -j "$(nproc)" --target flurry_cli >/dev/null
flurry=build/release/bin/flurry
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p docs/gallery
# name:frame — the frame each still is taken at (a moment where the effect reads best).
shots="fountain:90 fireworks:100 galaxy:120 magnetic:30 pinball2d:150 smoke:200 hair:5
       tornado:200 snow:150 shockwave:40 campfire:150 comet:180 waterfall:150
       rain_on_glass:150"
{
  echo "# Gallery"
  echo
  echo "The built-in effects (\`flurry list\`), each a still rendered headless by"
  echo "\`scripts/gallery.sh\` with \`flurry run NAME --frames N --png DIR --size 480x270\`."
  echo "Regenerate with \`bash scripts/gallery.sh\` after a change in a sample or in the look."
  echo
} >docs/gallery.md
for shot in $shots; do
  name=${shot%%:*}
  frame=${shot##*:}
  if [ $# -eq 0 ] || [[ " $* " == *" $name "* ]]; then
    "$flurry" run "$name" --frames "$frame" --png "$tmp/$name" --png-every "$frame" \
      --size 480x270 --quiet >/dev/null
    cp "$tmp/$name/$name.$(printf %04d "$frame").png" "docs/gallery/$name.png"
    echo "gallery: $name ($(du -k "docs/gallery/$name.png" | cut -f1) KB)"
  fi
  description=$("$flurry" list | sed -n "s/^ *$name  *//p" | head -n 1)
  {
    echo "## $name"
    echo
    echo "$description (frame $frame)"
    echo
    echo "![$name](gallery/$name.png)"
    echo
  } >>docs/gallery.md
done
