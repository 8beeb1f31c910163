# The Cycles settings both Blender-side scripts (pt_scene.py, gltf_scene.py) render with: unbiased
# and counting samples as pt does (adaptive sampling, denoising, clamping and Filter Glossy off,
# caustics on, a box pixel filter of width 1: pt's film), and the render itself, timed.
import time

import bpy


def unbiased_cycles(scene, spp, max_depth, seed, width, height, out):
    """MAX_DEPTH is pt's --max-depth: Cycles counts bounces after the first hit, so it gets
    max_bounces = MAX_DEPTH - 1, the same set of paths."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0  # "Filter Glossy" blurs mirrors after diffuse bounces: biased
    c.caustics_reflective = True
    c.caustics_refractive = True
    bounces = max(0, max_depth - 1)
    c.max_bounces = bounces
    c.diffuse_bounces = bounces
    c.glossy_bounces = bounces
    c.transmission_bounces = bounces
    c.transparent_max_bounces = bounces
    c.volume_bounces = 0
    c.seed = seed
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.use_auto_tile = False
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "ZIP"
    scene.view_settings.view_transform = "Standard"
    scene.render.filepath = out


def render_timed(out):
    """Renders, saves the EXR (which carries cycles.*.render_time etc. as metadata) and prints
    CYCLES_WALL_SECONDS, the wall time of bpy.ops.render.render."""
    t0 = time.time()
    bpy.ops.render.render(write_still=False)
    total = time.time() - t0
    bpy.data.images["Render Result"].save_render(out)
    print("CYCLES_WALL_SECONDS %.3f" % total)
