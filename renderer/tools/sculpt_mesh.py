# A sculpt-like mesh for the BVH size sweep (renderer/tools/real_meshes.sh): an icosphere displaced by
# noise at three scales, voxel-remeshed into one closed surface of even quads, and decimated to the
# requested triangle count, leaving triangles of many sizes as a processed scan has.
#   blender -b --python renderer/tools/sculpt_mesh.py -- OUT.obj TRIANGLES
import bpy, sys, time
argv = sys.argv[sys.argv.index("--") + 1:]
out, target, seed = argv[0], int(argv[1]), int(argv[2]) if len(argv) > 2 else 1
t0 = time.time()
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=7, radius=1.0)
obj = bpy.context.active_object
def apply(mod):
    bpy.ops.object.modifier_apply(modifier=mod.name)
# Large forms, then finer detail: two displacements by noise along the normals.
for scale, strength, depth in ((0.9, 0.6, 2), (0.25, 0.12, 4), (0.06, 0.03, 2)):
    tex = bpy.data.textures.new("noise", type='CLOUDS')
    tex.noise_scale = scale
    tex.noise_depth = depth
    tex.noise_basis = 'VORONOI_F1' if scale < 0.1 else 'BLENDER_ORIGINAL'
    m = obj.modifiers.new("displace", 'DISPLACE')
    m.texture = tex
    m.strength = strength
    m.texture_coords = 'LOCAL'
    apply(m)
# A voxel remesh makes one closed surface of even quads, as sculpting tools do; then decimation
# (edge collapse) leaves triangles of many sizes, as a processed scan has.
m = obj.modifiers.new("remesh", 'REMESH')
m.mode = 'VOXEL'
m.voxel_size = 0.006
apply(m)
tris = sum(len(p.vertices) - 2 for p in obj.data.polygons)
m = obj.modifiers.new("decimate", 'DECIMATE')
m.ratio = min(1.0, target / tris)
m.use_collapse_triangulate = True
apply(m)
m = obj.modifiers.new("tri", 'TRIANGULATE')
apply(m)
print("faces", len(obj.data.polygons), "from", tris, "in", time.time() - t0, "s")
bpy.ops.wm.obj_export(filepath=out, export_selected_objects=False, export_uv=False, export_normals=False,
                      export_materials=False, apply_modifiers=True)
