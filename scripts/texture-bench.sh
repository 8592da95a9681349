#!/usr/bin/env bash
# What textures cost a frame: the conference room with a 1024 x 1024 texture on every
# material (scripts/textured-conference.py) against the same room with each texture
# replaced by its mean colour (`texture = false`), iv+ds+il and canonical at 180 VPLs,
# at 800x600 and 1920x1080. On the GPU machine, from the repository root:
#
#   IGI=target/release/igi SHARED=../shared OUT=bench-out scripts/texture-bench.sh
#
# SHARED needs scenes/conference; the generated scene goes to $OUT/textured-conference
# (about 60 MB). Writes $OUT/textures-{800x600,1920x1080}/results.{json,csv,md}.
set -euo pipefail
IGI=${IGI:-target/release/igi}
SHARED=${SHARED:-../shared}
OUT=${OUT:-bench-out}
FRAMES=${FRAMES:-20}
root=$(cd "$(dirname "$0")/.." && pwd)
scene=$OUT/textured-conference
mkdir -p "$OUT"
[ -f "$scene/textured.toml" ] || python3 "$root/scripts/textured-conference.py" "$SHARED/scenes/conference" "$scene"
for size in 800x600 1920x1080; do
  "$IGI" bench "$scene/textured.toml" "$scene/averaged.toml" --vpls 180 \
    --setups iv+ds+il,canonical --width "${size%x*}" --height "${size#*x}" \
    --frames "$FRAMES" --warmup 3 --out "$OUT/textures-$size" --quiet
done
