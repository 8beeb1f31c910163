#!/usr/bin/env bash
# Two or more pt binaries alternated on the same meshes (issue 26, docs/bvh.md): each round runs
# `pt bench rays` on every mesh, with the default studio's ground and with `--studio none`, once per
# binary in an order that rotates from round to round (a fixed order favoured the last binary by
# 1-3% on this machine), and prints, per row, each binary's median and range of BVH time / Embree
# time over the rounds, then each binary's geometric mean of its row medians and its worst row.
# The ratio is taken within one process, against Embree's time on the same rays, so it tolerates
# a machine whose speed drifts between runs better than two rates would.
#
#   renderer/bench/ab_rays.sh ROUNDS THREADS LABEL=PT_BINARY LABEL=PT_BINARY... -- MESH.obj...
#
# Environment: RAYS (default 262144 per kind), PASSES (default 3), OUT (keep the raw rows there).
set -euo pipefail
[ $# -ge 4 ] || { sed -n 2,12p "$0" >&2; exit 2; }
rounds="$1" threads="$2"
shift 2
bins=()
while [ $# -gt 0 ] && [ "$1" != -- ]; do bins+=("$1"); shift; done
[ "${1:-}" = -- ] && shift
[ ${#bins[@]} -ge 1 ] && [ $# -ge 1 ] || { echo "ab_rays: give LABEL=BINARY... -- MESH..." >&2; exit 2; }
for b in "${bins[@]}"; do [ -x "${b#*=}" ] || { echo "ab_rays: no binary at ${b#*=}" >&2; exit 2; }; done
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
raw="${OUT:-$work/rows}"
: > "$raw"
n=${#bins[@]}
for r in $(seq 1 "$rounds"); do
  for mesh in "$@"; do
    for studio in sun none; do
      for i in $(seq 0 $((n - 1))); do
        b="${bins[$(((i + r) % n))]}"
        "${b#*=}" bench rays "$mesh" --studio "$studio" --threads "$threads" --rays "${RAYS:-262144}" \
          --passes "${PASSES:-3}" --csv "$work/run.csv" > "$work/run.log" 2>&1 ||
          { echo "ab_rays: ${b#*=} failed on $mesh:" >&2; tail -3 "$work/run.log" >&2; exit 1; }
        awk -F, -v label="${b%%=*}" -v mesh="$(basename "${mesh%.*}")" -v studio="$studio" -v t="$threads" \
          '$1 == "mrays_per_s" && $3 == t { print label, mesh, (studio == "sun" ? "ground" : "bare"), $2, $6 }' \
          "$work/run.csv" >> "$raw"
      done
    done
  done
  echo "ab_rays: round $r of $rounds done" >&2
done
python3 - "$raw" <<'PY'
import collections, math, statistics, sys
rows, labels = collections.defaultdict(list), []
for line in open(sys.argv[1]):
    label, mesh, ground, kind, ratio = line.split()
    if label not in labels: labels.append(label)
    rows[(mesh, ground, kind, label)].append(float(ratio))
keys = sorted({k[:3] for k in rows})
medians = collections.defaultdict(list)
print("BVH time / Embree time: median (range) over the rounds")
print(f"{'mesh':<16}{'ground':<8}{'kind':<9}" + "".join(f"{l:<20}" for l in labels))
for k in keys:
    cells = []
    for l in labels:
        v = rows.get(k + (l,), [])
        if v:
            medians[l].append((statistics.median(v), k))
            cells.append(f"{statistics.median(v):.2f} ({min(v):.2f}-{max(v):.2f})")
        else:
            cells.append("-")
    print(f"{k[0]:<16}{k[1]:<8}{k[2]:<9}" + "".join(f"{c:<20}" for c in cells))
for l in labels:
    m = medians[l]
    worst = max(m)
    print(f"{l}: geometric mean {math.exp(sum(math.log(x) for x, _ in m) / len(m)):.3f}, "
          f"worst row {worst[0]:.2f} ({' '.join(worst[1])})")
PY
