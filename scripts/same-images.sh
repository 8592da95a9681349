#!/usr/bin/env bash
# Do two igi binaries render the same images, bit for bit? For proving that a refactor
# changes no pixel: build today's main and the branch, then
#
#   scripts/same-images.sh OLD_IGI NEW_IGI [OUTDIR]
#
# Each binary renders, on the adapter `igi info` picks (the software Vulkan adapter on a
# machine without a GPU; IGI_ADAPTER=INDEX|NAME passes `--adapter`), the built-in Cornell
# box and the shared scenes (SHARED, default ../shared from the repository root: the
# Cornell box, the conference room and its all-diffuse variant) at small sizes, with
# --setup canonical and --setup iv+ds+il, and for the conference room (which has mirrors)
# iv+ds+il with --filter fused too, writing linear EXR. Each pair of EXRs is compared byte
# for byte (cmp): one line per image, `same` or `DIFFERENT` (or `FAILED` where a render
# failed, with its log). Exits 0 when every pair is the same, 1 otherwise, 2 on bad usage.
# The images and logs stay in OUTDIR (default: a temporary folder, removed on success).
# About 2-4 minutes on a 2-core machine with the software adapter.
set -euo pipefail

usage() {
  cat >&2 <<'EOF'
usage: scripts/same-images.sh OLD_IGI NEW_IGI [OUTDIR]
  Renders the built-in and shared scenes with both igi binaries and compares the EXRs
  byte for byte. Environment: SHARED (default ../shared from the repository root),
  IGI_ADAPTER (passed as --adapter). Exit status: 0 all same, 1 any different or failed.
EOF
  exit 2
}

[ $# -ge 2 ] && [ $# -le 3 ] || usage
case "$1" in -h|--help) usage ;; esac
old=$1
new=$2
for bin in "$old" "$new"; do
  [ -x "$bin" ] && [ -f "$bin" ] || { echo "same-images: $bin is not an executable file" >&2; usage; }
done

root=$(cd "$(dirname "$0")/.." && pwd)
SHARED=${SHARED:-$root/../shared}
scenes=$SHARED/scenes
for f in "$scenes/cornell-box/scene.toml" "$scenes/conference/scene.toml" \
  "$scenes/conference/conference-diffuse.toml"; do
  [ -f "$f" ] || { echo "same-images: $f is missing (set SHARED)" >&2; exit 2; }
done

if [ $# -eq 3 ]; then
  out=$3
  mkdir -p "$out"
  keep=1
else
  out=$(mktemp -d "${TMPDIR:-/tmp}/same-images.XXXXXX")
  keep=0
fi
mkdir -p "$out/old" "$out/new"
# lavapipe warns on every start without a runtime directory.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
adapter=()
[ -n "${IGI_ADAPTER:-}" ] && adapter=(--adapter "$IGI_ADAPTER")

# name | scene arguments | size | setup arguments
cases=(
  "cornell-builtin-canonical|--builtin cornell-box|160 120|--setup canonical"
  "cornell-builtin-ivdsil|--builtin cornell-box|160 120|--setup iv+ds+il"
  "cornell-box-canonical|$scenes/cornell-box/scene.toml|160 120|--setup canonical"
  "cornell-box-ivdsil|$scenes/cornell-box/scene.toml|160 120|--setup iv+ds+il"
  "conference-canonical|$scenes/conference/scene.toml|200 150|--setup canonical"
  "conference-ivdsil|$scenes/conference/scene.toml|200 150|--setup iv+ds+il"
  "conference-ivdsil-fused|$scenes/conference/scene.toml|200 150|--setup iv+ds+il --filter fused"
  "conference-diffuse-canonical|$scenes/conference/conference-diffuse.toml|200 150|--setup canonical"
  "conference-diffuse-ivdsil|$scenes/conference/conference-diffuse.toml|200 150|--setup iv+ds+il"
)

start=$(date +%s)
bad=0
for c in "${cases[@]}"; do
  IFS='|' read -r name scene size setup <<<"$c"
  read -r w h <<<"$size"
  failed=0
  for side in old new; do
    if [ "$side" = old ]; then bin=$old; else bin=$new; fi
    # shellcheck disable=SC2086 # scene and setup are word lists on purpose
    if ! "$bin" render $scene --width "$w" --height "$h" $setup "${adapter[@]}" \
      --exr "$out/$side/$name.exr" >"$out/$side/$name.log" 2>&1; then
      failed=1
      echo "FAILED     $name ($side: see $out/$side/$name.log)"
    fi
  done
  if [ "$failed" = 1 ]; then
    bad=1
  elif cmp -s "$out/old/$name.exr" "$out/new/$name.exr"; then
    echo "same       $name"
  else
    echo "DIFFERENT  $name"
    bad=1
  fi
done

secs=$(( $(date +%s) - start ))
if [ "$bad" = 0 ] && [ "$keep" = 0 ]; then
  rm -rf "$out"
  echo "same-images: every image the same (${secs} s)"
elif [ "$bad" = 0 ]; then
  echo "same-images: every image the same (${secs} s); images and logs in $out"
else
  echo "same-images: some images differ or failed (${secs} s); images and logs in $out" >&2
fi
exit "$bad"
