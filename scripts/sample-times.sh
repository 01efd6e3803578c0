#!/usr/bin/env bash
# Times every built-in sample run headless with the one command the README gives,
#   flurry run NAME --png DIR --vdb DIR
# (the effect's own frame count; a 1280x720 PNG and a VDB file every 10th frame and the
# last, --every's default; hair's VDB once when it is static) and
# prints a Markdown table: frames, wall seconds of the whole command (start, Xvfb, steps,
# rendering, writing) and the CPU seconds it used (user + system, all threads), the wall
# seconds of the same run without outputs (`flurry run NAME --quiet`: the simulation's
# share), particles alive at the end and emitted in all (strands for hair), the PNG and VDB
# files written, their size, and where the time went: the tool's own measurements of a PNG
# (render + encode, on the simulation thread) and of a VDB file (built and written on the
# export thread), per file. Then the totals. A run of a minute or more is marked
# "OVER A MINUTE". Builds the `flurry` tool only (Release); the frames go to a temporary
# folder, removed after each sample (with --vdb-every 1 the VDB files of one run can take
# gigabytes: FLURRY_RUN_ARGS="--vdb-every 1" measures that).
#
#   bash scripts/sample-times.sh                 # every sample
#   bash scripts/sample-times.sh fountain smoke  # only those
#   FLURRY_RUN_ARGS="--vdb-every 1" bash scripts/sample-times.sh    # other `flurry run` options
#   bash scripts/sample-times.sh --gallery       # also replace the table in docs/gallery.md
#
# docs/gallery.md's last section, "Run times", is this script's table (--gallery replaces
# it, and keeps the notes written under it); scripts/gallery.sh keeps the whole section when
# it rewrites the page.
set -euo pipefail
cd "$(dirname "$0")/.."
gallery=0
names=()
for a in "$@"; do
  if [ "$a" = --gallery ]; then gallery=1; else names+=("$a"); fi
done
cmake --preset release >/dev/null 2>&1
cmake --build --preset release -j "$(nproc)" --target flurry_cli >/dev/null
flurry=build/release/bin/flurry
if [ ${#names[@]} -eq 0 ]; then mapfile -t names < <("$flurry" list | awk '{print $1}'); fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

model=$(awk -F': ' '/^model name/ { n = $2 } /^cpu family/ { f = $2 } /^model[[:space:]]*:/ { m = $2 }
  /^flags/ { v = $2 ~ /hypervisor/ ? ", virtual" : "" } END { print n ", family " f " model " m v }' /proc/cpuinfo)
command="flurry run NAME --png DIR --vdb DIR${FLURRY_RUN_ARGS:+ $FLURRY_RUN_ARGS}"
table="$tmp/table.md"
{
  echo "\`bash scripts/sample-times.sh\` ($(date -u +%Y-%m-%d)): \`$command\`, Release build,"
  echo "on $(nproc) cores ($model), load average $(cut -d' ' -f1-3 /proc/loadavg) at the start."
  echo
  echo "| sample | frames | wall s | CPU s | no output s | alive | emitted | strands | PNG | VDB | MB | PNG ms | VDB ms |"
  echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
} >"$table"
total=0
cputotal=0
over=()
for name in "${names[@]}"; do
  dir="$tmp/$name"
  log="$tmp/$name.log"
  mkdir -p "$dir"
  # Wall, user and system seconds of the command (bash's `time`, children included).
  TIMEFORMAT='%R %U %S'
  # shellcheck disable=SC2086  # FLURRY_RUN_ARGS is a list of options
  if ! { time "$flurry" run "$name" --png "$dir/png" --vdb "$dir/vdb" ${FLURRY_RUN_ARGS:-} \
    >"$log" 2>&1; } 2>"$tmp/time"; then
    cat "$log" >&2
    echo "sample-times: $name failed" >&2
    exit 1
  fi
  read -r wall cpu < <(awk '{ printf "%.1f %.1f\n", $1, $2 + $3 }' "$tmp/time")
  # The same run without outputs: the simulation's share.
  # shellcheck disable=SC2086
  { time "$flurry" run "$name" --quiet ${FLURRY_RUN_ARGS:-} >/dev/null 2>&1; } 2>"$tmp/time"
  bare=$(awk '{ printf "%.1f", $1 }' "$tmp/time")
  # Each group's summary: "GROUP: 300 steps in 1.234 s; emitted E = alive A + ...".
  read -r frames alive emitted < <(awk '
    / steps in .*; emitted [0-9]+ = alive [0-9]+ / {
      for (i = 1; i <= NF; ++i) {
        if ($i == "steps") f = $(i - 1)
        if ($i == "emitted") e += $(i + 1)
        if ($i == "alive") a += $(i + 1)
      }
    }
    END { print f, a, e }' "$log")
  # The last frame's per-group lines: "frame  300 ... strands S (V vertices)".
  strands=$(awk -v f="$frames" '$1 == "frame" && $2 == f {
      for (i = 1; i <= NF; ++i) if ($i == "strands") s += $(i + 1) }
    END { print s + 0 }' "$log")
  # The tool's own timings: a PNG frame ("render R ms, PNG P ms per frame"), a VDB file
  # ("M ms/frame on the export thread").
  pngms=$(sed -n 's/.*(render \([0-9.]*\) ms, PNG \([0-9.]*\) ms per frame).*/\1 \2/p' "$log" |
    awk '{ printf "%.0f", $1 + $2 }')
  vdbms=$(sed -n 's/.* s: \([0-9.]*\) ms\/frame on the export thread.*/\1/p' "$log" |
    awk '{ printf "%.0f", $1 }')
  png=$(find "$dir/png" -name '*.png' | wc -l)
  vdb=$(find "$dir/vdb" -name '*.vdb' | wc -l)
  mb=$(du -sm "$dir" | cut -f1)
  note=""
  if awk -v w="$wall" 'BEGIN { exit !(w >= 60) }'; then
    note=" OVER A MINUTE"
    over+=("$name")
  fi
  echo "| $name | $frames | $wall$note | $cpu | $bare | $alive | $emitted | $strands | $png | $vdb | $mb | ${pngms:--} | ${vdbms:--} |" >>"$table"
  echo "sample-times: $name: $frames frames in $wall s" >&2
  total=$(awk -v t="$total" -v w="$wall" 'BEGIN { printf "%.1f", t + w }')
  cputotal=$(awk -v t="$cputotal" -v c="$cpu" 'BEGIN { printf "%.1f", t + c }')
  rm -rf "$dir"
done
echo "| total (${#names[@]} samples) | | $total | $cputotal | | | | | | | | | |" >>"$table"
{
  echo
  echo -n "Load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)."
  if [ ${#over[@]} -gt 0 ]; then echo " Over a minute: ${over[*]}."; else echo " All under a minute."; fi
} >>"$table"
cat "$table"

if [ "$gallery" = 1 ]; then
  # Replace the page's "## Run times" section up to the end-of-table marker (the notes
  # written under it stay), or add the section at the end.
  page=docs/gallery.md
  marker='<!-- end of the sample-times.sh table: notes below stay -->'
  {
    echo "## Run times"
    echo
    cat "$table"
    echo
    echo "$marker"
  } >"$tmp/section.md"
  if grep -qx '## Run times' "$page"; then
    awk -v section="$tmp/section.md" -v marker="$marker" '
      $0 == "## Run times" { while ((getline l < section) > 0) print l; skip = 1; next }
      skip && $0 == marker { skip = 0; next }
      !skip { print }' "$page" >"$tmp/page.md"
    cat "$tmp/page.md" >"$page"
  else
    cat "$tmp/section.md" >>"$page"
  fi
  echo "sample-times: updated $page" >&2
fi
