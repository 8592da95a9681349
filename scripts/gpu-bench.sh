#!/usr/bin/env bash
# The benchmark table of docs/BENCHMARKS.md in one command, for the GPU machine.
#
# Run from the repository root where the release binary and the shared scenes and
# references are at hand (defaults: target/release/igi and ../shared):
#   IGI=target/release/igi SHARED=../shared OUT=bench-out scripts/gpu-bench.sh
# Through the device tool: carry the binary, .gl and a copy of shared/scenes and
# shared/references in an ignored folder, and point SHARED at it (see docs/BENCHMARKS.md).
set -euo pipefail
IGI=${IGI:-target/release/igi}
SHARED=${SHARED:-../shared}
OUT=${OUT:-bench-out}
FRAMES=${FRAMES:-10}
SETUPS=${SETUPS:-canonical,iv,iv+ds,iv+ds+il,iv+ds+il+irregular,iv+ds+il+fused}
mkdir -p "$OUT"
"$IGI" info
for scene in conference/scene.toml conference/conference-diffuse.toml cornell-box/scene.toml; do
  name=$(basename "$(dirname "$scene")")-$(basename "$scene" .toml)
  "$IGI" bench "$SHARED/scenes/$scene" --vpls 30,90,180 --setups "$SETUPS" \
    --frames "$FRAMES" --warmup 3 --out "$OUT/$name" --quiet
done
# The issue-6 targets: all accelerations at 1920x1080 too.
"$IGI" bench "$SHARED/scenes/conference/scene.toml" --vpls 180 --setups canonical,iv+ds+il \
  --width 1920 --height 1080 --frames "$FRAMES" --warmup 3 --out "$OUT/conference-1080p" --quiet
