#!/usr/bin/env bash
# The BVH build figure of docs/BENCHMARKS.md (issue "Fast": <= 100 ms on the 2-core
# machine) in one command, on the CPU machine:
#
#   scripts/build-bench.sh [ROUNDS] [BIN...]
#
# For each binary of the bvh_build example (default: target/release/examples/bvh_build,
# built first), ROUNDS rounds (default 8) in turn, each the median of 5 builds in one
# process (`bvh_build SCENE 5 --build-only`); then ROUNDS single builds, each in a new
# process (what `igi render` pays: fresh memory, cold caches). With two or more
# binaries the rounds alternate between them and the median of each round's ratio to the
# first binary is printed too: the machine's speed swings 1.5x within minutes, so only
# paired rounds compare binaries. SCENE defaults to the conference room of ../shared.
set -euo pipefail
ROUNDS=${1:-8}
shift || true
SCENE=${SCENE:-../shared/scenes/conference/scene.toml}
if [ $# -eq 0 ]; then
  cargo build --release -q -p igi-core --example bvh_build
  set -- target/release/examples/bvh_build
fi
[ -f "$SCENE" ] || { echo "build-bench: no scene at $SCENE (set SCENE)" >&2; exit 1; }
median() { sort -n | awk '{v[NR]=$1} END {printf "%.3f\n", (NR % 2) ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2}'; }
build_ms() { "$1" "$SCENE" "$2" --build-only | awk '/^build: median/ {print $3}'; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "$(date -u +%FT%TZ) $(nproc) cores, scene $SCENE"
for r in $(seq "$ROUNDS"); do
  first=""
  for k in $(seq $#); do
    bin=${!k}
    ms=$(build_ms "$bin" 5)
    echo "$ms" >>"$tmp/rounds-$k"
    if [ -z "$first" ]; then first=$ms; fi
    awk -v a="$ms" -v b="$first" 'BEGIN {printf "%.4f\n", a / b}' >>"$tmp/ratio-$k"
  done
done
for r in $(seq "$ROUNDS"); do
  for k in $(seq $#); do build_ms "${!k}" 1 >>"$tmp/single-$k"; done
done
for k in $(seq $#); do
  echo "${!k}:"
  echo "  rounds of 5 builds, medians (sorted): $(sort -n "$tmp/rounds-$k" | tr '\n' ' ')-> median $(median <"$tmp/rounds-$k") ms"
  echo "  single builds in new processes (sorted): $(sort -n "$tmp/single-$k" | tr '\n' ' ')-> median $(median <"$tmp/single-$k") ms"
  if [ "$k" -gt 1 ]; then
    echo "  paired ratio to the first binary, median of rounds: $(median <"$tmp/ratio-$k")"
  fi
done
