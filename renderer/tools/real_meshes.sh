#!/usr/bin/env bash
# Real scanned meshes for the BVH's size sweep (docs/bvh.md), made from what Debian packages ship:
#   bunny.obj       the Stanford bunny, 69,666 triangles (glmark2-data: /usr/share/glmark2/models)
#   armadillo.obj   the Stanford armadillo, decimated to 52,000 triangles (libcgal-demo's data)
#   dragon-20k.obj  the Chinese dragon scan, 19,994 triangles (libcgal-demo)
#   bunny-75k.obj   a refined Stanford bunny, 75,408 triangles (libcgal-demo: bunny00.off)
#   sculpt-124k.obj a sculpt-like closed surface of 124,000 triangles: an icosphere displaced by
#                   noise, voxel-remeshed and decimated by Blender (renderer/tools/sculpt_mesh.py;
#                   needs blender, a few minutes)
# None is committed: the CGAL data carries no licence statement of its own. Install the packages
# with `apt-get install glmark2-data libcgal-demo blender`.
#
#   renderer/tools/real_meshes.sh OUT_DIR
set -euo pipefail
out="${1:?usage: real_meshes.sh OUT_DIR}"
mkdir -p "$out"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [ -f /usr/share/glmark2/models/bunny.obj ]; then
  cp /usr/share/glmark2/models/bunny.obj "$out/bunny.obj"
else
  echo "real_meshes: no glmark2-data (the bunny); skipped" >&2
fi
# OFF (a header line, counts, vertices, then faces as "n i0 i1 ... ") to OBJ, polygons as fans.
off2obj() {
  awk 'BEGIN { h = 0 }
       /^[ \t]*#/ || NF == 0 { next }
       h == 0 { if ($1 == "OFF" && NF == 1) next; if ($1 == "OFF") sub(/^OFF/, ""); $0 = $0; nv = $1; nf = $2; h = 1; next }
       nv > 0 { print "v", $1, $2, $3; nv--; next }
       nf > 0 { for (i = 3; i <= $1; i++) print "f", $2 + 1, $(i) + 1, $(i + 1) + 1; nf-- }' "$1" > "$2"
}
data=/usr/share/doc/libcgal-dev/data.tar.gz
if [ -f "$data" ]; then
  tmp="$(mktemp -d)"
  trap 'rm -rf "$tmp"' EXIT
  tar xzf "$data" -C "$tmp" data/meshes/armadillo.off data/meshes/ChineseDragon-10kv.off data/meshes/bunny00.off
  off2obj "$tmp/data/meshes/armadillo.off" "$out/armadillo.obj"
  off2obj "$tmp/data/meshes/ChineseDragon-10kv.off" "$out/dragon-20k.obj"
  off2obj "$tmp/data/meshes/bunny00.off" "$out/bunny-75k.obj"
else
  echo "real_meshes: no libcgal-demo ($data); skipped" >&2
fi
if command -v blender > /dev/null; then
  [ -f "$out/sculpt-124k.obj" ] || blender -b --python "$here/sculpt_mesh.py" -- "$out/sculpt-124k.obj" 124000 > /dev/null
else
  echo "real_meshes: no blender; the sculpt-like mesh skipped" >&2
fi
ls "$out"
