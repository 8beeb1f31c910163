# Renders scenes/cornell-box with Blender Cycles for side-by-side comparison with pt.
# Usage: blender -b -noaudio --factory-startup -P docs/cycles/cornell_box.py -- OUT.exr SPP SIZE MAX_BOUNCES
# Geometry is read from the same OBJ (our y-up, mm) and turned into Blender's z-up frame; materials
# and the light match the MTL; adaptive sampling, denoising and clamping are off so "spp" means
# the same thing in both renderers.
import sys, os, time
import bpy

args = sys.argv[sys.argv.index("--") + 1:]
out, spp, size, bounces = args[0], int(args[1]), int(args[2]), int(args[3])
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
obj = os.path.join(root, "scenes", "cornell-box", "cornell-box.obj")

colours = {"white": (0.725, 0.71, 0.68), "red": (0.63, 0.065, 0.05), "green": (0.14, 0.45, 0.091)}
verts, faces, mats = [], [], []
current = None
for line in open(obj):
    t = line.split()
    if not t: continue
    if t[0] == "v":
        x, y, z = map(float, t[1:4])
        verts.append((x, -z, y))  # y-up -> z-up: a rotation of +90 degrees about x
    elif t[0] == "usemtl":
        current = t[1]
    elif t[0] == "f":
        faces.append([int(i.split("/")[0]) - 1 for i in t[1:]])
        mats.append(current)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
mesh = bpy.data.meshes.new("cornell")
mesh.from_pydata(verts, [], faces)
names = sorted(set(mats))
for n in names:
    m = bpy.data.materials.new(n)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    outn = nt.nodes.new("ShaderNodeOutputMaterial")
    if n == "light":
        # Emission plus the MTL's Kd 0.78: the light also reflects, as in pt.
        e = nt.nodes.new("ShaderNodeEmission")
        e.inputs["Color"].default_value = (17.0, 12.0, 4.0, 1.0)
        e.inputs["Strength"].default_value = 1.0
        d = nt.nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Color"].default_value = (0.78, 0.78, 0.78, 1.0)
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(e.outputs[0], add.inputs[0])
        nt.links.new(d.outputs[0], add.inputs[1])
        nt.links.new(add.outputs[0], outn.inputs["Surface"])
    else:
        d = nt.nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Color"].default_value = (*colours[n], 1.0)
        nt.links.new(d.outputs[0], outn.inputs["Surface"])
    mesh.materials.append(m)
for poly, n in zip(mesh.polygons, mats):
    poly.material_index = names.index(n)
ob = bpy.data.objects.new("cornell", mesh)
scene.collection.objects.link(ob)

cam = bpy.data.cameras.new("cam")
cam.sensor_fit = "VERTICAL"
cam.angle_y = 39.3 * 3.141592653589793 / 180
cam.clip_start = 1.0
cam.clip_end = 10000.0
co = bpy.data.objects.new("cam", cam)
co.location = (278.0, 800.0, 273.0)
co.rotation_euler = (3.141592653589793 / 2, 0.0, 3.141592653589793)
scene.collection.objects.link(co)
scene.camera = co

world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
scene.world = world

scene.render.engine = "CYCLES"
c = scene.cycles
c.device = "CPU"
c.samples = spp
c.use_adaptive_sampling = False
c.use_denoising = False
c.sample_clamp_direct = 0.0
c.sample_clamp_indirect = 0.0
c.max_bounces = bounces
c.diffuse_bounces = bounces
c.caustics_reflective = True
c.caustics_refractive = True
c.seed = 1
c.pixel_filter_type = "BOX"
c.filter_width = 1.0
scene.render.resolution_x = size
scene.render.resolution_y = size
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.view_settings.view_transform = "Standard"
scene.render.filepath = out
t0 = time.time()
bpy.ops.render.render(write_still=True)
print("CYCLES_RENDER_SECONDS %.3f" % (time.time() - t0))
