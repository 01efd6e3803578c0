#!/usr/bin/env bash
# Regenerates docs/gallery.md, its stills (docs/gallery/NAME.png, 480x270) and its animated
# previews (docs/gallery/NAME.gif, 320x180, 15 fps, a few hundred KB): builds the `flurry`
# tool only, runs each built-in sample headless to a frame that shows it, and keeps that
# frame; for the previews it keeps every other frame of a stretch and turns them into a GIF
# with Debian's ffmpeg (installed by `scripts/setup.sh --gallery` when missing: only the
# gallery needs it). No display needed (the renderer starts its own Xvfb). A few minutes on
# 2 cores. `bash scripts/gallery.sh NAME...` renders only those (docs/gallery.md is
# rewritten whole, but for its "Run times" section: `bash scripts/sample-times.sh --gallery`).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v ffmpeg >/dev/null; then bash scripts/setup.sh --gallery; fi
cmake --preset release >/dev/null 2>&1
cmake --build --preset release -j "$(nproc)" --target flurry_cli >/dev/null
flurry=build/release/bin/flurry
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p docs/gallery
# The page's last section, "Run times", is scripts/sample-times.sh's table: kept as it is.
sed -n '/^## Run times$/,$p' docs/gallery.md >"$tmp/times.md" 2>/dev/null || true
# name:frame — the frame each still is taken at (a moment where the effect reads best).
shots="fountain:90 fireworks:100 galaxy:120 magnetic:30 pinball2d:150 smoke:200 hair:5
       tornado:200 snow:150 shockwave:40 campfire:150 comet:120 waterfall:150
       rain_on_glass:150 grass:5 fur:5 rain:90 grinder:90"
# name:first:last — the frames each animated preview plays (every other one, at 15 fps:
# real time for the samples' 1/30 s step).
previews="fireworks:40:160 campfire:60:180 waterfall:60:180 comet:60:180"

wanted() { [ $# -eq 0 ] || [[ " $* " == *" $name "* ]]; }

# preview NAME FIRST LAST: docs/gallery/NAME.gif
preview() {
  local name=$1 first=$2 last=$3 dir="$tmp/$1.preview" seq="$tmp/$1.seq" k=0 f
  "$flurry" run "$name" --frames "$last" --png "$dir" --png-every 2 --size 320x180 \
    --quiet >/dev/null
  mkdir -p "$seq"
  for ((f = first; f <= last; f += 2)); do
    ln -s "$dir/$name.$(printf %04d "$f").png" "$seq/$(printf %04d "$k").png"
    k=$((k + 1))
  done
  # One palette for the whole clip (mostly dark: 96 colours are plenty), ordered dithering
  # (no crawling noise between frames), only the changed rectangle stored per frame.
  ffmpeg -v error -y -framerate 15 -i "$seq/%04d.png" -vf \
    "split[a][b];[a]palettegen=max_colors=96:stats_mode=diff[p];[b][p]paletteuse=dither=bayer:bayer_scale=3:diff_mode=rectangle" \
    "docs/gallery/$name.gif"
  echo "gallery: $name preview ($(du -k "docs/gallery/$name.gif" | cut -f1) KB)"
}

{
  echo "# Gallery"
  echo
  echo "The built-in effects (\`flurry list\`), each a still rendered headless by"
  echo "\`scripts/gallery.sh\` with \`flurry run NAME --frames N --png DIR --size 480x270\`,"
  echo "and for some an animated preview (320x180, real time, every other frame)."
  echo "Regenerate with \`bash scripts/gallery.sh\` after a change in a sample or in the look."
  echo
} >docs/gallery.md
for shot in $shots; do
  name=${shot%%:*}
  frame=${shot##*:}
  if wanted "$@"; then
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
  for p in $previews; do
    IFS=: read -r pname first last <<<"$p"
    if [ "$pname" = "$name" ]; then
      if wanted "$@"; then preview "$name" "$first" "$last"; fi
      {
        echo "Frames $first to $last:"
        echo
        echo "![$name, animated](gallery/$name.gif)"
        echo
      } >>docs/gallery.md
    fi
  done
  if [ "$name" = galaxy ]; then
    # The same effect with a million stars: --spawn-scale multiplies every rate, burst and
    # capacity by 150, --exposure 1/150 keeps the additive glow as bright as with 6,800.
    if wanted "$@"; then
      "$flurry" run galaxy --spawn-scale 150 --exposure 0.0067 --frames 300 --png "$tmp/million" \
        --png-every 300 --size 480x270 --quiet >"$tmp/million.log"
      cp "$tmp/million/galaxy.0300.png" docs/gallery/galaxy_million.png
      echo "gallery: galaxy_million ($(tail -n 1 "$tmp/million.log"))"
    fi
    {
      echo "A million stars: \`flurry run galaxy --spawn-scale 150 --exposure 0.0067\` (frame 300;"
      echo "\`bench_fountain --benchmark_filter=GalaxyStars\` times its step against the effect's 1/30 s)."
      echo
      echo "![galaxy, a million stars](gallery/galaxy_million.png)"
      echo
    } >>docs/gallery.md
  fi
done
cat "$tmp/times.md" >>docs/gallery.md
