#!/usr/bin/env bash
# The BVH build figure over a stretch of time (issue "Fast": <= 100 ms on the 2-core
# machine), on the CPU machine:
#
#   scripts/build-sampler.sh [MINUTES] [BIN...]      (default: 60 minutes)
#
# The 2-core machine's speed changes from minute to minute (docs/lab/PERFORMANCE.md attempts
# 114 and 129: in some minutes it runs a two-thread build on one core), so one set of
# builds says little about the next hour. Every INTERVAL seconds (default 180) while
# nothing else keeps the machine busy (no compiler, a 1-minute load average under 0.6)
# this runs one set of `scripts/build-bench.sh 5 BIN...` (rounds of 5 builds in one
# process and single builds in new processes) and a round of 5 one-thread builds of the
# last BIN (RAYON_NUM_THREADS=1): that round's median over the set's two-thread rounds
# of the same binary is the speed-up the second core gave in that minute (about 1.9 with
# both cores, about 1 with one). The log is appended to LOG (default
# target/build-sampler.log); at the end (or on Ctrl-C) the pooled figures of this run's
# sets are printed: per binary the median, p90 and range of the rounds and single builds
# and how many took over 100 ms; the one-thread rounds and the speed-ups; and each set
# with a single build over 100 ms, with its speed-up.
set -euo pipefail
MINUTES=${1:-60}
shift || true
INTERVAL=${INTERVAL:-180}
LOG=${LOG:-target/build-sampler.log}
SCENE=${SCENE:-../shared/scenes/conference/scene.toml}
export SCENE
if [ $# -eq 0 ]; then
  cargo build --release -q -p igi-core --example bvh_build
  set -- target/release/examples/bvh_build
fi
[ -f "$SCENE" ] || { echo "build-sampler: no scene at $SCENE (set SCENE)" >&2; exit 1; }
for bin in "$@"; do
  [ -x "$bin" ] || { echo "build-sampler: $bin is not an executable bvh_build" >&2; exit 1; }
done
mkdir -p "$(dirname "$LOG")"
here=$(cd "$(dirname "$0")" && pwd)
last=${!#}

busy() {
  ps -eo comm= | grep -cE '^(rustc|cargo|cc1|cc1plus|ld|ld.lld|clippy-driver|rustdoc|valgrind)$' || true
}

summary() {
  python3 - "$LOG" "$last" <<'PY'
import re, statistics as st, sys
log, last = sys.argv[1], sys.argv[2]
data, one, speedup, slow, rounds_of_last = {}, [], {}, [], {}
start = binary = None
sets = 0
for line in open(log):
    if re.match(r'# \S+ build-sampler:', line):
        # A new run appended to the same log: pool this run's sets only.
        data, one, speedup, slow, rounds_of_last = {}, [], {}, [], {}
        start = binary = None
        sets = 0
        continue
    m = re.match(r'=== (\S+) load', line)
    if m:
        start, binary, sets = m.group(1), None, sets + 1
        continue
    m = re.match(r'(\S+):$', line)
    if m and start:
        binary = m.group(1)
        continue
    m = re.match(r'\s+(rounds|single)[^:]*: ([\d. ]+)-> median ([\d.]+)', line)
    if m and binary:
        values = [float(x) for x in m.group(2).split()]
        data.setdefault((binary, m.group(1)), []).extend(values)
        if m.group(1) == 'rounds' and binary == last:
            rounds_of_last[start] = float(m.group(3))
        if m.group(1) == 'single' and max(values) > 100:
            slow.append((start, binary, max(values)))
        continue
    m = re.match(r'one thread, round of 5: median ([\d.]+)', line)
    if m:
        one.append(float(m.group(1)))
        if start in rounds_of_last:
            speedup[start] = float(m.group(1)) / rounds_of_last[start]
print(f'{sets} sets in {log}')
def pct(v, q):
    return v[min(len(v) - 1, int(round(q * (len(v) - 1))))]
for (b, kind), v in sorted(data.items()):
    v.sort()
    name = 'rounds of 5 builds' if kind == 'rounds' else 'single builds'
    print(f'{b}: {name}: {len(v)}, median {st.median(v):.1f} ms, p90 {pct(v, 0.9):.1f}, '
          f'range {v[0]:.1f}-{v[-1]:.1f}, over 100 ms: {sum(x > 100 for x in v)}')
if one:
    print(f'one thread, rounds of 5: {len(one)}, median {st.median(one):.1f} ms, '
          f'range {min(one):.1f}-{max(one):.1f}')
if speedup:
    r = list(speedup.values())
    print(f'speed-up of the second core: {len(r)} sets, median {st.median(r):.2f}, '
          f'range {min(r):.2f}-{max(r):.2f}')
for start, b, ms in slow:
    su = speedup.get(start)
    print(f'set {start}: a single build of {b} took {ms:.1f} ms; the second core gave '
          + (f'{su:.2f}x' if su else 'no figure'))
PY
}
trap 'summary' EXIT

end=$(($(date +%s) + MINUTES * 60))
echo "# $(date -u +%FT%TZ) build-sampler: $MINUTES minutes, every $INTERVAL s, $(nproc) cores, scene $SCENE, binaries: $*" | tee -a "$LOG"
while [ "$(date +%s)" -lt "$end" ]; do
  load=$(cut -d' ' -f1 /proc/loadavg)
  n=$(busy)
  if [ "$n" -gt 0 ] || awk -v l="$load" 'BEGIN {exit !(l > 0.6)}'; then
    echo "--- $(date -u +%FT%TZ) skipped: $n compiler processes, load $load" >>"$LOG"
    sleep 30
    continue
  fi
  {
    echo "=== $(date -u +%FT%TZ) load $load"
    bash "$here/build-bench.sh" 5 "$@" 2>&1 | grep -v '^20[0-9][0-9]-\|WARN'
    ms=$(RAYON_NUM_THREADS=1 "$last" "$SCENE" 5 --build-only 2>/dev/null | awk '/^build: median/ {print $3}')
    echo "one thread, round of 5: median $ms ms ($last)"
  } | tee -a "$LOG"
  left=$((end - $(date +%s)))
  if [ "$left" -gt 0 ]; then sleep $((left < INTERVAL ? left : INTERVAL)); fi
done
