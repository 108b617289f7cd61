#!/usr/bin/env python3
"""Renders a NeRF synthetic ("Blender") dataset of a glTF model, headless, with Blender 3.4 Cycles.

Run it through Blender (the arguments after `--` are this script's):

    blender -b --factory-startup --python scripts/make-nerf-dataset.py -- MODEL.gltf OUT_DIR \
        [--train 100] [--val 0] [--test 20] [--size 200] [--spp 64] [--radius 4] [--seed 0]

It writes, as the original NeRF datasets lay them out:
  OUT_DIR/transforms_{train,val,test}.json  camera_angle_x and frames of file_path ("./train/r_0", no
                                            extension) and the 4x4 camera-to-world transform_matrix
                                            (Blender's camera: it looks down its -z with y up; world z up);
  OUT_DIR/{train,val,test}/r_<i>.png        RGBA, 8 bits, sRGB ("Standard" view transform), the
                                            background transparent.

The model is moved and scaled so that its bounding box is centred on the origin and its bounding
sphere has radius 1 (so the [-1.5, 1.5]^3 box that radiance_fields trains in holds it). It is lit by a
uniform white sky and one sun, since the glTF samples carry no lights. Training cameras lie on the
upper hemisphere of radius --radius (uniformly in area, from --seed), all looking at the origin; test
and validation cameras follow a spiral over the same hemisphere, as the originals' test paths do.

Cycles is set up for a fair reference: fixed seed, no adaptive sampling, no denoising, no clamping or
glossy blur, a 1-pixel box filter. The render is deterministic for a seed, across thread counts.
`apt-get install --no-install-recommends blender python3-numpy` provides Blender 3.4 on Debian 12.
"""
import argparse
import json
import math
import os
import random
import sys


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="make-nerf-dataset.py",
                                     description="Render a NeRF synthetic dataset of a glTF model with Cycles.")
    parser.add_argument("model", help="a .gltf or .glb file")
    parser.add_argument("out", help="the dataset folder to write")
    parser.add_argument("--train", type=int, default=100, help="training views (default 100)")
    parser.add_argument("--val", type=int, default=0, help="validation views (default 0: no transforms_val.json)")
    parser.add_argument("--test", type=int, default=20, help="test views (default 20)")
    parser.add_argument("--size", type=int, default=200, help="image width and height in pixels (default 200)")
    parser.add_argument("--spp", type=int, default=64, help="Cycles samples per pixel (default 64)")
    parser.add_argument("--radius", type=float, default=4.0, help="camera distance from the origin (default 4)")
    parser.add_argument("--fov", type=float, default=0.6911112070083618,
                        help="horizontal field of view in radians (default 0.6911, as the originals)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the training cameras and of Cycles")
    return parser.parse_args(argv)


def fail(message):
    print("make-nerf-dataset.py: error: " + message, file=sys.stderr)
    sys.exit(1)


def script_args():
    if "--" not in sys.argv:
        return []
    return sys.argv[sys.argv.index("--") + 1:]


def import_model(bpy, path):
    # Debian's numpy dropped the alias that Blender 3.4's glTF importer still uses.
    import numpy
    if not hasattr(numpy, "bool"):
        numpy.bool = numpy.bool_
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    result = bpy.ops.import_scene.gltf(filepath=path)
    if "FINISHED" not in result:
        fail(path + ": Blender's glTF importer did not finish")
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    if not meshes:
        fail(path + ": the file holds no mesh")
    return meshes


def normalise(bpy, meshes):
    """Parents every root object under one empty that centres the model and scales it to radius 1."""
    from mathutils import Vector
    bpy.context.view_layer.update()
    lo = Vector((math.inf,) * 3)
    hi = Vector((-math.inf,) * 3)
    for obj in meshes:
        for corner in obj.bound_box:
            p = obj.matrix_world @ Vector(corner)
            lo = Vector(map(min, lo, p))
            hi = Vector(map(max, hi, p))
    centre = (lo + hi) / 2
    radius = (hi - lo).length / 2
    if not radius > 0:
        fail("the model's bounding box is empty")
    root = bpy.data.objects.new("nerf_root", None)
    bpy.context.scene.collection.objects.link(root)
    for obj in list(bpy.context.scene.objects):
        if obj is not root and obj.parent is None:
            obj.parent = root
    root.scale = (1 / radius,) * 3
    root.location = -centre / radius
    bpy.context.view_layer.update()
    return radius


def set_up_cycles(bpy, args):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.spp
    scene.cycles.seed = args.seed
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.blur_glossy = 0.0
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    scene.render.film_transparent = True
    scene.render.resolution_x = args.size
    scene.render.resolution_y = args.size
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.image_settings.color_depth = "8"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"

    world = bpy.data.worlds.new("nerf_sky")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    background.inputs["Strength"].default_value = 0.35
    scene.world = world

    sun_data = bpy.data.lights.new("nerf_sun", type="SUN")
    sun_data.energy = 1.5
    sun = bpy.data.objects.new("nerf_sun", sun_data)
    sun.rotation_euler = (math.radians(40), math.radians(10), math.radians(30))
    scene.collection.objects.link(sun)

    cam_data = bpy.data.cameras.new("nerf_camera")
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.angle_x = args.fov
    cam_data.clip_start = 0.01
    cam_data.clip_end = 100.0  # the default, 1000 units, is far more than needed; set it explicitly
    camera = bpy.data.objects.new("nerf_camera", cam_data)
    scene.collection.objects.link(camera)
    scene.camera = camera
    return camera


def look_at_origin(camera, position):
    from mathutils import Vector
    camera.location = Vector(position)
    camera.rotation_mode = "QUATERNION"
    camera.rotation_quaternion = (-Vector(position)).to_track_quat("-Z", "Y")


def hemisphere_uniform(rng, radius):
    """A point uniformly distributed on the upper hemisphere (z >= 0.05 radius, so never on the floor plane)."""
    z = rng.uniform(0.05, 1.0)
    phi = rng.uniform(0.0, 2.0 * math.pi)
    s = math.sqrt(1.0 - z * z)
    return (radius * s * math.cos(phi), radius * s * math.sin(phi), radius * z)


def hemisphere_spiral(i, count, radius):
    """The i-th of `count` points on a spiral: two turns around z while the elevation rises from 15 to 60 degrees."""
    t = (i + 0.5) / count
    elevation = math.radians(15.0 + 45.0 * t)
    phi = 4.0 * math.pi * t
    return (radius * math.cos(elevation) * math.cos(phi), radius * math.cos(elevation) * math.sin(phi),
            radius * math.sin(elevation))


def render_split(bpy, camera, args, split, positions):
    scene = bpy.context.scene
    folder = os.path.join(args.out, split)
    os.makedirs(folder, exist_ok=True)
    frames = []
    for i, position in enumerate(positions):
        look_at_origin(camera, position)
        bpy.context.view_layer.update()
        scene.render.filepath = os.path.join(folder, "r_%d.png" % i)
        bpy.ops.render.render(write_still=True)
        if not os.path.exists(scene.render.filepath):
            fail("Cycles wrote no image to " + scene.render.filepath)
        frames.append({"file_path": "./%s/r_%d" % (split, i),
                       "transform_matrix": [list(row) for row in camera.matrix_world]})
        print("make-nerf-dataset.py: %s %d/%d" % (split, i + 1, len(positions)), file=sys.stderr, flush=True)
    with open(os.path.join(args.out, "transforms_%s.json" % split), "w") as f:
        json.dump({"camera_angle_x": args.fov, "frames": frames}, f, indent=2)


def main():
    args = parse_args(script_args())
    try:
        import bpy
    except ImportError:
        fail("run this script through Blender: blender -b --factory-startup --python " + sys.argv[0] + " -- MODEL OUT")
    if not os.path.isfile(args.model):
        fail(args.model + ": no such file")
    if min(args.train, args.test) < 1 or args.val < 0 or args.size < 8 or args.spp < 1:
        fail("need at least one training and one test view, images of 8 pixels or more and 1 sample or more")
    os.makedirs(args.out, exist_ok=True)

    meshes = import_model(bpy, args.model)
    scale = normalise(bpy, meshes)
    camera = set_up_cycles(bpy, args)
    print("make-nerf-dataset.py: %s, %d meshes, scaled by %.4g; %d/%d/%d views of %dx%d at %d spp"
          % (args.model, len(meshes), 1 / scale, args.train, args.val, args.test, args.size, args.size, args.spp),
          file=sys.stderr, flush=True)

    rng = random.Random(args.seed)
    render_split(bpy, camera, args, "train", [hemisphere_uniform(rng, args.radius) for _ in range(args.train)])
    if args.val:
        render_split(bpy, camera, args, "val", [hemisphere_spiral(i + 0.5, args.val, args.radius) for i in range(args.val)])
    render_split(bpy, camera, args, "test", [hemisphere_spiral(i, args.test, args.radius) for i in range(args.test)])


if __name__ == "__main__":
    main()
