#!/usr/bin/env bash
# The BVH against Embree across mesh sizes (issue 26, docs/bvh.md "Size sweep"): generated meshes
# (`pt gen dense`, nearly equilateral) and scan-like ones (`pt gen scan`, long thin triangles, holes,
# overlapping sheets) from about 10k to 5M triangles, each as a bare OBJ with the default studio's
# ground and with `--studio none`, timed by `pt bench rays` at 1 and 2 threads. Prints one table of
# BVH time / Embree time (below 1: the BVH is faster) and the worst row. Real scanned meshes are
# added: every .obj and .ply in REAL (renderer/tools/real_meshes.sh makes them from Debian
# packages), or else the Stanford bunny of Debian's glmark2-data (69k triangles) when installed.
#
#   renderer/bench/size_sweep.sh [PT_BINARY]      (default build/renderer/pt)
#
# Environment: SIZES=small (10k-100k only) or all (default); RAYS (default 262144 per kind);
# PASSES (default 3); THREADS (default 2: both the 1- and the 2-thread rows); WORK (the folder for
# the generated meshes, default a temporary one, removed at the end); REAL (a folder of real
# meshes); CSV (also write the table); REPEAT (default 1: run the whole sweep N times, one after
# the other, and print each cell's median and its largest reading, and the worst of each; on a
# shared 2-core VM single readings of a 2-thread row spike by 0.1-0.2). With --studio none
# nothing can be sampled as a light, and the shadow rows are ambient-occlusion rays (any hit
# along the diffuse directions).
set -euo pipefail
pt="${1:-build/renderer/pt}"
[ -x "$pt" ] || { echo "size_sweep: no pt binary at $pt" >&2; exit 2; }
rays="${RAYS:-262144}"
passes="${PASSES:-3}"
repeats="${REPEAT:-1}"
[[ "$repeats" =~ ^[1-9][0-9]*$ ]] || { echo "size_sweep: REPEAT must be a positive integer, not '$repeats'" >&2; exit 2; }
threads="${THREADS:-2}"
work="${WORK:-}"
if [ -z "$work" ]; then
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi
mkdir -p "$work" || exit 1

# name, generator arguments: dense levels 5-9 (20k-5.2M), scan resolutions for ~10k-5M (8 views).
meshes=("dense-20k:dense --level 5" "dense-82k:dense --level 6" "scan-10k:scan --resolution 140"
        "scan-100k:scan --resolution 440")
if [ "${SIZES:-all}" = all ]; then
  meshes+=("dense-328k:dense --level 7" "dense-1.3M:dense --level 8" "dense-5.2M:dense --level 9"
           "scan-1M:scan --resolution 1400" "scan-5M:scan --resolution 3130")
fi

run() {  # mesh name, obj path
  local name="$1" obj="$2"
  for studio in sun none; do
    local csv="$work/$name-$studio.csv" log="$work/$name-$studio.log"
    "$pt" bench rays "$obj" --studio "$studio" --threads "$threads" --rays "$rays" --passes "$passes" --csv "$csv" \
      > "$log" 2>&1
    local tris
    tris="$(sed -n 's/.*: \([0-9]*\) triangles,.*/\1/p' "$log" | head -1)"
    local ground=yes
    [ "$studio" = none ] && ground=no
    awk -F, -v mesh="$name" -v tris="$tris" -v ground="$ground" '
      $1 == "mrays_per_s" { r[$3 "," $2] = $6; th[$3] = 1 }
      function f(x) { return x == "" ? "-" : sprintf("%.2f", x) }
      END { for (t in th) printf "%s,%s,%s,%s,%s,%s,%s\n", mesh, tris, ground, t, f(r[t ",primary"]), f(r[t ",shadow"]), f(r[t ",diffuse"]) }
    ' "$csv" | sort -t, -k4 >> "$table"
    grep -E "hit/miss|occlusion" "$log" | sed "s/^/  $name ($studio): /" >&2
  done
}

sweep() {  # one pass over every mesh into $table
  for m in "${meshes[@]}"; do
    local name="${m%%:*}" args="${m#*:}"
    local obj="$work/$name.obj"
    # shellcheck disable=SC2086
    [ -f "$obj" ] || "$pt" gen $args "$obj" > /dev/null
    run "$name" "$obj"
  done
  local bunny=/usr/share/glmark2/models/bunny.obj
  if [ -n "${REAL:-}" ]; then
    for f in "$REAL"/*.obj "$REAL"/*.ply; do
      [ -f "$f" ] || continue
      name="$(basename "$f")"
      run "real:${name%.*}" "$f"
    done
  elif [ -f "$bunny" ]; then
    run real:bunny "$bunny"
  else
    echo "size_sweep: no real scan (REAL unset, no $bunny from Debian's glmark2-data); skipped" >&2
  fi
}

header="mesh,triangles,ground,threads,primary,shadow,diffuse"
for ((rep = 1; rep <= repeats; ++rep)); do
  table="$work/sweep-$rep.csv"
  echo "$header" > "$table"
  ((repeats == 1)) || echo "size_sweep: sweep $rep of $repeats" >&2
  sweep
done
if ((repeats > 1)); then
  # Each cell's median over the sweeps (the mean of the middle two for an even count) and its
  # largest reading, rows in the first sweep's order. mawk has no sort: the readings are sorted
  # as lines first (row, column, value).
  for ((rep = 1; rep <= repeats; ++rep)); do
    awk -F, 'NR > 1 { for (k = 5; k <= 7; ++k) print $1 "," $2 "," $3 "," $4 "," k "," $k }' "$work/sweep-$rep.csv"
  done | sort -t, -k1,4 -k5,5n -k6,6g > "$work/readings.csv"
  table="$work/sweep.csv"
  awk -F, -v header="$header" '
    NR == FNR { cell = $1 "," $2 "," $3 "," $4 "," $5; v[cell, ++c[cell]] = $6; next }
    FNR == 1 { print header ",max_primary,max_shadow,max_diffuse"; next }
    function median(cell,   m) {
      m = c[cell]
      if (v[cell, 1] == "-") return "-"
      return m % 2 ? v[cell, (m + 1) / 2] : sprintf("%.2f", (v[cell, m / 2] + v[cell, m / 2 + 1]) / 2)
    }
    { k = $1 "," $2 "," $3 "," $4
      printf "%s,%s,%s,%s,%s,%s,%s\n", k, median(k ",5"), median(k ",6"), median(k ",7"),
             v[k ",5", c[k ",5"]], v[k ",6", c[k ",6"]], v[k ",7", c[k ",7"]] }' \
    "$work/readings.csv" "$work/sweep-1.csv" > "$table"
  echo
  echo "medians of $repeats sweeps; max_*: the row's largest reading"
fi
echo
column -s, -t < "$table"
awk -F, 'NR > 1 { for (k = 5; k <= 7; ++k) if ($k != "-" && $k + 0 > worst) { worst = $k + 0; row = $0; kind = k }
                  for (k = 8; k <= 10 && k <= NF; ++k) if ($k != "-" && $k + 0 > top) { top = $k + 0; toprow = $0; topkind = k } }
         END { split("primary shadow diffuse", names, " ");
               printf "\nworst row%s: %s (%s %.2f)\n", (NF > 7 ? " (medians)" : ""), row, names[kind - 4], worst
               if (top) printf "largest single reading: %s (%s %.2f)\n", toprow, names[topkind - 7], top }' "$table"
[ -n "${CSV:-}" ] && cp "$table" "$CSV"
exit 0
