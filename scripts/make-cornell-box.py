#!/usr/bin/env python3
"""Write a Cornell box test scene as a self-contained glTF 2.0 file.

Usage:
    python3 scripts/make-cornell-box.py [--shape-lights] OUT.gltf

The output is a text .gltf whose single buffer is embedded as a base64 data
URI.  The file is deterministic byte for byte (plain Python, no numpy, no
randomness, fixed dictionary order), so it can be regenerated and compared.

Scene (Y up, metres, glTF conventions):
  * Box interior x in [-1, 1], y in [0, 2], z in [-1, 1], open at z = +1.
    Floor, ceiling, back wall white (0.73); left wall (x = -1) red
    (0.63, 0.065, 0.05); right wall (x = +1) green (0.14, 0.45, 0.091).
    One mesh "CornellBox" with one primitive per wall.  Wall materials are
    "pure diffuse" by the CrossRT convention: metallicFactor 0, no
    transmission, KHR_materials_specular.specularFactor 0 (=> Lambertian).
    Normals face into the box, triangles are counter-clockwise seen from
    inside.
  * Area light "Light": a 0.5 (x) by 0.4 (z) quad centred at x = 0, z = 0,
    1 mm below the ceiling (y = 1.999), facing down (-y), single sided.
    Black pure-diffuse base, emissiveFactor (1, 0.85, 0.6) and
    KHR_materials_emissive_strength 17, i.e. emitted radiance
    17 * (1, 0.85, 0.6) W/(sr m^2).
  * Tall box 0.6 x 1.2 x 0.6 of rough copper-like metal (metallic 1,
    roughness 0.35, baseColor (0.95, 0.64, 0.54)), flat shaded (4 vertices
    per face with the face normal).  Placed through a two-level node
    hierarchy: parent "TallBoxPivot" (translation (-0.35, 0.6, -0.3)) with
    child "TallBox" (rotation 20 degrees about +y) instancing a box mesh
    centred at the origin, so the box stands on the floor.
  * Glass sphere: unit UV sphere (48 segments x 24 rings, smooth normals)
    instanced by node "GlassSphere" with translation (0.45, 0.35, 0.3) and
    uniform scale 0.35.  Material: white, metallic 0, roughness 0,
    KHR_materials_transmission 1, KHR_materials_ior 1.5.
  * Perspective camera node "Camera" at (0, 1, 3.6) with identity rotation
    (looks down -z), yfov 0.6911112 rad (39.6 degrees, Blender's default
    50 mm lens on a 36 mm sensor), aspectRatio 1, znear 0.01, zfar 100.
  * With --shape-lights, also a sphere light and a rectangle light: glTF
    point lights whose extras give a size (see add_shape_lights).

Validate with e.g.
    blender -b --factory-startup --python-exit-code 1 \
        --python scripts/cycles-reference.py -- OUT.gltf --out ref.exr
"""

import base64
import json
import math
import struct
import sys

GENERATOR = "CrossRT scripts/make-cornell-box.py"

WHITE = [0.73, 0.73, 0.73, 1.0]
RED = [0.63, 0.065, 0.05, 1.0]
GREEN = [0.14, 0.45, 0.091, 1.0]
COPPER = [0.95, 0.64, 0.54, 1.0]

LIGHT_EMISSIVE_FACTOR = [1.0, 0.85, 0.6]
LIGHT_EMISSIVE_STRENGTH = 17.0
LIGHT_Y = 1.999          # 1 mm below the ceiling
LIGHT_SIZE_X = 0.5
LIGHT_SIZE_Z = 0.4

TALL_BOX_SIZE = (0.6, 1.2, 0.6)
TALL_BOX_POS = (-0.35, 0.6, -0.3)   # centre of the box (bottom at y = 0)
TALL_BOX_ANGLE_DEG = 20.0

SPHERE_CENTRE = (0.45, 0.35, 0.3)
SPHERE_RADIUS = 0.35
SPHERE_SEGMENTS = 48
SPHERE_RINGS = 24

CAMERA_POS = (0.0, 1.0, 3.6)
CAMERA_YFOV = 0.6911112
CAMERA_ZNEAR = 0.01
CAMERA_ZFAR = 100.0

# glTF constants
ARRAY_BUFFER = 34962
ELEMENT_ARRAY_BUFFER = 34963
FLOAT = 5126
UNSIGNED_SHORT = 5123
TRIANGLES = 4


# ---------------------------------------------------------------- vectors --
def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def scale(a, s):
    return tuple(x * s for x in a)


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0])


def normalize(a):
    length = math.sqrt(dot(a, a))
    return scale(a, 1.0 / length)


def f32(x):
    """Round a Python float to the nearest float32 (what the buffer holds)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


# --------------------------------------------------------------- geometry --
class Geometry:
    """Indexed triangle list with per-vertex normals."""

    def __init__(self):
        self.positions = []
        self.normals = []
        self.indices = []

    def add_quad(self, centre, u, v):
        """Quad centre +- u +- v; its normal is normalize(u x v) and the two
        triangles are counter-clockwise when seen from the normal side."""
        n = normalize(cross(u, v))
        base = len(self.positions)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            self.positions.append(add(centre, add(scale(u, su), scale(v, sv))))
            self.normals.append(n)
        self.indices += [base, base + 1, base + 2, base, base + 2, base + 3]
        return n

    def check_winding(self):
        """Every triangle's geometric normal (CCW) must agree with its vertex
        normals."""
        idx = self.indices
        for t in range(0, len(idx), 3):
            a, b, c = (self.positions[i] for i in idx[t:t + 3])
            ng = cross(sub(b, a), sub(c, a))
            if dot(ng, ng) == 0.0:
                raise AssertionError("degenerate triangle %d" % (t // 3))
            for i in idx[t:t + 3]:
                if dot(ng, self.normals[i]) <= 0.0:
                    raise AssertionError("triangle %d winding disagrees with "
                                         "its normals" % (t // 3))


def cornell_walls():
    """Five walls, each (name, geometry).  Normals point into the box."""
    walls = []
    specs = [
        # name,      centre,         u,           v         (u x v = normal)
        ("Floor",    (0.0, 0.0, 0.0), (0, 0, 1), (1, 0, 0)),   # +y
        ("Ceiling",  (0.0, 2.0, 0.0), (1, 0, 0), (0, 0, 1)),   # -y
        ("BackWall", (0.0, 1.0, -1.0), (1, 0, 0), (0, 1, 0)),  # +z
        ("LeftWall", (-1.0, 1.0, 0.0), (0, 1, 0), (0, 0, 1)),  # +x
        ("RightWall", (1.0, 1.0, 0.0), (0, 0, 1), (0, 1, 0)),  # -x
    ]
    interior = (0.0, 1.0, 0.0)
    for name, centre, u, v in specs:
        g = Geometry()
        n = g.add_quad(centre, u, v)
        if dot(n, sub(interior, centre)) <= 0.0:
            raise AssertionError("%s faces out of the box" % name)
        g.check_winding()
        walls.append((name, g))
    return walls


def area_light():
    g = Geometry()
    n = g.add_quad((0.0, LIGHT_Y, 0.0),
                   (LIGHT_SIZE_X / 2, 0.0, 0.0),
                   (0.0, 0.0, LIGHT_SIZE_Z / 2))
    if n != (0.0, -1.0, 0.0):
        raise AssertionError("the light must face down, got %r" % (n,))
    g.check_winding()
    return g


def flat_box(sx, sy, sz):
    """Axis-aligned box centred at the origin, outward normals, 24 vertices."""
    a, b, c = sx / 2, sy / 2, sz / 2
    g = Geometry()
    faces = [
        ((a, 0, 0), (0, b, 0), (0, 0, c)),    # +x
        ((-a, 0, 0), (0, 0, c), (0, b, 0)),   # -x
        ((0, b, 0), (0, 0, c), (a, 0, 0)),    # +y
        ((0, -b, 0), (a, 0, 0), (0, 0, c)),   # -y
        ((0, 0, c), (a, 0, 0), (0, b, 0)),    # +z
        ((0, 0, -c), (0, b, 0), (a, 0, 0)),   # -z
    ]
    for centre, u, v in faces:
        n = g.add_quad(centre, u, v)
        if dot(n, centre) <= 0.0:
            raise AssertionError("box face at %r faces inwards" % (centre,))
    g.check_winding()
    return g


def uv_sphere(segments, rings):
    """Unit UV sphere: one vertex per pole, rings - 1 latitude rings of
    `segments` vertices, no seam duplication (no texcoords).  The normal of
    each vertex is its position."""
    g = Geometry()

    def vertex(p):
        g.positions.append(p)
        g.normals.append(p)
        return len(g.positions) - 1

    top = vertex((0.0, 1.0, 0.0))
    ring_start = []
    for i in range(1, rings):
        theta = math.pi * i / rings
        y, r = math.cos(theta), math.sin(theta)
        ring_start.append(len(g.positions))
        for j in range(segments):
            phi = 2.0 * math.pi * j / segments
            vertex((r * math.cos(phi), y, -r * math.sin(phi)))
    bottom = vertex((0.0, -1.0, 0.0))

    def ring_vertex(i, j):
        return ring_start[i] + j % segments

    # With phi increasing counter-clockwise seen from +y (x -> -z), the
    # triangles below are counter-clockwise seen from outside.
    for j in range(segments):
        g.indices += [top, ring_vertex(0, j), ring_vertex(0, j + 1)]
    for i in range(rings - 2):
        for j in range(segments):
            a, b = ring_vertex(i, j), ring_vertex(i, j + 1)
            c, d = ring_vertex(i + 1, j), ring_vertex(i + 1, j + 1)
            g.indices += [a, c, d, a, d, b]
    last = rings - 2
    for j in range(segments):
        g.indices += [bottom, ring_vertex(last, j + 1), ring_vertex(last, j)]
    g.check_winding()
    return g


# ------------------------------------------------------------------- glTF --
class GltfWriter:
    def __init__(self):
        self.blob = bytearray()
        self.buffer_views = []
        self.accessors = []

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        self.buffer_views.append({
            "buffer": 0,
            "byteOffset": len(self.blob),
            "byteLength": len(data),
            "target": target,
        })
        self.blob += data
        return len(self.buffer_views) - 1

    def _vec3_accessor(self, values, with_bounds):
        data = b"".join(struct.pack("<3f", *v) for v in values)
        accessor = {
            "bufferView": self._view(data, ARRAY_BUFFER),
            "componentType": FLOAT,
            "count": len(values),
            "type": "VEC3",
        }
        if with_bounds:
            rounded = [[f32(x) for x in v] for v in values]
            accessor["min"] = [min(v[k] for v in rounded) for k in range(3)]
            accessor["max"] = [max(v[k] for v in rounded) for k in range(3)]
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def _index_accessor(self, indices):
        if max(indices) > 0xFFFF:
            raise ValueError("too many vertices for 16-bit indices")
        data = struct.pack("<%dH" % len(indices), *indices)
        self.accessors.append({
            "bufferView": self._view(data, ELEMENT_ARRAY_BUFFER),
            "componentType": UNSIGNED_SHORT,
            "count": len(indices),
            "type": "SCALAR",
        })
        return len(self.accessors) - 1

    def primitive(self, geometry, material):
        return {
            "attributes": {
                "POSITION": self._vec3_accessor(geometry.positions, True),
                "NORMAL": self._vec3_accessor(
                    [tuple(f32(x) for x in n) for n in geometry.normals],
                    False),
            },
            "indices": self._index_accessor(geometry.indices),
            "material": material,
            "mode": TRIANGLES,
        }

    def buffer(self):
        while len(self.blob) % 4:
            self.blob.append(0)
        return {
            "byteLength": len(self.blob),
            "uri": "data:application/octet-stream;base64,"
                   + base64.b64encode(bytes(self.blob)).decode("ascii"),
        }


def pure_diffuse_material(name, colour):
    return {
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": colour,
            "metallicFactor": 0.0,
            "roughnessFactor": 1.0,
        },
        "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}},
    }


def build_gltf():
    materials = [
        pure_diffuse_material("White", WHITE),        # 0
        pure_diffuse_material("Red", RED),            # 1
        pure_diffuse_material("Green", GREEN),        # 2
        {                                             # 3
            "name": "Light",
            "pbrMetallicRoughness": {
                "baseColorFactor": [0.0, 0.0, 0.0, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0,
            },
            "emissiveFactor": LIGHT_EMISSIVE_FACTOR,
            "extensions": {
                "KHR_materials_specular": {"specularFactor": 0.0},
                "KHR_materials_emissive_strength": {
                    "emissiveStrength": LIGHT_EMISSIVE_STRENGTH},
            },
        },
        {                                             # 4
            "name": "Copper",
            "pbrMetallicRoughness": {
                "baseColorFactor": COPPER,
                "metallicFactor": 1.0,
                "roughnessFactor": 0.35,
            },
        },
        {                                             # 5
            "name": "Glass",
            "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 0.0,
            },
            "extensions": {
                "KHR_materials_transmission": {"transmissionFactor": 1.0},
                "KHR_materials_ior": {"ior": 1.5},
            },
        },
    ]
    wall_material = {"Floor": 0, "Ceiling": 0, "BackWall": 0,
                     "LeftWall": 1, "RightWall": 2}

    w = GltfWriter()
    meshes = [
        {"name": "CornellBox",
         "primitives": [w.primitive(g, wall_material[name])
                        for name, g in cornell_walls()]},
        {"name": "AreaLight", "primitives": [w.primitive(area_light(), 3)]},
        {"name": "TallBoxMesh",
         "primitives": [w.primitive(flat_box(*TALL_BOX_SIZE), 4)]},
        {"name": "UnitSphere",
         "primitives": [w.primitive(uv_sphere(SPHERE_SEGMENTS, SPHERE_RINGS),
                                    5)]},
    ]

    half = math.radians(TALL_BOX_ANGLE_DEG) / 2
    nodes = [
        {"name": "CornellBox", "mesh": 0},                             # 0
        {"name": "Light", "mesh": 1},                                  # 1
        {"name": "TallBoxPivot", "translation": list(TALL_BOX_POS),    # 2
         "children": [3]},
        {"name": "TallBox", "mesh": 2,                                 # 3
         "rotation": [0.0, math.sin(half), 0.0, math.cos(half)]},
        {"name": "GlassSphere", "mesh": 3,                             # 4
         "translation": list(SPHERE_CENTRE),
         "scale": [SPHERE_RADIUS] * 3},
        {"name": "Camera", "camera": 0, "translation": list(CAMERA_POS)},  # 5
    ]

    extensions_used = sorted({name for m in materials
                              for name in m.get("extensions", {})})
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "extensionsUsed": extensions_used,
        "scene": 0,
        "scenes": [{"name": "CornellBox", "nodes": [0, 1, 2, 4, 5]}],
        "nodes": nodes,
        "cameras": [{
            "name": "Camera",
            "type": "perspective",
            "perspective": {
                "yfov": CAMERA_YFOV,
                "aspectRatio": 1.0,
                "znear": CAMERA_ZNEAR,
                "zfar": CAMERA_ZFAR,
            },
        }],
        "meshes": meshes,
        "materials": materials,
        "accessors": w.accessors,
        "bufferViews": w.buffer_views,
        "buffers": [w.buffer()],
    }


def add_shape_lights(gltf):
    """--shape-lights: a bluish sphere light (radius 0.12, 400 cd) upper left,
    and a warm 0.5 x 0.25 rectangle (300 cd along its axis) by the right wall,
    facing -x: KHR_lights_punctual point lights with CrossRT's size extras."""
    gltf["extensionsUsed"] = sorted(gltf["extensionsUsed"] + ["KHR_lights_punctual"])
    gltf["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "Sphere", "type": "point", "color": [0.6, 0.8, 1.0],
         "intensity": 400.0, "extras": {"radius": 0.12}},
        {"name": "Rectangle", "type": "point", "color": [1.0, 0.9, 0.7],
         "intensity": 300.0, "extras": {"width": 0.5, "height": 0.25}}]}}
    first = len(gltf["nodes"])
    gltf["nodes"].append({"name": "SphereLight", "translation": [-0.5, 1.4, 0.4],
                          "extensions": {"KHR_lights_punctual": {"light": 0}}})
    half = math.sqrt(0.5)  # a quarter turn about +y: the node's -z looks along -x
    gltf["nodes"].append({"name": "RectLight", "translation": [0.95, 1.2, -0.3],
                          "rotation": [0.0, half, 0.0, half],
                          "extensions": {"KHR_lights_punctual": {"light": 1}}})
    gltf["scenes"][0]["nodes"] += [first, first + 1]


def command_line(argv, usage, help_text, flag, build, with_flag):
    """[flag] OUT.gltf: writes build(), changed by with_flag(gltf) when the
    flag is given (make-room.py's command line too)."""
    if argv in (["-h"], ["--help"]):
        sys.stdout.write(help_text)
        return 0
    flagged = flag in argv
    argv = [a for a in argv if a != flag]
    if len(argv) != 1 or argv[0].startswith("-"):
        sys.stderr.write(usage)
        return 2
    gltf = build()
    if flagged:
        with_flag(gltf)
    text = json.dumps(gltf, indent=1) + "\n"
    with open(argv[0], "w", encoding="ascii", newline="\n") as f:
        f.write(text)
    return 0


def main(argv):
    usage = (__doc__.split("\n\n")[1] + "\n\n"
             "Writes a deterministic Cornell box glTF 2.0 scene (embedded "
             "buffer) to OUT.gltf.\n")
    return command_line(argv, usage, usage, "--shape-lights", build_gltf,
                        add_shape_lights)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
