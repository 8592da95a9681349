#!/usr/bin/env bash
# How the BVH build scales with threads on this machine's CPU (docs/lab/BENCHMARKS-history.md, "The
# BVH build on other CPUs"): for 1, 2, 4, ... threads up to the CPU count, a round of 11
# builds in one process (`bvh_build SCENE 11 --build-only`) and 5 single builds in new
# processes, each under RAYON_NUM_THREADS.
#
#   scripts/build-scaling.sh [SCENE]     (BIN=path/to/bvh_build to use a built binary)
set -euo pipefail
SCENE=${1:-../shared/scenes/conference/scene.toml}
BIN=${BIN:-}
if [ -z "$BIN" ]; then
  cargo build --release -q -p igi-core --example bvh_build
  BIN=target/release/examples/bvh_build
fi
[ -f "$SCENE" ] || { echo "build-scaling: no scene at $SCENE" >&2; exit 1; }
n=$(nproc)
echo "$(date -u +%FT%TZ) $n CPUs,$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2), scene $SCENE"
t=1
while :; do
  echo "== threads $t"
  RAYON_NUM_THREADS=$t "$BIN" "$SCENE" 11 --build-only |
    grep -E "^(threads|CPU time|build:|phases|tree hash)"
  singles=$(for i in 1 2 3 4 5; do
    RAYON_NUM_THREADS=$t "$BIN" "$SCENE" 1 --build-only | awk '/^build: median/ {print $3}'
  done | sort -n | tr '\n' ' ')
  echo "single builds in new processes (sorted): $singles"
  [ "$t" -ge "$n" ] && break
  t=$((2 * t > n ? n : 2 * t))
done
