"""Render a glTF 2.0 scene with Blender 3.4 Cycles as a reference image.

Usage (everything after "--" belongs to this script):

    blender -b --factory-startup --python-exit-code 1 \\
        --python scripts/cycles-reference.py -- SCENE.gltf --out OUT.exr \\
        [--size WxH] [--spp N] [--depth D] [--seed S] \\
        [--env FILE.exr] [--env-strength F] [--threads T] \\
        [--time-log CSV] [--default-camera] [--camera NAME] \\
        [--lighting-mode SPEC|COMPAT|RAW] [--cycles-lights] \\
        [--materials matched|imported|imported-burley]

    blender -b --factory-startup --python scripts/cycles-reference.py -- --help

Exit status: 0 success, 2 bad arguments / missing or unreadable scene,
1 anything else (with --python-exit-code 1; without it Blender exits 0 after
an uncaught Python exception).

What it does
  1. Clears the factory startup scene (objects, meshes, cameras, lights,
     materials), imports SCENE with Blender's glTF importer
     (io_scene_gltf2; numpy.bool is aliased first, the importer needs it).
  2. Picks the camera: --camera NAME, else the first glTF node (in node index
     order) that has a camera, else the default camera (see below).
  3. Material fix-ups so Cycles renders what CrossRT models (--materials
     matched, the default; --materials imported leaves the importer's
     Principled BSDFs as they are, and imported-burley only sets Specular 0
     on its non-metals, to measure its diffuse model alone):
     * "Pure diffuse" materials -- metallicFactor 0, no transmission (absent
       or transmissionFactor 0), KHR_materials_specular.specularFactor 0, and
       no clearcoat/sheen -- are Lambertian in CrossRT.  The importer turns
       them into a Principled BSDF (Burley diffuse, and it even keeps the
       specular layer: it ignores specularFactor and derives Principled
       "Specular" from specularColorFactor and the IOR only).  So for such
       materials the Principled BSDF is replaced by a Diffuse BSDF
       (roughness 0 = Lambert) with the same Base Color (linked texture or
       value) and Normal input, plus, if the material emits, an Emission
       shader (same colour and strength) through an Add Shader, plus, if
       alpha < 1 or textured, a Mix with a Transparent BSDF.  Classification
       uses the glTF JSON; Blender materials are matched by the importer's
       naming rule (name, or "Material_<index>", possibly with ".NNN").
     * Non-metal materials (metallicFactor 0, no transmission or sheen)
       that are not pure diffuse get glTF 2.0's dielectric BRDF as CrossRT
       evaluates it, instead of the Principled BSDF's Burley diffuse under an
       added specular layer (on 2CylinderEngine under an HDR map that renders
       13% brighter): the specular layer is a black Principled BSDF (its
       Fresnel follows the microfacet normal; Specular = F0 / 0.08 for F0 from
       KHR_materials_ior's IOR, 1.5, times KHR_materials_specular's factor),
       plus a Lambert Diffuse BSDF of the base colour weighted by a Mix
       Shader by (1 - F0)(1 - g(n.v)): what CrossRT's 1 - F(v.h) leaves of the
       base, averaged over the light's directions (see base_fresnel; a
       Fresnel node of the shading normal took the whole base away at grazing
       views, and rendered a closed room of rough walls 4-8% darker than
       CrossRT).  A KHR_materials_clearcoat layer is left out, as CrossRT
       leaves it out.
     * Every remaining Principled BSDF gets distribution 'GGX' (single
       scattering), not multiscatter GGX.
     * Punctual lights get radius 0 (point/spot shadow_soft_size, sun angle;
       Blender's default is a 0.25 m sphere), except CrossRT's lights with a
       size: a point light whose glTF extras give a "radius" (a sphere light)
       or a "width" and "height" (a rectangle) becomes an opaque mesh of that
       shape with an Emission shader of the same radiance.  CrossRT's sphere
       and rectangle lights stop every ray that meets them, camera, BSDF and
       shadow rays alike, as a glowing object would; Cycles' lights let every
       ray through.  --cycles-lights keeps them Cycles lights instead: a
       sphere light of that radius, and a rectangular area light (Cycles'
       area light of power P sends P / (4 A)), both visible to camera rays.
       With the importer's default
       --lighting-mode SPEC a point/spot light of glTF intensity I (cd) has
       radiant intensity I/683 W/sr in Cycles, a sun of E lux has irradiance
       E/683 W/m^2.  COMPAT: I W/sr and E W/m^2.  RAW: Blender Watts = I.
       Blender's spot_blend smoothstep differs from glTF's cone falloff.
  4. Render settings: Cycles on the CPU; resolution W x H at 100 %; samples
     N; seed S (not animated); no adaptive sampling, no denoising, no sample
     clamping, no glossy blur, light_sampling_threshold 0, path guiding off,
     MIS direct light sampling; BOX pixel filter of width 1 px; max, diffuse,
     glossy, transmission, volume and transparent bounces all = D; reflective
     and refractive caustics on; film not transparent; view transform
     Standard, look None, exposure 0, gamma 1; a glTF camera's clip_end is
     raised to at least 1e4 (clip_start = glTF znear is kept).  The glTF
     importer sets the camera's vertical FOV = yfov (sensor fit VERTICAL)
     and ignores aspectRatio: the aspect is W/H of --size.  Note that the
     importer creates objects for ALL nodes of the file, also nodes outside
     the default scene.
  5. World: black (strength 0) unless --env FILE.exr is given; then an
     Environment Texture (equirectangular, Linear interpolation, linear
     colour space) into a Background of strength --env-strength (1).
  6. Writes OUT as OpenEXR, RGB (no alpha), 32-bit float, ZIP, scene linear.
     Prints "cycles: W x H, N spp, T s" (T = wall time of the render call:
     scene sync + BVH build + path tracing, without the file write).
     With --time-log CSV it instead renders at spp = 1, 2, 4, ... , N (N is
     appended if it is not a power of two), each a separate render with the
     same seed, writes OUT with "_sppNNNN" before the extension
     (ref_spp0004.exr) and appends "spp,seconds,path" lines to CSV (a header
     line is written when the CSV is new or empty).

Default camera (--default-camera, or automatically when the scene has no
camera).  CrossRT applies the same rule.  In glTF coordinates (Y up):
    lo, hi  = axis-aligned bounds of the world-space positions of all mesh
              vertices of the scene (node transforms applied);
    centre  = (lo + hi) / 2,  radius = |hi - lo| / 2  (half the diagonal;
              radius = 1 and centre = 0 if there is no geometry or it is a
              single point);
    yfov    = 0.6911112 rad (vertical), aspect = W / H;
    position = centre + (0, 0, radius / sin(yfov / 2)), identity rotation
              (looks down -z at the centre, +y up);
    znear   = 0.01 * radius, zfar = 100 * radius.
The bounding sphere fits the vertical field of view exactly; for W < H it may
be cropped horizontally.

Environment map convention (verified empirically: 1x1-pixel renders with a
0.0001 rad camera looking along 16 glTF directions at a 1024x512 equirect
whose pixels store their own (u, v); all matched the formula within 2e-6,
and looking along -x returned 0.5, the wrapped average across the seam).
For a glTF world direction d = (x, y, z) (unit, pointing away from the
scene) Cycles looks up
    u = 0.5 + atan2(z, x) / (2 pi)      (u in [0, 1], 0 = left image edge)
    v = 0.5 + asin(y) / pi              (v = 1 at the TOP image row)
i.e. with the importer's axis change d_b = (x, -z, y) (Blender, Z up), this
is Cycles' direction_to_equirectangular:
    u = 0.5 - atan2(d_b.y, d_b.x) / (2 pi),
    v = 0.5 + atan2(d_b.z, hypot(d_b.x, d_b.y)) / pi.
So glTF +x sees the image centre (u = 0.5), -z (the default glTF camera
direction) sees u = 0.25, +z sees u = 0.75, and -x sees the left/right seam;
+y is the top row.  Pixel column i covers u in [i/W, (i+1)/W], row r counted
from the top covers v in [1 - (r+1)/H, 1 - r/H]; lookups interpolate
bilinearly between pixel centres and wrap around in u.
"""

import argparse
import json
import math
import os
import re
import struct
import sys
import time

import bpy

DEFAULT_YFOV = 0.6911112
PROG = ("blender -b --factory-startup --python-exit-code 1 "
        "--python scripts/cycles-reference.py --")


def fail(msg, code=2):
    sys.stderr.write("cycles-reference: error: %s\n" % msg)
    sys.stderr.flush()
    sys.exit(code)


def note(msg):
    print("cycles-reference: %s" % msg, flush=True)


# ---------------------------------------------------------------- arguments --
def parse_size(text):
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m or int(m.group(1)) < 1 or int(m.group(2)) < 1:
        raise argparse.ArgumentTypeError("expected WxH, e.g. 512x512")
    return int(m.group(1)), int(m.group(2))


def positive_int(text):
    v = int(text)
    if v < 1:
        raise argparse.ArgumentTypeError("must be >= 1")
    return v


def non_negative_int(text):
    v = int(text)
    if v < 0:
        raise argparse.ArgumentTypeError("must be >= 0")
    return v


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(
        prog=PROG,
        description="Render a glTF 2.0 scene with Cycles as an unbiased "
                    "reference image for CrossRT (see the header of "
                    "scripts/cycles-reference.py for the exact settings).")
    p.add_argument("scene", help="glTF 2.0 file (.gltf or .glb)")
    p.add_argument("--out", required=True, help="output OpenEXR file")
    p.add_argument("--size", type=parse_size, default=(512, 512),
                   metavar="WxH", help="image size (default 512x512)")
    p.add_argument("--spp", type=positive_int, default=128,
                   help="samples per pixel (default 128)")
    p.add_argument("--depth", type=non_negative_int, default=8,
                   help="max bounces of every kind (default 8)")
    p.add_argument("--seed", type=int, default=0, help="Cycles seed (0)")
    p.add_argument("--env", metavar="FILE.exr",
                   help="equirectangular environment map (linear EXR)")
    p.add_argument("--env-strength", type=float, default=1.0,
                   help="background strength with --env (default 1)")
    p.add_argument("--threads", type=positive_int,
                   help="fixed number of render threads (default: auto)")
    p.add_argument("--time-log", metavar="CSV",
                   help="render at spp 1,2,4,..,N and append spp,seconds,"
                        "path lines to CSV")
    p.add_argument("--default-camera", action="store_true",
                   help="ignore the scene's cameras and frame the bounding "
                        "box (automatic when the scene has no camera)")
    p.add_argument("--camera", metavar="NAME",
                   help="Blender object name of the camera to use")
    p.add_argument("--cycles-lights", action="store_true",
                   help="keep CrossRT's sphere and rectangle lights as Cycles "
                        "lights, which every ray passes through (default: "
                        "opaque emitting meshes, as CrossRT traces them)")
    p.add_argument("--lighting-mode", choices=("SPEC", "COMPAT", "RAW"),
                   default="SPEC",
                   help="glTF importer's punctual light unit conversion "
                        "(default SPEC)")
    p.add_argument("--materials", choices=("matched", "imported", "imported-burley"),
                   default="matched",
                   help="matched (default): the material fix-ups of step 3, "
                        "so that Cycles renders glTF's BRDF as CrossRT does; "
                        "imported: the importer's Principled BSDFs as they "
                        "come (Blender 3.4: Burley's diffuse with a specular "
                        "layer added on top), as a user who imports the file "
                        "sees them; imported-burley: the same with Specular 0 "
                        "on non-metals (Burley's diffuse alone)")
    return p.parse_args(argv)


# ------------------------------------------------------------- glTF JSON ----
def load_gltf_json(path):
    """The JSON part of a .gltf or .glb file (for material classification and
    camera order; geometry comes from Blender's importer)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":
        if len(data) < 20:
            raise ValueError("truncated GLB header")
        length, chunk_type = struct.unpack_from("<II", data, 12)
        if chunk_type != 0x4E4F534A:
            raise ValueError("first GLB chunk is not JSON")
        data = data[20:20 + length]
    return json.loads(data.decode("utf-8"))


def is_pure_diffuse(m):
    ext = m.get("extensions") or {}
    if "KHR_materials_pbrSpecularGlossiness" in ext or \
            "KHR_materials_unlit" in ext:
        return False
    pbr = m.get("pbrMetallicRoughness") or {}
    if pbr.get("metallicFactor", 1.0) != 0:
        return False
    if (ext.get("KHR_materials_transmission") or {}).get(
            "transmissionFactor", 0.0) != 0:
        return False
    if (ext.get("KHR_materials_clearcoat") or {}).get(
            "clearcoatFactor", 0.0) != 0:
        return False
    if any(c != 0 for c in (ext.get("KHR_materials_sheen") or {}).get(
            "sheenColorFactor", [0, 0, 0])):
        return False
    if "KHR_materials_specular" not in ext:
        return False
    return ext["KHR_materials_specular"].get("specularFactor", 1.0) == 0


def material_class(m):
    """'diffuse' (Lambert in CrossRT), 'dielectric' (glTF's dielectric BRDF:
    GGX specular over diffuse, mixed by Fresnel; a clearcoat is dropped, as
    CrossRT drops it) or 'principled' (left to the Principled BSDF)."""
    if is_pure_diffuse(m):
        return "diffuse"
    ext = m.get("extensions") or {}
    if "KHR_materials_pbrSpecularGlossiness" in ext or \
            "KHR_materials_unlit" in ext:
        return "principled"
    pbr = m.get("pbrMetallicRoughness") or {}
    if pbr.get("metallicFactor", 1.0) != 0:
        return "principled"
    if (ext.get("KHR_materials_transmission") or {}).get(
            "transmissionFactor", 0.0) != 0:
        return "principled"
    if any(c != 0 for c in (ext.get("KHR_materials_sheen") or {}).get(
            "sheenColorFactor", [0, 0, 0])):
        return "principled"
    return "dielectric"


def dielectric_f0_scale(m):
    """glTF dielectric: (IOR, specularFactor) of KHR_materials_ior/_specular."""
    ext = m.get("extensions") or {}
    ior = (ext.get("KHR_materials_ior") or {}).get("ior", 1.5)
    spec = (ext.get("KHR_materials_specular") or {}).get("specularFactor", 1.0)
    return ior, spec


def gltf_base_name(blender_name, known):
    """Map a Blender ID name back to the glTF name it was created from."""
    if blender_name in known:
        return blender_name
    m = re.fullmatch(r"(.*)\.\d{3}", blender_name)
    if m and m.group(1) in known:
        return m.group(1)
    return None


# ----------------------------------------------------------------- scene ----
def clear_scene():
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.cameras,
                       bpy.data.lights, bpy.data.materials):
        for item in list(collection):
            collection.remove(item)


def import_gltf(path, lighting_mode):
    import numpy
    numpy.bool = numpy.bool_          # the 3.4 importer uses numpy.bool
    try:
        result = bpy.ops.import_scene.gltf(
            filepath=path, convert_lighting_mode=lighting_mode)
    except Exception as e:          # the operator raises on bad files
        fail("importing %s failed: %s" % (path, e))
    if "FINISHED" not in result:
        fail("importing %s failed: %s" % (path, result))
    bpy.context.view_layer.update()


def choose_camera(scene, gltf, wanted):
    cams = [o for o in scene.objects if o.type == "CAMERA"]
    if wanted:
        for o in cams:
            if o.name == wanted:
                return o
        fail("no camera object named %r (cameras: %s)"
             % (wanted, ", ".join(o.name for o in cams) or "none"))
    if not cams:
        return None
    if len(cams) == 1:
        return cams[0]
    # Several cameras: the first glTF node (index order) with a camera.  The
    # importer names the object after the node, else after the camera.
    by_name = {o.name: o for o in cams}
    for node in gltf.get("nodes", []):
        if node.get("camera") is None:
            continue
        cam = gltf["cameras"][node["camera"]]
        name = node.get("name") or cam.get("name") or "Camera"
        for o in sorted(cams, key=lambda o: o.name):
            if gltf_base_name(o.name, {name}) == name:
                note("%d cameras; using the first glTF camera node: %s"
                     % (len(cams), o.name))
                return o
    chosen = sorted(by_name)[0]
    note("%d cameras; using %s" % (len(cams), chosen))
    return by_name[chosen]


def scene_bounds_gltf(scene):
    """World-space AABB of all mesh vertices, in glTF axes (Y up).
    Blender (bx, by, bz) = glTF (x, -z, y), so glTF = (bx, bz, -by)."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for o in scene.objects:
        if o.type != "MESH":
            continue
        mw = o.matrix_world
        for v in o.data.vertices:
            b = mw @ v.co
            g = (b.x, b.z, -b.y)
            for k in range(3):
                lo[k] = min(lo[k], g[k])
                hi[k] = max(hi[k], g[k])
    if lo[0] == math.inf:
        return None
    return lo, hi


def add_default_camera(scene, width, height, prefix):
    bounds = scene_bounds_gltf(scene)
    if bounds is None:
        centre, radius = [0.0, 0.0, 0.0], 1.0
    else:
        lo, hi = bounds
        centre = [(a + b) / 2 for a, b in zip(lo, hi)]
        radius = math.sqrt(sum((b - a) ** 2 for a, b in zip(lo, hi))) / 2
        if radius <= 0.0:
            radius = 1.0
    yfov = DEFAULT_YFOV
    dist = radius / math.sin(yfov / 2)
    pos = (centre[0], centre[1], centre[2] + dist)          # glTF axes
    cam = bpy.data.cameras.new("DefaultCamera")
    cam.lens_unit = "FOV"
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = yfov
    cam.clip_start = 0.01 * radius
    cam.clip_end = 100.0 * radius
    obj = bpy.data.objects.new("DefaultCamera", cam)
    scene.collection.objects.link(obj)
    obj.location = (pos[0], -pos[2], pos[1])                # Blender axes
    obj.rotation_euler = (math.pi / 2, 0.0, 0.0)  # -z(cam) -> +y(Blender)
    bpy.context.view_layer.update()
    print(prefix + "glTF position (%.6g, %.6g, %.6g) looking down -z, "
         "centre (%.6g, %.6g, %.6g), radius %.6g, yfov %.7g rad, aspect %.6g, "
         "znear %.6g, zfar %.6g"
         % (pos + tuple(centre) + (radius, yfov, width / height,
                                    cam.clip_start, cam.clip_end)),
          flush=True)
    return obj


def emitting_mesh(scene, light_object, shape, size, radiance):
    """An opaque mesh in place of a light with a shape, emitting `radiance`
    (RGB, W/(m^2 sr)): a sphere of radius size[0], or a size[0] x size[1]
    rectangle that emits towards the light's -z and is black behind.  Cycles'
    lights let every ray through (camera, BSDF and shadow rays), CrossRT's
    sphere and rectangle lights stop them, as a glowing object would; the
    mesh makes Cycles do the same.  An Emission closure of strength s sends
    radiance s, and a surface with nothing but emission ends a path."""
    if shape == "SPHERE":
        bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128,
                                             radius=size[0])
    else:
        bpy.ops.mesh.primitive_plane_add(size=1.0)
    mesh_object = bpy.context.active_object
    mesh_object.matrix_world = light_object.matrix_world.copy()
    if shape == "RECTANGLE":
        mesh_object.scale = (size[0], size[1], 1.0)
    if shape == "SPHERE":
        for polygon in mesh_object.data.polygons:
            polygon.use_smooth = True
    material = bpy.data.materials.new(light_object.name + "_emitter")
    material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (radiance[0], radiance[1],
                                              radiance[2], 1.0)
    emission.inputs["Strength"].default_value = 1.0
    shader = emission.outputs["Emission"]
    if shape == "RECTANGLE":  # the plane's normal is +z: it emits from its back
        black = tree.nodes.new("ShaderNodeEmission")
        black.inputs["Strength"].default_value = 0.0
        geometry = tree.nodes.new("ShaderNodeNewGeometry")
        mix = tree.nodes.new("ShaderNodeMixShader")
        tree.links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
        tree.links.new(black.outputs["Emission"], mix.inputs[1])
        tree.links.new(emission.outputs["Emission"], mix.inputs[2])
        shader = mix.outputs["Shader"]
    tree.links.new(shader, output.inputs["Surface"])
    mesh_object.data.materials.append(material)
    bpy.data.objects.remove(light_object, do_unlink=True)
    return mesh_object


def fix_lights(scene, opaque_shapes):
    for o in list(scene.objects):
        if o.type != "LIGHT":
            continue
        light = o.data
        # CrossRT's lights with a size: a glTF point light whose extras (the
        # importer's custom properties) give a radius is a sphere, one with a
        # width and height a rectangle facing the node's -z.
        radius = float(light.get("radius", 0.0))
        width, height = float(light.get("width", 0.0)), float(light.get("height", 0.0))
        if radius > 0.0 or (width > 0.0 and height > 0.0):
            o.visible_camera = True  # CrossRT's camera rays see them too
        # A point light of Blender energy P sends P / (4 pi) W/sr: over a
        # sphere's disc, or over the rectangle, that is its radiance.
        colour, name = tuple(light.color), o.name
        if opaque_shapes and light.type == "POINT" and radius > 0.0:
            value = light.energy / (4.0 * math.pi) / (math.pi * radius * radius)
            emitting_mesh(scene, o, "SPHERE", (radius,),
                          tuple(c * value for c in colour))
            note("light %s: an emitting sphere of radius %g, radiance %g"
                 % (name, radius, value))
            continue
        if opaque_shapes and light.type == "POINT" and width > 0.0 and height > 0.0:
            value = light.energy / (4.0 * math.pi) / (width * height)
            emitting_mesh(scene, o, "RECTANGLE", (width, height),
                          tuple(c * value for c in colour))
            note("light %s: an emitting %g x %g rectangle, radiance %g"
                 % (name, width, height, value))
            continue
        if light.type == "POINT" and radius > 0.0:
            light.shadow_soft_size = radius
            note("light %s: a sphere of radius %g, Blender energy %g"
                 % (o.name, radius, light.energy))
            continue
        if light.type == "POINT" and width > 0.0 and height > 0.0:
            energy = light.energy
            light.type = "AREA"
            light = o.data
            light.shape = "RECTANGLE"
            light.size, light.size_y = width, height
            # The same radiance, intensity / area: the point light's power is
            # 4 pi I, and Cycles' area light of power P sends P / (4 A)
            # (measured: seen directly, P / (pi A) would be 27% brighter).
            light.energy = energy / math.pi
            note("light %s: a %g x %g rectangle, Blender energy %g"
                 % (o.name, width, height, light.energy))
            continue
        if light.type in ("POINT", "SPOT"):
            light.shadow_soft_size = 0.0
        elif light.type == "SUN":
            light.angle = 0.0
        note("light %s: %s, Blender energy %g, radius set to 0"
             % (o.name, light.type, light.energy))


# ------------------------------------------------------------- materials ----
def copy_input(tree, src, dst):
    if src.is_linked:
        tree.links.new(src.links[0].from_socket, dst)
    else:
        dst.default_value = src.default_value


def lambert(tree, p):
    """A Diffuse BSDF of roughness 0 (Lambert) with p's colour and normal."""
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.location = p.location
    diffuse.inputs["Roughness"].default_value = 0.0
    copy_input(tree, p.inputs["Base Color"], diffuse.inputs["Color"])
    if p.inputs["Normal"].is_linked:
        copy_input(tree, p.inputs["Normal"], diffuse.inputs["Normal"])
    return diffuse.outputs["BSDF"]


# Ours weighs the base of glTF's dielectric by 1 - F(v.h), with Schlick's F of
# the microfacet normal h = normalize(v + l).  Averaged over the directions l
# light comes from (cosine-weighted), that is 1 - F0 - (1 - F0) g(n.v), with
#   g(mu) = integral over the hemisphere of (1 - v.h)^5 cos(l) / pi dl,
# which depends on the view alone.  These are a fit of g in t = 1 - mu
# (numerical integration, 800 x 1600 directions; the fit is within 8e-6 of it;
# g(1) = 0.00008, g(0.5) = 0.0050, g(0) = 0.028).
BASE_FRESNEL_FIT = (8.95188019e-03, 7.79726926e-03, 9.30993250e-03,
                    2.02211075e-03, 8.23312910e-05)


def math_node(tree, operation, a, b=None, c=None):
    """A Math node; each input is a socket or a number."""
    node = tree.nodes.new("ShaderNodeMath")
    node.operation = operation
    for i, value in enumerate((a, b, c)):
        if value is None:
            continue
        if isinstance(value, (int, float)):
            node.inputs[i].default_value = value
        else:
            tree.links.new(value, node.inputs[i])
    return node.outputs["Value"]


def base_fresnel(tree, p, f0):
    """The share of light the base of glTF's dielectric loses to its
    specular layer, seen from the view direction: F0 + (1 - F0) g(n.v)."""
    geometry = tree.nodes.new("ShaderNodeNewGeometry")
    geometry.location = (p.location[0] - 400, p.location[1] + 150)
    normal = geometry.outputs["Normal"]
    if p.inputs["Normal"].is_linked:
        normal = p.inputs["Normal"].links[0].from_socket
    dot = tree.nodes.new("ShaderNodeVectorMath")
    dot.operation = "DOT_PRODUCT"
    tree.links.new(geometry.outputs["Incoming"], dot.inputs[0])
    tree.links.new(normal, dot.inputs[1])
    mu = math_node(tree, "ABSOLUTE", dot.outputs["Value"])
    t = math_node(tree, "SUBTRACT", 1.0, mu)
    g = BASE_FRESNEL_FIT[0]
    for c in BASE_FRESNEL_FIT[1:]:  # Horner: g = g t + c
        g = math_node(tree, "MULTIPLY_ADD", g, t, c)
    return math_node(tree, "MULTIPLY_ADD", g, 1.0 - f0, f0)


def gltf_dielectric(tree, p, ior, specular):
    """glTF 2.0's dielectric BRDF as CrossRT evaluates it: a GGX reflection
    whose Fresnel follows the microfacet normal (the Principled BSDF itself,
    black, so that only its specular layer is left: Specular = F0 / 0.08 for
    F0 from the IOR times KHR_materials_specular's factor) plus a Lambert base
    weighted by 1 - F(v.h) averaged over the light's directions (see
    base_fresnel): exact for light that comes from all directions alike, as in
    a room; a Fresnel node (of the shading normal) would take the base away
    at grazing views, where CrossRT keeps 97% of it."""
    base = lambert(tree, p)
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2 * specular
    weight = base_fresnel(tree, p, f0)
    under = tree.nodes.new("ShaderNodeMixShader")  # (1 - F) base + F nothing
    under.location = (p.location[0] + 200, p.location[1])
    tree.links.new(weight, under.inputs["Fac"])
    tree.links.new(base, under.inputs[1])
    coat = tree.nodes.new("ShaderNodeBsdfPrincipled")
    coat.location = (p.location[0], p.location[1] - 300)
    coat.distribution = "GGX"
    coat.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    coat.inputs["Metallic"].default_value = 0.0
    coat.inputs["Specular"].default_value = f0 / 0.08
    coat.inputs["Specular Tint"].default_value = 0.0
    coat.inputs["Sheen"].default_value = 0.0
    coat.inputs["Clearcoat"].default_value = 0.0
    coat.inputs["IOR"].default_value = ior
    copy_input(tree, p.inputs["Roughness"], coat.inputs["Roughness"])
    if p.inputs["Normal"].is_linked:
        copy_input(tree, p.inputs["Normal"], coat.inputs["Normal"])
    add = tree.nodes.new("ShaderNodeAddShader")
    add.location = (p.location[0] + 400, p.location[1])
    tree.links.new(under.outputs["Shader"], add.inputs[0])
    tree.links.new(coat.outputs["BSDF"], add.inputs[1])
    return add.outputs["Shader"]


def replace_principled(mat, surface, kind):
    """Replace the material's Principled BSDF by surface(tree, p) (+ emission,
    + alpha).  Returns a short description or None."""
    tree = mat.node_tree
    principled = [n for n in tree.nodes
                  if n.bl_idname == "ShaderNodeBsdfPrincipled"]
    if len(principled) != 1:
        note("warning: material %s has %d Principled BSDF nodes; not swapped"
             % (mat.name, len(principled)))
        return None
    p = principled[0]
    targets = [link.to_socket for link in p.outputs["BSDF"].links]
    shader = surface(tree, p)
    parts = [kind]

    colour, strength = p.inputs["Emission"], p.inputs["Emission Strength"]
    emits = (strength.is_linked or strength.default_value != 0) and \
        (colour.is_linked or any(c != 0 for c in colour.default_value[:3]))
    if emits:
        emission = tree.nodes.new("ShaderNodeEmission")
        emission.location = (p.location[0], p.location[1] - 250)
        copy_input(tree, colour, emission.inputs["Color"])
        copy_input(tree, strength, emission.inputs["Strength"])
        add = tree.nodes.new("ShaderNodeAddShader")
        add.location = (p.location[0] + 200, p.location[1])
        tree.links.new(shader, add.inputs[0])
        tree.links.new(emission.outputs["Emission"], add.inputs[1])
        shader = add.outputs["Shader"]
        parts.append("emission")

    alpha = p.inputs["Alpha"]
    if alpha.is_linked or alpha.default_value < 1.0:
        transparent = tree.nodes.new("ShaderNodeBsdfTransparent")
        mix = tree.nodes.new("ShaderNodeMixShader")
        copy_input(tree, alpha, mix.inputs["Fac"])
        tree.links.new(transparent.outputs["BSDF"], mix.inputs[1])
        tree.links.new(shader, mix.inputs[2])
        shader = mix.outputs["Shader"]
        parts.append("alpha")

    for socket in targets:
        tree.links.new(shader, socket)
    tree.nodes.remove(p)
    return "+".join(parts)


def fix_materials(scene, gltf, mode):
    if mode != "matched":
        unlayered = []
        for m in bpy.data.materials:
            for n in (m.node_tree.nodes if m.node_tree else []):
                if n.bl_idname == "ShaderNodeBsdfPrincipled" and \
                        mode == "imported-burley" and \
                        not n.inputs["Metallic"].is_linked and \
                        n.inputs["Metallic"].default_value == 0.0:
                    n.inputs["Specular"].default_value = 0.0
                    unlayered.append(m.name)
        note("materials as imported%s" % (
            "; Specular 0 on %s" % ", ".join(unlayered) if unlayered else ""))
        return
    classes, f0 = {}, {}
    for i, m in enumerate(gltf.get("materials", [])):
        name = m.get("name") or "Material_%d" % i
        classes.setdefault(name, set()).add(material_class(m))
        f0[name] = dielectric_f0_scale(m)

    used = []
    for o in scene.objects:
        for slot in getattr(o, "material_slots", []):
            if slot.material and slot.material not in used:
                used.append(slot.material)

    swapped, kept = [], []
    for mat in used:
        if not mat.use_nodes:
            continue
        base = gltf_base_name(mat.name, classes)
        kind = classes.get(base)
        what = None
        if kind == {"diffuse"}:
            what = replace_principled(mat, lambert, "diffuse")
        elif kind == {"dielectric"}:
            ior, spec = f0[base]
            what = replace_principled(
                mat, lambda t, p: gltf_dielectric(t, p, ior, spec),
                "glTF dielectric")
        elif kind and len(kind) > 1:
            note("warning: several glTF materials are named %r and they are "
                 "not all alike; %s keeps its Principled BSDF" % (base, mat.name))
        if what:
            swapped.append("%s (%s)" % (mat.name, what))
        else:
            kept.append(mat.name)

    ggx = 0
    trees = [m.node_tree for m in bpy.data.materials if m.node_tree]
    trees += list(bpy.data.node_groups)
    for tree in trees:
        for n in tree.nodes:
            if n.bl_idname == "ShaderNodeBsdfPrincipled":
                n.distribution = "GGX"
                ggx += 1
    note("materials swapped to Lambert or glTF's dielectric: %s"
         % (", ".join(swapped) or "none"))
    note("materials kept as Principled BSDF (distribution GGX, %d nodes): %s"
         % (ggx, ", ".join(kept) or "none"))


# --------------------------------------------------------- render settings --
def setp(owner, name, value):
    if hasattr(owner, name):
        setattr(owner, name, value)
    else:
        note("warning: %s has no property %s (Blender version?)"
             % (type(owner).__name__, name))


def configure_render(scene, args):
    width, height = args.size
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y = width, height
    r.resolution_percentage = 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.use_border = False
    r.film_transparent = False
    r.use_motion_blur = False
    r.use_persistent_data = False
    r.use_compositing = False
    r.use_sequencer = False
    if args.threads:
        r.threads_mode = "FIXED"
        r.threads = args.threads
    else:
        r.threads_mode = "AUTO"

    c = scene.cycles
    c.device = "CPU"
    c.samples = args.spp
    c.seed = args.seed
    c.use_animated_seed = False
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.light_sampling_threshold = 0.0
    setp(c, "use_guiding", False)
    setp(c, "direct_light_sampling_type", "MULTIPLE_IMPORTANCE_SAMPLING")
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.film_exposure = 1.0
    for name in ("max_bounces", "diffuse_bounces", "glossy_bounces",
                 "transmission_bounces", "volume_bounces",
                 "transparent_max_bounces"):
        setattr(c, name, args.depth)
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0
    c.caustics_reflective = True
    c.caustics_refractive = True
    setp(c, "use_fast_gi", False)

    v = scene.view_settings
    scene.display_settings.display_device = "sRGB"
    v.view_transform = "Standard"
    v.look = "None"
    v.exposure = 0.0
    v.gamma = 1.0
    v.use_curve_mapping = False

    im = r.image_settings
    im.file_format = "OPEN_EXR"
    im.color_mode = "RGB"
    im.color_depth = "32"
    im.exr_codec = "ZIP"


def configure_world(scene, env, strength):
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    tree = world.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputWorld")
    bg = tree.nodes.new("ShaderNodeBackground")
    tree.links.new(bg.outputs["Background"], out.inputs["Surface"])
    if env is None:
        bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        bg.inputs["Strength"].default_value = 0.0
        return
    try:
        image = bpy.data.images.load(os.path.abspath(env))
    except RuntimeError as e:
        fail("cannot load environment map %s: %s" % (env, e))
    for space in ("Linear", "Linear Rec.709", "Non-Color"):
        try:
            image.colorspace_settings.name = space
            break
        except TypeError:
            continue
    tex = tree.nodes.new("ShaderNodeTexEnvironment")
    tex.image = image
    tex.projection = "EQUIRECTANGULAR"
    tex.interpolation = "Linear"
    tree.links.new(tex.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = strength
    note("environment %s (%d x %d, %s), strength %g"
         % (env, image.size[0], image.size[1],
            image.colorspace_settings.name, strength))


# ----------------------------------------------------------------- render ----
def render_to(scene, path):
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    seconds = time.perf_counter() - t0
    result = bpy.data.images["Render Result"]
    directory = os.path.dirname(path)
    if directory:
        os.makedirs(directory, exist_ok=True)
    result.save_render(filepath=path, scene=scene)
    if not os.path.exists(path):
        fail("Cycles did not write %s" % path, 1)
    return seconds


def spp_schedule(n):
    s, p = [], 1
    while p < n:
        s.append(p)
        p *= 2
    s.append(n)
    return s


def main():
    args = parse_args()
    scene_path = os.path.abspath(args.scene)
    out_path = os.path.abspath(args.out)
    if not os.path.isfile(scene_path):
        fail("scene file not found: %s" % args.scene)
    if args.env is not None and not os.path.isfile(args.env):
        fail("environment map not found: %s" % args.env)
    if not out_path.lower().endswith(".exr"):
        fail("--out must name an .exr file")
    try:
        gltf = load_gltf_json(scene_path)
    except (OSError, ValueError, UnicodeDecodeError) as e:
        fail("cannot read %s as glTF: %s" % (args.scene, e))

    clear_scene()
    scene = bpy.context.scene
    import_gltf(scene_path, args.lighting_mode)

    width, height = args.size
    camera = None if args.default_camera else \
        choose_camera(scene, gltf, args.camera)
    if camera is None:
        prefix = "cycles-reference: default camera: " if args.default_camera \
            else "note: the scene has no camera; using the default camera: "
        camera = add_default_camera(scene, width, height, prefix)
    else:
        camera.data.clip_end = max(camera.data.clip_end, 1e4)
    scene.camera = camera
    note("camera %s: yfov %.7g rad (vertical), clip %g .. %g"
         % (camera.name, camera.data.angle_y, camera.data.clip_start,
            camera.data.clip_end))

    fix_lights(scene, not args.cycles_lights)
    fix_materials(scene, gltf, args.materials)
    configure_render(scene, args)
    configure_world(scene, args.env, args.env_strength)
    note("Cycles: depth %d, seed %d, sampling pattern %s, threads %s"
         % (args.depth, args.seed, scene.cycles.sampling_pattern,
            args.threads or "auto"))

    if not args.time_log:
        seconds = render_to(scene, out_path)
        print("cycles: %d x %d, %d spp, %.3f s" % (width, height, args.spp,
                                                    seconds), flush=True)
        note("wrote %s" % out_path)
        return

    stem, ext = os.path.splitext(out_path)
    log = os.path.abspath(args.time_log)
    new_log = not os.path.exists(log) or os.path.getsize(log) == 0
    with open(log, "a") as f:
        if new_log:
            f.write("spp,seconds,path\n")
        for spp in spp_schedule(args.spp):
            scene.cycles.samples = spp
            path = "%s_spp%04d%s" % (stem, spp, ext)
            seconds = render_to(scene, path)
            print("cycles: %d x %d, %d spp, %.3f s" % (width, height, spp,
                                                        seconds), flush=True)
            f.write("%d,%.6f,%s\n" % (spp, seconds, path))
            f.flush()
    note("wrote %s_spp*.exr and %s" % (stem, log))


if __name__ == "__main__":
    main()
