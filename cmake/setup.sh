#!/usr/bin/env bash
# One-step set-up on Debian 12: install the packages the build needs, build Release, render the demo.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
mapfile -t packages < <(grep -v '^#' cmake/packages.txt)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "setup: installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
fi
extra=()
[ "${CI:-}" = "true" ] && extra+=(-DPT_WERROR=ON)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${extra[@]}"
cmake --build build -j "$(nproc)"
./build/renderer/pt render scenes/cornell-box/scene.json -o cornell-box.png
echo "setup: rendered cornell-box.png"
