# Renders a pt scene (scene.json + OBJ/MTL) with Blender Cycles, for side-by-side comparison with pt.
#
# Usage: blender -b -noaudio --factory-startup -P docs/cycles/pt_scene.py -- SCENE OUT.exr SPP WIDTH HEIGHT MAX_DEPTH [SEED]
#   SCENE      a scene.json or the folder holding one
#   MAX_DEPTH  pt's --max-depth (bounces; 1 = direct lighting only). Cycles counts bounces after the
#              first hit, so it gets max_bounces = MAX_DEPTH - 1: the same set of paths.
# The EXR's metadata holds Cycles' own timings (cycles.<layer>.synchronization_time: scene export and
# BVH build; .render_time: path tracing; to 10 ms); the script also prints "CYCLES_WALL_SECONDS T",
# the wall time of bpy.ops.render.render (both of those plus Blender's overhead, no image writing).
#
# The subset of pt's scene format understood (anything else is refused with a message):
#   camera (position, look_at, up, vertical fov), objects (OBJ with scale/rotate/translate and a
#   material override), spheres, quad/triangle lights, a constant environment; materials diffuse,
#   mirror (perfect specular, tint), emission (front face only, plus the material's own BSDF, as in
#   pt). MTL as pt reads it: illum 3/5 mirror tinted by Ks, Ke emission, Kd diffuse; glass, glossy
#   and textures are refused. y-up (pt) becomes z-up (Blender): (x, y, z) -> (x, -z, y).
# Spheres are exact: a one-vertex point cloud made by geometry nodes, which Cycles renders as a true
# sphere (a tessellated sphere's facets would show in a mirror ball).
# Settings that keep Cycles unbiased and counting samples as pt does: adaptive sampling, denoising,
# clamping and Filter Glossy off, caustics on, box pixel filter of width 1 (pt's film).
import json
import math
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_settings import render_timed, unbiased_cycles  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
if len(args) < 6:
    sys.exit("usage: blender -b -P pt_scene.py -- SCENE OUT.exr SPP WIDTH HEIGHT MAX_DEPTH [SEED]")
scene_path, out = args[0], args[1]
spp, width, height, max_depth = int(args[2]), int(args[3]), int(args[4]), int(args[5])
seed = int(args[6]) if len(args) > 6 else 1
if os.path.isdir(scene_path):
    scene_path = os.path.join(scene_path, "scene.json")
root = os.path.dirname(os.path.abspath(scene_path))


def fail(msg):
    sys.stderr.write("pt_scene.py: %s: %s\n" % (scene_path, msg))
    sys.exit(2)


def to_z_up(v):
    return (v[0], -v[2], v[1])


def colour(v, default):
    if v is None:
        return default
    return (float(v), float(v), float(v)) if isinstance(v, (int, float)) else tuple(float(c) for c in v)


# --- Materials: a small record per material, turned into Cycles nodes below. ---
class Mat:
    def __init__(self, name, kind="diffuse", kd=(0.8, 0.8, 0.8), ks=(1, 1, 1), emission=(0, 0, 0)):
        self.name, self.kind, self.kd, self.ks, self.emission = name, kind, kd, ks, emission


def json_material(name, m):
    for key in m:
        if key not in ("type", "albedo", "specular", "emission"):
            fail("material %s: '%s' is not supported by this script" % (name, key))
    kind = m.get("type", "diffuse")
    if kind not in ("diffuse", "mirror"):
        fail("material %s: type '%s' is not supported by this script (diffuse, mirror)" % (name, kind))
    return Mat(name, kind, colour(m.get("albedo"), (0.8,) * 3), colour(m.get("specular"), (1.0,) * 3),
               colour(m.get("emission"), (0.0,) * 3))


def read_mtl(path):
    mats, cur = {}, None
    for line in open(path):
        t = line.split()
        if not t or t[0].startswith("#"):
            continue
        if t[0] == "newmtl":
            cur = {"name": t[1], "Kd": (0, 0, 0), "Ks": (0, 0, 0), "Ke": (0, 0, 0), "illum": 2, "d": 1.0}
            mats[t[1]] = cur
        elif t[0] in ("Kd", "Ks", "Ke"):
            cur[t[0]] = tuple(float(x) for x in t[1:4])
        elif t[0] == "illum":
            cur["illum"] = int(t[1])
        elif t[0] == "d":
            cur["d"] = float(t[1])
        elif t[0] == "Tr":
            cur["d"] = 1.0 - float(t[1])
        elif t[0].startswith("map_"):
            fail("%s: textures are not supported by this script" % path)
    out = {}
    for name, m in mats.items():
        if m["illum"] in (4, 6, 7) or m["d"] < 1:
            fail("%s: %s is glass, not supported by this script" % (path, name))
        if m["illum"] in (3, 5):
            ks = m["Ks"] if max(m["Ks"]) > 0 else (1, 1, 1)
            out[name] = Mat(name, "mirror", m["Kd"], tuple(min(c, 1.0) for c in ks), m["Ke"])
        elif max(m["Ks"]) > 0 and m["illum"] != 1:
            fail("%s: %s is glossy (Phong), not supported by this script" % (path, name))
        else:
            s = max(m["Kd"])
            kd = tuple(c / s for c in m["Kd"]) if s > 1 else m["Kd"]
            out[name] = Mat(name, "diffuse", kd, (0, 0, 0), m["Ke"])
    return out


# --- Geometry: triangles (z-up) with a material record per face. ---
verts, faces, face_mats = [], [], []


def transform(o):
    """pt's object transform: scale, then rotate x, y, z (degrees, right-handed), then translate."""
    s = o.get("scale", 1.0)
    s = (s, s, s) if isinstance(s, (int, float)) else tuple(s)
    rx, ry, rz = (math.radians(a) for a in o.get("rotate", (0, 0, 0)))
    tx, ty, tz = o.get("translate", (0, 0, 0))

    def apply(v):
        x, y, z = v[0] * s[0], v[1] * s[1], v[2] * s[2]
        y, z = y * math.cos(rx) - z * math.sin(rx), y * math.sin(rx) + z * math.cos(rx)
        x, z = x * math.cos(ry) + z * math.sin(ry), -x * math.sin(ry) + z * math.cos(ry)
        x, y = x * math.cos(rz) - y * math.sin(rz), x * math.sin(rz) + y * math.cos(rz)
        return (x + tx, y + ty, z + tz)
    return apply, s[0] * s[1] * s[2] < 0


def read_obj(path, apply, flip, override):
    base = len(verts)
    local, mtls, current = [], {}, None
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == "v":
            local.append(apply(tuple(float(x) for x in t[1:4])))
        elif t[0] == "mtllib":
            mtl_path = os.path.join(os.path.dirname(path), " ".join(t[1:]))
            if os.path.exists(mtl_path):
                mtls.update(read_mtl(mtl_path))
        elif t[0] == "usemtl":
            current = mtls.get(t[1])
        elif t[0] == "f":
            idx = []
            for w in t[1:]:
                i = int(w.split("/")[0])
                idx.append(base + (i - 1 if i > 0 else len(local) + i))
            faces.append(idx[::-1] if flip else idx)
            face_mats.append(override or current or default_mat)
        elif t[0] == "vn":
            fail("%s: vertex normals are not supported by this script" % path)
    verts.extend(to_z_up(v) for v in local)


doc = json.load(open(scene_path))
for key in doc:
    if key not in ("camera", "materials", "objects", "spheres", "lights", "environment", "render"):
        fail("'%s' is not supported by this script" % key)
default_mat = Mat("default")
materials = {n: json_material(n, m) for n, m in doc.get("materials", {}).items()}
for o in doc.get("objects", []):
    apply, flip = transform(o)
    read_obj(os.path.join(root, o["file"]), apply, flip, materials[o["material"]] if "material" in o else None)
for i, l in enumerate(doc.get("lights", [])):
    if l["type"] not in ("quad", "triangle"):
        fail("light %d: type '%s' is not supported by this script (quad, triangle)" % (i, l["type"]))
    base = len(verts)
    verts.extend(to_z_up(c) for c in l["corners"])
    faces.append(list(range(base, base + len(l["corners"]))))
    face_mats.append(Mat("light%d" % i, "diffuse", (0, 0, 0), (0, 0, 0), colour(l["radiance"], None)))
spheres = [(to_z_up(s["center"]), float(s["radius"]), materials[s["material"]] if "material" in s else default_mat)
           for s in doc.get("spheres", [])]

# --- Blender scene. ---
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
blender_mats = {}


def blender_material(m):
    if m.name in blender_mats:
        return blender_mats[m.name]
    b = bpy.data.materials.new(m.name)
    b.use_nodes = True
    nt = b.node_tree
    nt.nodes.clear()
    out_node = nt.nodes.new("ShaderNodeOutputMaterial")
    if m.kind == "mirror":
        bsdf = nt.nodes.new("ShaderNodeBsdfGlossy")
        bsdf.distribution = "SHARP"
        bsdf.inputs["Color"].default_value = (*m.ks, 1.0)
    else:
        bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Color"].default_value = (*m.kd, 1.0)
    shader = bsdf.outputs[0]
    if max(m.emission) > 0:
        # pt's emitters emit from the front face only (the winding's normal), and also reflect with
        # their own BSDF; Cycles' emission is two-sided, so the back face gets the BSDF alone.
        emit = nt.nodes.new("ShaderNodeEmission")
        emit.inputs["Color"].default_value = (*m.emission, 1.0)
        emit.inputs["Strength"].default_value = 1.0
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(emit.outputs[0], add.inputs[0])
        nt.links.new(bsdf.outputs[0], add.inputs[1])
        geo = nt.nodes.new("ShaderNodeNewGeometry")
        mix = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
        nt.links.new(add.outputs[0], mix.inputs[1])
        nt.links.new(bsdf.outputs[0], mix.inputs[2])
        shader = mix.outputs[0]
    nt.links.new(shader, out_node.inputs["Surface"])
    blender_mats[m.name] = b
    return b


mesh = bpy.data.meshes.new("pt_mesh")
mesh.from_pydata(verts, [], faces)
names = []
for m in face_mats:
    if m.name not in names:
        names.append(m.name)
by_name = {m.name: m for m in face_mats}
for n in names:
    mesh.materials.append(blender_material(by_name[n]))
index = {n: i for i, n in enumerate(names)}
mesh.polygons.foreach_set("material_index", [index[m.name] for m in face_mats])
mesh.update()
ob = bpy.data.objects.new("pt_mesh", mesh)
scene.collection.objects.link(ob)

for i, (c, r, m) in enumerate(spheres):
    # One vertex turned into one point of radius r: Cycles intersects it as an exact sphere.
    pm = bpy.data.meshes.new("sphere%d" % i)
    pm.from_pydata([(0.0, 0.0, 0.0)], [], [])
    so = bpy.data.objects.new("sphere%d" % i, pm)
    so.location = c
    scene.collection.objects.link(so)
    ng = bpy.data.node_groups.new("sphere%d" % i, "GeometryNodeTree")
    ng.inputs.new("NodeSocketGeometry", "Geometry")
    ng.outputs.new("NodeSocketGeometry", "Geometry")
    gin, gout = ng.nodes.new("NodeGroupInput"), ng.nodes.new("NodeGroupOutput")
    to_points = ng.nodes.new("GeometryNodeMeshToPoints")
    to_points.inputs["Radius"].default_value = r
    set_mat = ng.nodes.new("GeometryNodeSetMaterial")
    set_mat.inputs["Material"].default_value = blender_material(m)
    ng.links.new(gin.outputs[0], to_points.inputs["Mesh"])
    ng.links.new(to_points.outputs["Points"], set_mat.inputs["Geometry"])
    ng.links.new(set_mat.outputs["Geometry"], gout.inputs[0])
    mod = so.modifiers.new("sphere", "NODES")
    mod.node_group = ng

cam_doc = doc.get("camera")
if cam_doc is None:
    fail("needs a 'camera' (pt's framing default camera is not reproduced here)")
pos = to_z_up(cam_doc.get("position", (0, 0, 5)))
at = to_z_up(cam_doc.get("look_at", (0, 0, 0)))
up = to_z_up(cam_doc.get("up", (0, 1, 0)))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    s = math.sqrt(sum(x * x for x in a))
    return tuple(x / s for x in a)


f = norm(sub(at, pos))
r = norm(cross(f, up))
u = cross(r, f)
cam = bpy.data.cameras.new("cam")
cam.sensor_fit = "VERTICAL"
cam.angle_y = math.radians(cam_doc.get("fov", 40.0))
span = max(max(abs(x) for v in verts for x in v), 1.0) if verts else 100.0
cam.clip_start = 1e-4 * span
cam.clip_end = 1e3 * span
co = bpy.data.objects.new("cam", cam)
import mathutils  # noqa: E402  (available inside Blender only)
# A Blender camera looks down its local -z with +y up: columns right, up, -forward.
rot = mathutils.Matrix(((r[0], u[0], -f[0]), (r[1], u[1], -f[1]), (r[2], u[2], -f[2])))
co.matrix_world = mathutils.Matrix.Translation(pos) @ rot.to_4x4()
scene.collection.objects.link(co)
scene.camera = co

world = bpy.data.worlds.new("world")
world.use_nodes = True
env = doc.get("environment")
sky = (0.0, 0.0, 0.0)
if env is not None:
    if "radiance" not in env or "file" in env:
        fail("only a constant environment ('radiance') is supported by this script")
    sky = colour(env["radiance"], None)
world.node_tree.nodes["Background"].inputs["Color"].default_value = (*sky, 1.0)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
scene.world = world

unbiased_cycles(scene, spp, max_depth, seed, width, height, out)
render_timed(out)
