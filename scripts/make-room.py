#!/usr/bin/env python3
"""Write a room as an artist would make it, as a self-contained glTF 2.0 file.

Usage:
    python3 scripts/make-room.py [--lambert] OUT.gltf

Where scripts/make-cornell-box.py writes a scene tuned to what CrossRT models
(walls whose KHR_materials_specular factor is 0, so that they are Lambertian),
this room uses glTF's defaults the way an exporter writes them: walls of
metallicFactor 0 with no roughnessFactor (glTF's default, 1) and no specular
extension, so every wall has glTF's dielectric specular layer; an emissive
ceiling panel with KHR_materials_emissive_strength and a white base colour; a
rough gold sphere; a grey box of roughness 0.5; a glTF camera inside the room.
It is the scene of issue 51's comparison with Cycles through Blender's glTF
importer.  The file is deterministic byte for byte (the geometry helpers and
the writer are make-cornell-box.py's).

Scene (Y up, metres):
  * A closed room x in [-2, 2], y in [0, 2.5], z in [-2.5, 2.5]: plaster
    white back and front walls and ceiling, a terracotta left wall, a sage
    green right wall, an oak-brown floor.
  * "Panel": a 1.2 x 0.8 m quad 1 mm below the ceiling at (0, 2.499, -0.6),
    facing down; base colour 0.8, emissiveFactor (1, 0.92, 0.8), emissive
    strength 8 (radiance 8 x that, W / (sr m^2)).
  * "GoldSphere": a unit UV sphere scaled to radius 0.5 at (0.8, 0.5, -1.0):
    glTF's gold (1, 0.766, 0.336), metallic 1, roughness 0.45.
  * "GreyBox": 0.7 x 0.9 x 0.7 at (-0.9, 0.45, -1.1), turned 25 degrees about
    +y: base colour 0.4, metallic 0, roughness 0.5.
  * "Camera" at (0, 1.3, 2.3), tilted 8 degrees down, yfov 1.0 rad, aspect 1.
  * With --lambert, every non-metal gets KHR_materials_specular with factor 0
    (no specular layer: Lambertian in CrossRT, a Diffuse BSDF in Cycles), to
    tell the dielectric layer's part of a difference from the rest's.
"""

import importlib.util
import math
import os
import sys

GENERATOR = "CrossRT scripts/make-room.py"


def cornell_helpers():
    """make-cornell-box.py as a module (its name has dashes)."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                        "make-cornell-box.py")
    spec = importlib.util.spec_from_file_location("make_cornell_box", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


cb = cornell_helpers()

ROOM_HALF_X, ROOM_HEIGHT, ROOM_HALF_Z = 2.0, 2.5, 2.5


def dielectric(name, colour, roughness=None):
    """A non-metal as an exporter writes it: roughness left at glTF's default
    (1) unless given, no specular extension."""
    pbr = {"baseColorFactor": list(colour) + [1.0], "metallicFactor": 0.0}
    if roughness is not None:
        pbr["roughnessFactor"] = roughness
    return {"name": name, "pbrMetallicRoughness": pbr}


def room_walls():
    """Six walls, each (name, geometry); normals point into the room."""
    x, h, z = ROOM_HALF_X, ROOM_HEIGHT, ROOM_HALF_Z
    specs = [
        # name,        centre,         u,             v     (u x v = normal)
        ("Floor",      (0.0, 0.0, 0.0), (0, 0, z), (x, 0, 0)),
        ("Ceiling",    (0.0, h, 0.0), (x, 0, 0), (0, 0, z)),
        ("BackWall",   (0.0, h / 2, -z), (x, 0, 0), (0, h / 2, 0)),
        ("FrontWall",  (0.0, h / 2, z), (0, h / 2, 0), (x, 0, 0)),
        ("LeftWall",   (-x, h / 2, 0.0), (0, h / 2, 0), (0, 0, z)),
        ("RightWall",  (x, h / 2, 0.0), (0, 0, z), (0, h / 2, 0)),
    ]
    inside = (0.0, h / 2, 0.0)
    walls = []
    for name, centre, u, v in specs:
        g = cb.Geometry()
        n = g.add_quad(centre, u, v)
        if cb.dot(n, cb.sub(inside, centre)) <= 0.0:
            raise AssertionError("%s faces out of the room" % name)
        g.check_winding()
        walls.append((name, g))
    return walls


def panel():
    g = cb.Geometry()
    n = g.add_quad((0.0, ROOM_HEIGHT - 0.001, -0.6), (0.6, 0.0, 0.0),
                   (0.0, 0.0, 0.4))
    if n != (0.0, -1.0, 0.0):
        raise AssertionError("the panel must face down, got %r" % (n,))
    g.check_winding()
    return g


def y_rotation(degrees):
    half = math.radians(degrees) / 2
    return [0.0, math.sin(half), 0.0, math.cos(half)]


def x_rotation(degrees):
    half = math.radians(degrees) / 2
    return [math.sin(half), 0.0, 0.0, math.cos(half)]


def build_gltf():
    materials = [
        dielectric("Plaster", (0.8, 0.78, 0.74)),        # 0
        dielectric("Terracotta", (0.7, 0.16, 0.09)),     # 1
        dielectric("Sage", (0.25, 0.48, 0.3)),           # 2
        dielectric("Oak", (0.45, 0.3, 0.17)),            # 3
        {                                                # 4
            "name": "Panel",
            "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
                                     "metallicFactor": 0.0},
            "emissiveFactor": [1.0, 0.92, 0.8],
            "extensions": {"KHR_materials_emissive_strength":
                           {"emissiveStrength": 8.0}},
        },
        {                                                # 5
            "name": "RoughGold",
            "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.766, 0.336, 1.0],
                                     "metallicFactor": 1.0,
                                     "roughnessFactor": 0.45},
        },
        dielectric("GreyPaint", (0.4, 0.4, 0.4), roughness=0.5),  # 6
    ]
    wall_material = {"Floor": 3, "Ceiling": 0, "BackWall": 0, "FrontWall": 0,
                     "LeftWall": 1, "RightWall": 2}

    w = cb.GltfWriter()
    meshes = [
        {"name": "Room", "primitives": [w.primitive(g, wall_material[name])
                                        for name, g in room_walls()]},
        {"name": "Panel", "primitives": [w.primitive(panel(), 4)]},
        {"name": "Sphere", "primitives": [w.primitive(cb.uv_sphere(64, 32), 5)]},
        {"name": "Box", "primitives": [w.primitive(cb.flat_box(0.7, 0.9, 0.7), 6)]},
    ]
    nodes = [
        {"name": "Room", "mesh": 0},
        {"name": "Panel", "mesh": 1},
        {"name": "GoldSphere", "mesh": 2, "translation": [0.8, 0.5, -1.0],
         "scale": [0.5, 0.5, 0.5]},
        {"name": "GreyBox", "mesh": 3, "translation": [-0.9, 0.45, -1.1],
         "rotation": y_rotation(25.0)},
        {"name": "Camera", "camera": 0, "translation": [0.0, 1.3, 2.3],
         "rotation": x_rotation(-8.0)},
    ]
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"name": "Room", "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"name": "Camera", "type": "perspective",
                     "perspective": {"yfov": 1.0, "aspectRatio": 1.0,
                                     "znear": 0.01, "zfar": 100.0}}],
        "meshes": meshes,
        "materials": materials,
        "accessors": w.accessors,
        "bufferViews": w.buffer_views,
        "buffers": [w.buffer()],
    }


def without_specular_layers(gltf):
    """--lambert: KHR_materials_specular factor 0 on every non-metal."""
    for m in gltf["materials"]:
        if m["pbrMetallicRoughness"].get("metallicFactor", 1.0) == 0.0:
            m.setdefault("extensions", {})["KHR_materials_specular"] = \
                {"specularFactor": 0.0}
    gltf["extensionsUsed"] = sorted(set(gltf["extensionsUsed"])
                                    | {"KHR_materials_specular"})


def main(argv):
    return cb.command_line(argv, __doc__.split("\n\n")[1] + "\n", __doc__,
                           "--lambert", build_gltf, without_specular_layers)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
