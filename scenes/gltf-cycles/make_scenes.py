# Makes the glTF scenes of the pt-against-Cycles comparison under an HDRI (docs/cycles/gltf_compare.py),
# with Blender's own glTF exporter, so the files are what a Blender user would hand to pt.
#
#   blender -b -noaudio --factory-startup -P scenes/gltf-cycles/make_scenes.py
#
# Writes, next to this script:
#   spheres.glb   metallic-roughness spheres (a metal row and a dielectric row, roughness 0.05, 0.25,
#                 0.5, 1), a cube with a base-colour texture, a panel with a tangent-space normal map,
#                 a grey floor and a camera
#   envcheck.glb  a camera and one small triangle out of its view: renders the sky alone, for checking
#                 that pt and Cycles map the environment's directions to the same texels
import math
import os

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))


def clear():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def principled(name, base, metallic, roughness):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = (*base, 1.0)
    b.inputs["Metallic"].default_value = metallic
    b.inputs["Roughness"].default_value = roughness
    return m


def image(name, size, fn, colorspace):
    img = bpy.data.images.new(name, size, size, alpha=False)
    px = []
    for y in range(size):
        for x in range(size):
            px.extend((*fn(x, y), 1.0))
    img.pixels = px
    # A generated image packed as it is exports black: save it as a PNG and load that instead.
    tmp = os.path.join(bpy.app.tempdir, name + ".png")
    img.filepath_raw = tmp
    img.file_format = "PNG"
    img.save()
    img = bpy.data.images.load(tmp)
    img.colorspace_settings.name = colorspace
    img.pack()
    return img


def camera(loc, look_at, yfov_deg):
    cd = bpy.data.cameras.new("camera")
    cd.sensor_fit = "VERTICAL"
    cd.angle_y = math.radians(yfov_deg)
    co = bpy.data.objects.new("camera", cd)
    bpy.context.scene.collection.objects.link(co)
    co.location = loc
    import mathutils
    d = mathutils.Vector(look_at) - mathutils.Vector(loc)
    co.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = co
    scn = bpy.context.scene
    scn.render.resolution_x, scn.render.resolution_y = 320, 240  # the exported aspectRatio


def export(name):
    bpy.ops.export_scene.gltf(filepath=os.path.join(HERE, name), export_format="GLB", export_cameras=True,
                              export_lights=False, export_tangents=True, export_yup=True)


def spheres():
    clear()
    # Floor (Blender is z-up; the exporter writes glTF's y-up).
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
    bpy.context.object.data.materials.append(principled("floor", (0.5, 0.5, 0.5), 0.0, 0.6))
    for row, (kind, base, metallic) in enumerate((("metal", (0.95, 0.64, 0.54), 1.0),
                                                  ("dielectric", (0.7, 0.08, 0.06), 0.0))):
        for i, r in enumerate((0.05, 0.25, 0.5, 1.0)):
            bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.45,
                                                 location=(-1.65 + 1.1 * i, 0.6 - 1.2 * row, 0.45))
            bpy.ops.object.shade_smooth()
            bpy.context.object.data.materials.append(principled("%s r%.2f" % (kind, r), base, metallic, r))
    # A textured cube: an 8x8 checker in sRGB (Blender's exporter writes it as a PNG base colour).
    checker = image("checker", 64, lambda x, y: (0.9, 0.75, 0.2) if (x // 8 + y // 8) % 2 else (0.1, 0.25, 0.6),
                    "sRGB")
    bpy.ops.mesh.primitive_cube_add(size=0.8, location=(-2.4, -1.6, 0.4), rotation=(0, 0, math.radians(30)))
    m = principled("checker cube", (1, 1, 1), 0.0, 0.5)
    nt = m.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = checker
    tex.interpolation = "Linear"
    nt.links.new(tex.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    bpy.context.object.data.materials.append(m)
    # A normal-mapped panel standing up: hemispherical bumps, a tangent-space map in glTF's
    # convention (+Y up, OpenGL), which is also Blender's.
    def bumps(x, y, n=128, cells=4):
        c = n / cells
        u, v = (x % c) / c * 2 - 1, (y % c) / c * 2 - 1
        rr = u * u + v * v
        if rr >= 0.64:
            nx, ny, nz = 0.0, 0.0, 1.0
        else:
            h = math.sqrt(0.64 - rr)
            nx, ny, nz = u, v, h
            s = math.sqrt(nx * nx + ny * ny + nz * nz)
            nx, ny, nz = nx / s, ny / s, nz / s
        return (nx * 0.5 + 0.5, ny * 0.5 + 0.5, nz * 0.5 + 0.5)
    normal = image("bumps", 128, bumps, "Non-Color")
    bpy.ops.mesh.primitive_plane_add(size=1.6, location=(2.3, -1.3, 0.8), rotation=(math.radians(90), 0,
                                                                                   math.radians(-20)))
    m = principled("normal-mapped panel", (0.8, 0.8, 0.8), 0.0, 0.35)
    nt = m.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = normal
    nm = nt.nodes.new("ShaderNodeNormalMap")
    nt.links.new(tex.outputs["Color"], nm.inputs["Color"])
    nt.links.new(nm.outputs["Normal"], nt.nodes["Principled BSDF"].inputs["Normal"])
    bpy.context.object.data.materials.append(m)
    camera((0.0, -6.2, 3.0), (0.0, -0.2, 0.35), 40.0)
    export("spheres.glb")


def envcheck():
    clear()
    # A triangle 50 units behind the camera: the file needs a mesh, the view sees only the sky.
    me = bpy.data.meshes.new("hidden")
    me.from_pydata([(0, 50, 0), (0.1, 50, 0), (0, 50, 0.1)], [], [(0, 1, 2)])
    ob = bpy.data.objects.new("hidden", me)
    bpy.context.scene.collection.objects.link(ob)
    # Looking along Blender's -y (glTF's +z, where pt's map wraps from u = 1 to 0), tilted up 20 degrees so the
    # view holds the horizon band and the sky above it.
    camera((0, 0, 0), (0, -1, math.tan(math.radians(20))), 100.0)
    export("envcheck.glb")


spheres()
envcheck()
