#!/usr/bin/env bash
# The ray-throughput figures of docs/BENCHMARKS.md (issue "Fast": >= 2.5x OptiX on the
# same GPU and the same rays) in one command, for the GPU machine:
#
#   IGI=target/release/igi SHARED=../shared OUT=rays-out ROUNDS=2 \
#     MITSUBA_SITE=/path/to/site-packages scripts/rays-bench.sh
#
# Makes the three ray files of the tables (16.8 M random segments and 16.8 M random rays
# on the all-diffuse conference room, the VPL shadow rays of a canonical 800 x 600 frame
# of the conference room with 180 VPLs asked), traces each ROUNDS times with igi (10
# timed runs each, the median reported) and, when Mitsuba 3 imports (from MITSUBA_SITE
# if set: see shared/tools/mitsuba-for-device.sh), with OptiX through
# shared/tools/optix_peer.py in the same call, then once more with igi. Prints one line
# per trace and a table of G rays/s and igi / OptiX; keeps the logs under OUT.
set -euo pipefail
IGI=${IGI:-target/release/igi}
SHARED=${SHARED:-../shared}
OUT=${OUT:-rays-out}
ROUNDS=${ROUNDS:-2}
RUNS=${RUNS:-10}
COUNT=${COUNT:-16777216}        # rays of the random sets
FRAME_OPTS=${FRAME_OPTS:---vpls 180 --count 86400000} # the frame set's options (a smaller frame for a quick check)
mkdir -p "$OUT"
conf=$SHARED/scenes/conference/scene.toml
diffuse=$SHARED/scenes/conference/conference-diffuse.toml
for f in "$conf" "$diffuse" "$SHARED/tools/optix_peer.py"; do
  [ -f "$f" ] || { echo "rays-bench: $f is missing (set SHARED)" >&2; exit 1; }
done
# name | scene | --kind | options that make the set
sets=(
  "random-segments|$diffuse|shadow|--set random --count $COUNT"
  "frame-shadow-rays|$conf|shadow|--set frame $FRAME_OPTS"
  "random-rays-closest|$diffuse|closest|--set random --count $COUNT"
)
"$IGI" info | tee "$OUT/info.txt"
for s in "${sets[@]}"; do
  IFS='|' read -r name scene kind opts <<<"$s"
  # shellcheck disable=SC2086 # opts are words on purpose
  "$IGI" bench rays "$scene" --kind "$kind" $opts --save "$OUT/$name.bin" --runs 1 >"$OUT/$name-make.txt" 2>&1 ||
    { cat "$OUT/$name-make.txt" >&2; exit 1; }
done
# "median 7.204 ms over 10 runs" and the ray count -> G rays/s
igi_trace() { # name scene kind label
  local log=$OUT/$1-igi-$4.txt
  "$IGI" bench rays "$2" --load "$OUT/$1.bin" --kind "$3" --runs "$RUNS" >"$log" 2>&1 ||
    { cat "$log" >&2; exit 1; }
  local line
  line=$(grep -E '^(shadow|closest)' "$log")
  echo "igi $4 $1: $line"
  awk '{for (i = 1; i < NF; i++) { if ($i ~ /^rays,?$/ && !n) n = $(i - 1); if ($i == "median") ms = $(i + 1) }}
       END {printf "%.4f\n", n / (ms * 1e6)}' <<<"$line" >>"$OUT/$1.igi"
}
for r in $(seq "$ROUNDS"); do
  for s in "${sets[@]}"; do IFS='|' read -r name scene kind _ <<<"$s"; igi_trace "$name" "$scene" "$kind" "round$r"; done
done
peer=""
if PYTHONPATH=${MITSUBA_SITE:-} python3 -c 'import mitsuba' 2>/dev/null; then
  peer=yes
  for s in "${sets[@]}"; do
    IFS='|' read -r name scene kind _ <<<"$s"
    PYTHONPATH=${MITSUBA_SITE:-} python3 "$SHARED/tools/optix_peer.py" "$scene" "$OUT/$name.bin" --kind "$kind" \
      >"$OUT/$name-optix.txt" 2>&1 || { cat "$OUT/$name-optix.txt" >&2; exit 1; }
    echo "optix $name: $(tail -1 "$OUT/$name-optix.txt")"
    tail -1 "$OUT/$name-optix.txt" | python3 -c 'import json, sys; print("%.4f" % (json.load(sys.stdin)["rays_per_s"] / 1e9))' >"$OUT/$name.optix"
  done
  # igi once more after OptiX: the GPU's clocks after a different load.
  for s in "${sets[@]}"; do IFS='|' read -r name scene kind _ <<<"$s"; igi_trace "$name" "$scene" "$kind" "after-optix"; done
else
  echo "rays-bench: Mitsuba 3 does not import (set MITSUBA_SITE): igi only" >&2
fi
echo
{
echo "| ray set | igi, G rays/s (each trace) | OptiX, G rays/s | igi (median) / OptiX |"
echo "|---|---|---|---|"
for s in "${sets[@]}"; do
  IFS='|' read -r name _ _ _ <<<"$s"
  runs=$(tr '\n' ' ' <"$OUT/$name.igi")
  med=$(sort -n "$OUT/$name.igi" | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}')
  if [ -n "$peer" ]; then
    o=$(cat "$OUT/$name.optix")
    echo "| $name | $runs| $o | $(awk -v a="$med" -v b="$o" 'BEGIN {printf "%.2fx", a / b}') |"
  else
    echo "| $name | $runs| - | - |"
  fi
done
} | tee "$OUT/table.md"
