#!/usr/bin/env bash
# Re-makes every CSV, chart and table of docs/README.md from a Release build in build/.
# References (long renders, stored and reused) go to $PT_REFS (default build/refs).
# About 15 minutes on 2 cores, most of it the 4096-spp references.
#   bash docs/make_charts.sh [all|cornell|hex|rays|stability]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
pt="$root/build/renderer/pt"
plot=(/usr/bin/python3 "$root/renderer/tools/plot_bench.py")
out="$root/docs/data"
refs="${PT_REFS:-$root/build/refs}"
mkdir -p "$out" "$refs"
what="${1:-all}"

converge() {  # name scene reference-name args...
  local name="$1" scene="$2" ref="$3"
  shift 3
  "$pt" bench converge "$scene" --reference "$refs/$ref.exr" --reference-spp 4096 --csv "$out/$name.csv" -q "$@"
  "${plot[@]}" "$out/$name.csv" -o "$out/$name.png" --title "$name" > /dev/null
}

if [[ "$what" == all || "$what" == cornell ]]; then
  # Path tracing: which backend and which sampler reach a given error first.
  converge cornell-path scenes/cornell-box cornell-path-256 --res 256x256 --integrator path --max-depth 8 \
    --backend embree,bvh --sampler sobol,independent --min-spp 4 --max-spp 256
  # Direct lighting: light, BSDF and MIS sampling, 1 and 4 shadow rays per hit.
  converge cornell-direct scenes/cornell-box cornell-direct-256 --res 256x256 --integrator direct \
    --strategy light,bsdf,mis --shadow-rays 1,4 --sampler sobol --min-spp 4 --max-spp 256
fi

if [[ "$what" == all || "$what" == hex ]]; then
  converge hex-path scenes/hex-room hex-path-256 --res 256x192 --integrator path --max-depth 12 \
    --backend embree,bvh --sampler sobol,independent --min-spp 4 --max-spp 256
  converge hex-direct scenes/hex-room hex-direct-256 --res 256x192 --integrator direct \
    --strategy light,bsdf,mis --shadow-rays 1,4 --sampler sobol --min-spp 4 --max-spp 256
fi

if [[ "$what" == all || "$what" == rays ]]; then
  [ -f scenes/dense/dense.obj ] || "$pt" gen dense scenes/dense/dense.obj
  "$pt" bench rays scenes/dense --csv "$out/rays-dense.csv" | tee "$out/rays-dense.txt"
  "${plot[@]}" "$out/rays-dense.csv" -o "$out/rays-dense.png" --title "scenes/dense"
  "$pt" bench rays scenes/cornell-box --csv "$out/rays-cornell.csv" | tee "$out/rays-cornell.txt"
  "${plot[@]}" "$out/rays-cornell.csv" -o "$out/rays-cornell.png" --title "scenes/cornell-box"
fi

if [[ "$what" == all || "$what" == stability ]]; then
  "$pt" bench stability --csv "$out/stability.csv" | tee "$out/stability.txt"
  "${plot[@]}" "$out/stability.csv" -o "$out/stability.png"
fi
