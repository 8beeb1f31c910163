# Renders a glTF file under an HDRI with Blender Cycles, set up as pt renders it with
# `pt render FILE --env HDRI --env-rotate DEG --env-strength S`, for docs/cycles/gltf_compare.py.
#
# Usage: blender -b -noaudio --factory-startup -P docs/cycles/gltf_scene.py -- \
#            FILE.gltf|.glb HDRI.exr|.hdr OUT.exr SPP WIDTH HEIGHT MAX_DEPTH [ENV_ROTATE_DEG] [ENV_STRENGTH] [--masks]
#
# --masks renders material masks instead: every material becomes an emitter of radiance (i, 0, 0),
# i = 1, 2, ... in the order of bpy.data.materials, under a black world with no bounces, and OUT.json
# gets {"i": "material name"}. A pixel whose red is an integer to 1e-3 lies wholly on one material.
#
# - The file is read by Blender's own glTF importer (bpy.ops.import_scene.gltf): its materials become
#   Principled BSDFs, each set here to Multiscatter GGX. Lights in the file are kept as the importer
#   converts them.
# - The camera is the file's first: the first node placing a camera in a depth-first walk of the
#   default scene (pt's choice), taken from the file's JSON and placed here, yfov vertical.
# - The world is the HDRI as an Environment Texture, turned by a Mapping node so that every direction
#   sees the texel pt's environment (core/scene/environment.h) gives it. pt (y-up) looks up
#   u = 0.5 + (atan2(d.x, -d.z) + rot) / 2pi, v = acos(d.y) / pi from the top row. Blender's importer
#   turns glTF's (x, y, z) into (x, -z, y), z-up, and Cycles' equirectangular lookup of a z-up
#   direction b is u = 0.5 - atan2(b.y, b.x) / 2pi, v from the top row at +z. With b = (d.x, -d.z, d.y),
#   atan2(d.x, -d.z) = atan2(b.x, b.y) = pi/2 - atan2(b.y, b.x), so pt's u = Cycles' u + 1/4 + rot/2pi.
#   Turning b about +z by a lowers Cycles' u by a/2pi, so the Mapping node turns the lookup direction
#   by a = -(90 + rot) degrees about z. v agrees as it is. Checked by rendering the sky alone in both:
#   docs/cycles.md, "glTF under an HDRI".
# - Unbiased settings as in docs/cycles/pt_scene.py: adaptive sampling, denoising, clamping and
#   Filter Glossy off, caustics on, box pixel filter of width 1, bounces = MAX_DEPTH - 1.
import json
import math
import os
import struct
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_settings import render_timed, unbiased_cycles  # noqa: E402
import mathutils
import numpy

args = sys.argv[sys.argv.index("--") + 1:]
if len(args) < 7:
    sys.exit("usage: blender -b -P gltf_scene.py -- FILE.gltf|.glb HDRI OUT.exr SPP WIDTH HEIGHT MAX_DEPTH "
             "[ENV_ROTATE_DEG] [ENV_STRENGTH]")
path, hdri, out = args[0], args[1], args[2]
spp, width, height, max_depth = int(args[3]), int(args[4]), int(args[5]), int(args[6])
env_rotate = float(args[7]) if len(args) > 7 else 0.0
env_strength = float(args[8]) if len(args) > 8 else 1.0
masks = "--masks" in args[9:]
seed = 1


def fail(msg):
    sys.stderr.write("gltf_scene.py: %s: %s\n" % (path, msg))
    sys.exit(2)


def gltf_json(p):
    data = open(p, "rb").read()
    if data[:4] == b"glTF":
        length, kind = struct.unpack("<II", data[12:20])
        if kind != 0x4E4F534A:
            fail("the first GLB chunk is not JSON")
        return json.loads(data[20:20 + length])
    return json.loads(data)


def node_matrix(n):
    if "matrix" in n:
        m = n["matrix"]  # column-major
        return mathutils.Matrix([[m[c * 4 + r] for c in range(4)] for r in range(4)])
    t = mathutils.Matrix.Translation(n.get("translation", (0, 0, 0)))
    x, y, z, w = n.get("rotation", (0, 0, 0, 1))
    r = mathutils.Quaternion((w, x, y, z)).to_matrix().to_4x4()
    s = n.get("scale", (1, 1, 1))
    return t @ r @ mathutils.Matrix.Diagonal((s[0], s[1], s[2], 1.0))


def first_camera(doc):
    """pt's choice: the first node with a camera in a depth-first walk of the default scene."""
    scenes = doc.get("scenes", [])
    s = doc.get("scene", 0 if scenes else -1)
    roots = scenes[s].get("nodes", []) if s >= 0 else []
    nodes = doc.get("nodes", [])
    stack = [(i, node_matrix(nodes[i])) for i in reversed(roots)]
    while stack:
        i, world = stack.pop()
        n = nodes[i]
        if "camera" in n:
            return doc["cameras"][n["camera"]], world
        for c in reversed(n.get("children", [])):
            stack.append((c, world @ node_matrix(nodes[c])))
    fail("has no camera (this script needs the file's own)")


doc = gltf_json(path)
gcam, gworld = first_camera(doc)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
# Debian 12's Blender 3.4 importer still uses numpy's aliases np.bool etc., which Debian's numpy 1.24
# removed ("module 'numpy' has no attribute 'bool'"): restore them for the importer's sake.
for alias, builtin in (("bool", bool), ("int", int), ("float", float), ("object", object)):
    if alias not in numpy.__dict__:
        setattr(numpy, alias, builtin)
bpy.ops.import_scene.gltf(filepath=os.path.abspath(path))

# Every Principled BSDF (the importer's material model) gets Multiscatter GGX: energy kept as in pt.
count = 0
trees = [m.node_tree for m in bpy.data.materials if m.node_tree] + list(bpy.data.node_groups)
for nt in trees:
    for node in nt.nodes:
        if node.type == "BSDF_PRINCIPLED":
            node.distribution = "MULTI_GGX"
            count += 1
print("GLTF_SCENE principled=%d" % count)

if masks:
    names = {}
    for i, m in enumerate(bpy.data.materials, start=1):
        names[i] = m.name
        m.use_nodes = True
        m.node_tree.nodes.clear()
        emit = m.node_tree.nodes.new("ShaderNodeEmission")
        emit.inputs["Color"].default_value = (float(i), 0.0, 0.0, 1.0)
        emit.inputs["Strength"].default_value = 1.0
        o = m.node_tree.nodes.new("ShaderNodeOutputMaterial")
        m.node_tree.links.new(emit.outputs[0], o.inputs["Surface"])
    for ob in bpy.data.objects:
        if ob.type == "LIGHT":
            ob.hide_render = True
    json.dump(names, open(os.path.splitext(out)[0] + ".json", "w"))
    env_strength, max_depth = 0.0, 1

# The camera: position, forward (-z) and up (+y) of the node, y-up -> z-up.
to_z_up = mathutils.Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))
w = to_z_up @ gworld
pos = w @ mathutils.Vector((0, 0, 0))
f = (w.to_3x3() @ mathutils.Vector((0, 0, -1))).normalized()
up = (w.to_3x3() @ mathutils.Vector((0, 1, 0))).normalized()
r = f.cross(up).normalized()
u = r.cross(f)
cam = bpy.data.cameras.new("pt_camera")
if gcam.get("type") == "orthographic":
    o = gcam["orthographic"]
    cam.type = "ORTHO"
    cam.sensor_fit = "VERTICAL"
    cam.ortho_scale = 2.0 * abs(o["ymag"]) * (gworld.to_3x3() @ mathutils.Vector((0, 1, 0))).length
else:
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = gcam["perspective"]["yfov"]
cam.clip_start = gcam.get("perspective", {}).get("znear", 1e-3) if gcam.get("type") != "orthographic" else 1e-3
cam.clip_end = 1e6
co = bpy.data.objects.new("pt_camera", cam)
rot = mathutils.Matrix(((r[0], u[0], -f[0]), (r[1], u[1], -f[1]), (r[2], u[2], -f[2])))
co.matrix_world = mathutils.Matrix.Translation(pos) @ rot.to_4x4()
scene.collection.objects.link(co)
scene.camera = co

# The world: the HDRI, turned as pt turns it (see the header for the derivation).
world = bpy.data.worlds.new("pt_env")
world.use_nodes = True
nt = world.node_tree
coord = nt.nodes.new("ShaderNodeTexCoord")
mapping = nt.nodes.new("ShaderNodeMapping")
mapping.vector_type = "VECTOR"
mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(-(90.0 + env_rotate)))
tex = nt.nodes.new("ShaderNodeTexEnvironment")
tex.image = bpy.data.images.load(os.path.abspath(hdri))
tex.interpolation = "Linear"
tex.projection = "EQUIRECTANGULAR"
nt.links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
nt.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
bg = nt.nodes["Background"]
nt.links.new(tex.outputs["Color"], bg.inputs["Color"])
bg.inputs["Strength"].default_value = env_strength
scene.world = world

unbiased_cycles(scene, spp, max_depth, seed, width, height, out)
render_timed(out)
