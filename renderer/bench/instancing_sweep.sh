#!/usr/bin/env bash
# Instancing against flattening, by number of copies: load, build and render seconds and peak
# memory of a field of N copies of one scan-like mesh (`pt gen instances ... .glb`), on both
# backends, instanced for every N and flattened (baked into world space) where it fits. One CSV row
# per run; the chart is docs/instancing_chart.py's.
#   bash renderer/bench/instancing_sweep.sh build/renderer/pt OUT_DIR [COUNTS] [FLAT_COUNTS]
# Defaults: COUNTS "1 10 100 1000 10000 100000", FLAT_COUNTS "1 10 100", a 71k-triangle mesh,
# 320x180 at 4 spp (direct lighting under the default studio), 2 threads.
set -euo pipefail
pt="$(realpath "$1")"
out="$2"
counts="${3:-1 10 100 1000 10000 100000}"
flat_counts="${4:-1 10 100}"
mkdir -p "$out"
cd "$out"
[ -f scan70k.obj ] || "$pt" gen scan scan70k.obj --resolution 370 2> /dev/null
csv=instancing.csv
echo "copies,mode,backend,triangles_placed,load_s,build_s,render_s,peak_mb" > "$csv"
run() {  # copies mode file
  local copies="$1" mode="$2" file="$3" backend
  for backend in embree bvh; do
    local log
    log=$( { /usr/bin/time -f "peak_kb %M" "$pt" render "$file" --backend "$backend" --res 320x180 --spp 4 \
             --threads 2 --timing -q -o "run-$backend.exr"; } 2>&1 )
    local t peak
    t=$(grep -o 'load [0-9.e-]* build [0-9.e-]* render [0-9.e-]*' <<< "$log" | awk '{print $2","$4","$6}')
    peak=$(awk '/peak_kb/ {printf "%.1f", $2 / 1024}' <<< "$log")
    echo "$copies,$mode,$backend,$((copies * 71223)),$t,$peak" | tee -a "$csv"
  done
}
for n in $counts; do
  "$pt" gen instances "field-$n.glb" --mesh scan70k.obj --count "$n" 2> /dev/null
  run "$n" instanced "field-$n.glb"
  rm -f "field-$n.glb"
done
for n in $flat_counts; do
  "$pt" gen instances "flat-$n.glb" --mesh scan70k.obj --count "$n" --flatten 2> /dev/null
  run "$n" flattened "flat-$n.glb"
  rm -f "flat-$n.glb"
done
echo "wrote $out/$csv"
