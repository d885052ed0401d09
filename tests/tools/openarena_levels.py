#!/usr/bin/env python3
"""Converts the OpenArena Community Map Pack (volume 1) into shadowbake levels: <map>.glb + <map>.toml.

What it makes, per map (the form of shared/assets/openarena/, README "OpenArena community map pack"):

- <map>.glb (glTF 2.0 binary), Y up, metres (1 Quake unit = 1/32 m; Quake's Z-up (x, y, z) becomes
  glTF (x, z, -y), a rotation, so windings and handedness are kept):
  - mesh node "world": every face of the world model (BSP model 0) that q3map2 gave a lightmap:
    planar faces and triangle soups as stored, patches (biquadratic Bezier, 3x3 control points per
    piece) tessellated 4x4 quads per piece. POSITION, NORMAL, and TEXCOORD_0 = TEXCOORD_1 (one
    accessor) = q3map2's own lightmap coordinates, its 128^2 pages tiled into one square atlas of
    n x n pages (n the smallest that holds them all), page k at column k mod n, row k div n.
  - mesh node "props": the world model's faces without a lightmap (vertex-lit), POSITION + NORMAL;
    left out where there are none (oacmpctf2), as glTF has no empty meshes.
  - sky (SURF_SKY) and nodraw (SURF_NODRAW) faces, flares, and brush entities' faces (doors,
    platforms: other BSP models) are left out.
  - one node per "light" entity of the map source, light_0, light_1, ... in the .map's entity
    order, with a KHR_lights_punctual light: a point, or a spot where the entity's "target" names
    an entity (aimed at its origin). intensity = the entity's value / 8 (relative), colour =
    "_color" divided by its largest component (q3map2's ColorNormalize), range = the distance at
    which q3map2's inverse-square falloff (intensity * 7500 / d^2) drops under its cut-off of 1,
    sqrt(intensity * 7500) units.
- <map>.toml: bake at the atlas's size, props as blockers only (that table only where there are
  props), each light a 0.125 m sphere.

From what: the pk3 of Debian's openarena-oacmp1 package (z_oacmp-volume1-v3.pk3, a zip), which holds
both the compiled maps (maps/<map>.bsp, Quake 3 IBSP version 46, compiled and lit by their authors
with q3map2) and the map sources (sources/maps/<map>.map); the BSP keeps the geometry and the
lightmap layout, the .map keeps the light entities (q3map2 strips them from the BSP).

Licence: the maps are GPL-2+ (see the package's copyright file). The files this script writes are
derived from them, so they are NOT to be committed to shadowbake; only this script is. The default
output folder (/work/levels/openarena) is outside the repository for that reason.

How to run (standard library only, Python 3.8+):

    python3 tests/tools/openarena_levels.py [--pk3 PK3] [--out DIR] [--compare REF_DIR] [MAP ...]

MAP defaults to all 13 maps of the pack. The pk3 is looked for where the package installs it and
where `apt-get download openarena-oacmp1 && dpkg-deb -x openarena-oacmp1_*.deb /tmp/oa/x` puts it.
--compare REF_DIR checks each written glb against REF_DIR/<map>.glb where that exists (the two
references in shared/assets/openarena/, which this reproduces byte for byte) and prints the
differences. It takes a few seconds for the whole pack.

Spot lights (only oacmpdm10 has them): q3map2 lights a point when its distance from the axis is
under radiusAtDist = depth * (radius + 16) / dist (radius = the entity's "radius", default 64; dist
= distance to the target, 64 if zero), fading linearly over the last 32 units of that. In glTF the
cone is an angle, so it is taken at the target's distance: outerConeAngle = atan((radius + 16) /
dist), innerConeAngle = atan(max(radius - 16, 0) / dist).
"""

import argparse
import array
import json
import math
import os
import re
import struct
import sys
import zipfile

PK3_NAME = "z_oacmp-volume1-v3.pk3"
PK3_CANDIDATES = [
    "/usr/share/games/openarena/baseoa/" + PK3_NAME,  # the package installed
    "/tmp/oa/x/usr/share/games/openarena/baseoa/" + PK3_NAME,  # the package extracted (see above)
]
DEFAULT_OUT = "/work/levels/openarena"
MAPS = [
    "oacmpctf1", "oacmpctf2", "oacmpctf3",
    "oacmpdm1", "oacmpdm2", "oacmpdm3", "oacmpdm4", "oacmpdm5",
    "oacmpdm6", "oacmpdm7", "oacmpdm8", "oacmpdm9", "oacmpdm10",
]

UNITS_PER_METRE = 32.0
PAGE = 128  # q3map2's lightmap page side in the BSP (LUMP_LIGHTMAPS holds 128x128 RGB pages)
PATCH_STEPS = 4  # quads per side of each 3x3 control-point piece of a patch
LIGHT_SCALE = 7500.0  # q3map2's pointScale (= spotScale): photons = intensity * 7500
FALLOFF_TOLERANCE = 1.0  # q3map2's default cut-off: a light ends where photons / d^2 < 1
INTENSITY_DIVISOR = 8.0  # glTF intensity = entity value / 8 (relative, as the references)
DEFAULT_INTENSITY = 300.0  # q3map2's default when "_light"/"light" is missing or zero
DEFAULT_SPOT_RADIUS = 64.0  # q3map2's default "radius" of a spot at its target
LIGHT_RADIUS_M = 0.125  # every light's sphere radius in the .toml

# Quake 3 BSP (IBSP 46) lump indices and record layouts (little-endian).
LUMP_SHADERS, LUMP_MODELS = 1, 7
LUMP_DRAWVERTS, LUMP_DRAWINDEXES, LUMP_SURFACES, LUMP_LIGHTMAPS = 10, 11, 13, 14
NUM_LUMPS = 17
SHADER = struct.Struct("<64sii")  # name, surface flags, content flags
MODEL = struct.Struct("<6f4i")  # mins, maxs, first surface, surfaces, first brush, brushes
DRAWVERT = struct.Struct("<3f2f2f3f4B")  # xyz, st, lightmap st, normal, colour
# shader, fog, type, first vert, verts, first index, indexes, lightmap index, lightmap x, y, w, h,
# lightmap origin, lightmap s/t vectors, normal, patch width, patch height
SURFACE = struct.Struct("<12i12f2i")
MST_PLANAR, MST_PATCH, MST_TRIANGLE_SOUP, MST_FLARE = 1, 2, 3, 4
SURF_SKY, SURF_NODRAW = 0x4, 0x80

GLTF_FLOAT, GLTF_UINT = 5126, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


# --------------------------------------------------------------------------------------------------
# Input


def find_pk3(explicit):
    candidates = [explicit] if explicit else PK3_CANDIDATES
    for path in candidates:
        if os.path.isfile(path):
            return path
    sys.exit(
        "openarena_levels.py: no %s found (looked in %s). Get it from Debian's package:\n"
        "    apt-get download openarena-oacmp1 && dpkg-deb -x openarena-oacmp1_*.deb /tmp/oa/x\n"
        "or install it (apt-get install openarena-oacmp1), or pass --pk3 PATH."
        % (PK3_NAME, ", ".join(candidates))
    )


class Bsp:
    """The parts of a Quake 3 BSP this converter needs."""

    def __init__(self, data):
        magic, version = struct.unpack_from("<4si", data, 0)
        if magic != b"IBSP" or version != 46:
            raise ValueError("not a Quake 3 BSP (IBSP 46): %r %d" % (magic, version))
        lumps = [struct.unpack_from("<ii", data, 8 + 8 * i) for i in range(NUM_LUMPS)]

        def records(index, layout):
            offset, length = lumps[index]
            if length % layout.size:
                raise ValueError("lump %d: %d bytes is not a whole number of records" % (index, length))
            return [layout.unpack_from(data, offset + k) for k in range(0, length, layout.size)]

        self.shaders = [(n.split(b"\0", 1)[0].decode("latin-1"), flags, contents)
                        for n, flags, contents in records(LUMP_SHADERS, SHADER)]
        self.models = records(LUMP_MODELS, MODEL)
        self.verts = records(LUMP_DRAWVERTS, DRAWVERT)
        offset, length = lumps[LUMP_DRAWINDEXES]
        self.indexes = struct.unpack_from("<%di" % (length // 4), data, offset)
        self.surfaces = records(LUMP_SURFACES, SURFACE)
        page_bytes = PAGE * PAGE * 3
        length = lumps[LUMP_LIGHTMAPS][1]
        if length % page_bytes:
            raise ValueError("lightmap lump is not a whole number of %d^2 pages" % PAGE)
        self.num_pages = length // page_bytes


def parse_entities(text):
    """The key/value pairs of every entity of a .map file, in file order (brushes and patches,
    one level deeper, are skipped)."""
    entities, depth, current, key = [], 0, None, None
    for m in re.finditer(r'//[^\n]*|"([^"]*)"|([{}])|[^\s{}"]+', text):
        quoted, brace = m.group(1), m.group(2)
        if brace == "{":
            depth += 1
            if depth == 1:
                current, key = {}, None
        elif brace == "}":
            depth -= 1
            if depth == 0:
                entities.append(current)
            elif depth < 0:
                raise ValueError("unbalanced } in .map")
        elif depth == 1 and quoted is not None:
            if key is None:
                key = quoted
            else:
                # q3map2 keeps the first of a repeated key; the pack has none, so either is fine.
                current.setdefault(key, quoted)
                key = None
    return entities


# --------------------------------------------------------------------------------------------------
# Geometry


def to_gltf(v):
    """Quake (x, y, z), Z up, units -> glTF (x, z, -y), Y up, metres (a rotation about X)."""
    return (v[0] / UNITS_PER_METRE, v[2] / UNITS_PER_METRE, -v[1] / UNITS_PER_METRE)


def to_gltf_direction(n):
    return (n[0], n[2], -n[1])


class MeshBuilder:
    def __init__(self, with_uv):
        self.positions, self.normals, self.uvs, self.indices = [], [], [], []
        self.with_uv = with_uv

    def add(self, positions, normals, uvs, triangles):
        base = len(self.positions)
        self.positions.extend(positions)
        self.normals.extend(normals)
        if self.with_uv:
            self.uvs.extend(uvs)
        self.indices.extend(base + i for i in triangles)

    @property
    def triangles(self):
        return len(self.indices) // 3


def bezier_weights(t):
    s = 1.0 - t
    return (s * s, 2.0 * s * t, t * t)


def tessellate_patch(control, width, height):
    """A patch's control grid (row-major, width columns) as 3x3 pieces, each evaluated on a
    (PATCH_STEPS + 1)^2 grid of its own (pieces do not share vertices, as in the references).
    control: per control point a tuple of vectors to interpolate (position, normal, lightmap st).
    Returns (vertices, triangles) with vertices in piece order, then row (v) major, column (u)."""
    steps = PATCH_STEPS
    weights = [bezier_weights(k / steps) for k in range(steps + 1)]
    vertices, triangles = [], []
    for py in range(0, height - 1, 2):
        for px in range(0, width - 1, 2):
            base = len(vertices)
            grid = [[control[(py + j) * width + px + i] for i in range(3)] for j in range(3)]
            for wv in weights:
                # Interpolate the three rows along v first, then along u.
                rows = [lerp3(grid[0][i], grid[1][i], grid[2][i], wv) for i in range(3)]
                for wu in weights:
                    vertices.append(lerp3(rows[0], rows[1], rows[2], wu))
            n = steps + 1
            for r in range(steps):
                for c in range(steps):
                    a = base + r * n + c
                    # Counter-clockwise seen from the side the normals face (glTF's front), as
                    # the references have it.
                    triangles += [a + 1, a + n, a, a + n + 1, a + n, a + 1]
    return vertices, triangles


def lerp3(p0, p1, p2, w):
    """Weighted sum of three control points, each a tuple of vectors."""
    return tuple(
        tuple(w[0] * x0 + w[1] * x1 + w[2] * x2 for x0, x1, x2 in zip(v0, v1, v2))
        for v0, v1, v2 in zip(p0, p1, p2)
    )


def normalize(v):
    length = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (v[0] / length, v[1] / length, v[2] / length) if length > 0 else v


def build_meshes(bsp):
    """world and props MeshBuilders from the world model's drawable surfaces, in BSP order."""
    n = atlas_grid(bsp.num_pages)
    world, props = MeshBuilder(with_uv=True), MeshBuilder(with_uv=False)
    first, count = bsp.models[0][6], bsp.models[0][7]
    for s in bsp.surfaces[first:first + count]:
        shader, kind, first_vert, num_verts, first_index, num_indexes, page = (
            s[0], s[2], s[3], s[4], s[5], s[6], s[7])
        if kind not in (MST_PLANAR, MST_PATCH, MST_TRIANGLE_SOUP):
            continue  # flares (and anything unknown) have no surface
        if bsp.shaders[shader][1] & (SURF_SKY | SURF_NODRAW):
            continue
        lit = page >= 0
        verts = bsp.verts[first_vert:first_vert + num_verts]

        def atlas_uv(st, rounding=float):
            # Page `page` sits at column page mod n, row page div n of the n x n atlas.
            return (rounding(rounding(page % n + st[0]) / n), rounding(rounding(page // n + st[1]) / n))

        if kind == MST_PATCH:
            width, height = s[24], s[25]
            control = [(v[0:3], v[7:10], v[5:7]) for v in verts]
            vertices, triangles = tessellate_patch(control, width, height)
            positions = [to_gltf(p) for p, _, _ in vertices]
            normals = [to_gltf_direction(normalize(nm)) for _, nm, _ in vertices]
            uvs = [atlas_uv(st) for _, _, st in vertices] if lit else None
        else:
            positions = [to_gltf(v[0:3]) for v in verts]
            normals = [to_gltf_direction(normalize(v[7:10])) for v in verts]
            # Stored coordinates are float32; the references' converter added and divided them in
            # float32 too (patches, interpolated in double, were not), and this matches it to the bit.
            uvs = [atlas_uv(v[5:7], to_float32) for v in verts] if lit else None
            indexes = bsp.indexes[first_index:first_index + num_indexes]
            # Quake 3 stores triangles clockwise seen from the front; glTF's fronts are
            # counter-clockwise, so each triangle is reversed (c, b, a).
            triangles = [indexes[k + 2 - j] for k in range(0, len(indexes) - 2, 3) for j in range(3)]
        (world if lit else props).add(positions, normals, uvs, triangles)
    return world, props


def to_float32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def atlas_grid(pages):
    """The smallest n with n * n >= pages (at least 1)."""
    n = max(1, math.isqrt(pages))
    return n if n * n >= pages else n + 1


# --------------------------------------------------------------------------------------------------
# Lights


def parse_vector(text):
    values = [float(x) for x in text.split()[:3]]
    return tuple(values + [0.0] * (3 - len(values)))


def make_lights(entities):
    """KHR_lights_punctual lights and their nodes' placement, one per "light" entity, as q3map2
    reads them (CreateEntityLights), in entity order. Returns [(light, node fields)], warnings."""
    by_name = {}
    for e in entities:
        by_name.setdefault(e.get("targetname"), e)  # q3map2 aims at the first one of that name
    lights, warnings = [], []
    for e in entities:
        if e.get("classname") != "light":
            continue
        origin = parse_vector(e.get("origin", "0 0 0"))
        # "_light" wins over "light"; zero or missing means the default.
        intensity = float((e.get("_light") or e.get("light") or "0").split()[0])
        if intensity == 0.0:
            intensity = DEFAULT_INTENSITY
        scale = float(e.get("scale", "0") or 0)
        if scale != 0.0:
            intensity *= scale
        if intensity < 0.0:
            warnings.append("negative light at %s kept as positive" % (origin,))
            intensity = -intensity
        spawnflags = int(float(e.get("spawnflags", "0") or 0))
        if spawnflags & 1 and "target" not in e:
            warnings.append("linear-falloff light at %s given the inverse-square range" % (origin,))
        color = (1.0, 1.0, 1.0)
        if "_color" in e:
            c = parse_vector(e["_color"])
            top = max(c)
            color = tuple(x / top for x in c) if top > 0 else (1.0, 1.0, 1.0)
        light = {
            "name": "light_%d" % len(lights),
            "type": "point",
            "color": list(color),
            "intensity": intensity / INTENSITY_DIVISOR,
            "range": math.sqrt(intensity * LIGHT_SCALE / FALLOFF_TOLERANCE) / UNITS_PER_METRE,
        }
        node = {"translation": list(to_gltf(origin))}
        target_name = e.get("target")
        if target_name:
            target = by_name.get(target_name)
            if target is None:
                warnings.append("light at %s: missing target %r, a point" % (origin, target_name))
            else:
                dest = parse_vector(target.get("origin", "0 0 0"))
                axis = tuple(b - a for a, b in zip(origin, dest))
                dist = math.sqrt(sum(x * x for x in axis))
                radius = float(e.get("radius", "0") or 0) or DEFAULT_SPOT_RADIUS
                if dist == 0.0:
                    # q3map2 counts a zero distance as 64 and leaves the axis undefined: down here.
                    dist, axis = 64.0, (0.0, 0.0, -1.0)
                light["type"] = "spot"
                light["spot"] = {
                    "innerConeAngle": math.atan(max(radius - 16.0, 0.0) / dist),
                    "outerConeAngle": math.atan((radius + 16.0) / dist),
                }
                node["rotation"] = rotation_from_minus_z(to_gltf_direction(normalize(axis)))
        lights.append((light, node))
    return lights, warnings


def rotation_from_minus_z(d):
    """Unit quaternion (x, y, z, w) turning -Z (a glTF spot's axis) onto the unit vector d."""
    # q = (a x b, 1 + a.b) normalised, a = (0, 0, -1), b = d.
    x, y, z = d[1], -d[0], 0.0
    w = 1.0 - d[2]
    if w < 1e-9:  # d is +Z: half a turn about X
        return [1.0, 0.0, 0.0, 0.0]
    length = math.sqrt(x * x + y * y + z * z + w * w)
    return [x / length, y / length, z / length, w / length]


# --------------------------------------------------------------------------------------------------
# Output


def float_array(rows):
    a = array.array("f")
    for row in rows:
        a.extend(row)
    return a


def write_glb(path, world, props, lights):
    blob = bytearray()
    accessors, views = [], []

    def add_view(data, target):
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        while len(blob) % 4:
            blob.append(0)
        return len(views) - 1

    def add_accessor(values, kind, bounds=False):
        if kind == "SCALAR":
            data = array.array("I", values)
            component, count = GLTF_UINT, len(values)
            target = ELEMENT_ARRAY_BUFFER
        else:
            data = float_array(values)
            component, count = GLTF_FLOAT, len(values)
            target = ARRAY_BUFFER
        if sys.byteorder != "little":
            data.byteswap()
        accessor = {"bufferView": add_view(data.tobytes(), target), "componentType": component,
                    "count": count, "type": kind}
        if bounds:
            # Bounds of the float32 values actually stored, as glTF asks.
            stored = [data[k::3] for k in range(3)]
            accessor["min"] = [min(c) for c in stored]
            accessor["max"] = [max(c) for c in stored]
        accessors.append(accessor)
        return len(accessors) - 1

    meshes, nodes = [], []
    for name, mesh in (("world", world), ("props", props)):
        if not mesh.indices:
            # glTF has no empty meshes (oacmpctf2 has no vertex-lit faces): the node is left out.
            continue
        attributes = {"POSITION": add_accessor(mesh.positions, "VEC3", bounds=True),
                      "NORMAL": add_accessor(mesh.normals, "VEC3")}
        if mesh.with_uv:
            uv = add_accessor(mesh.uvs, "VEC2")
            # The lightmap layout is also the only texture layout there is: one accessor, two sets.
            attributes["TEXCOORD_0"] = uv
            attributes["TEXCOORD_1"] = uv
        indices = add_accessor(mesh.indices, "SCALAR")
        meshes.append({"name": name, "primitives": [{"attributes": attributes, "indices": indices}]})
        nodes.append({"name": name, "mesh": len(meshes) - 1})

    for k, (light, placement) in enumerate(lights):
        node = {"name": light["name"]}
        node.update(placement)
        node["extensions"] = {"KHR_lights_punctual": {"light": k}}
        nodes.append(node)
    gltf = {
        "asset": {"version": "2.0", "generator": "bsp2glb"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob)}],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [light for light, _ in lights]}},
    }
    text = json.dumps(gltf).encode("utf-8")
    text += b" " * (-len(text) % 4)
    glb = bytearray()
    glb += struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + len(blob))
    glb += struct.pack("<I4s", len(text), b"JSON") + text
    glb += struct.pack("<I4s", len(blob), b"BIN\0") + blob
    with open(path, "wb") as f:
        f.write(glb)


def write_toml(path, name, pages, n, with_props):
    # An [[import.object]] that matches no object is an error (docs/scene-format.md), so the props
    # table is only written where the glb has props.
    props = '[[import.object]]\nname = "props"\nreceiver = false\n\n' if with_props else ""
    text = (
        "# {name}.bsp: q3map2's lightmap layout ({pages} pages of {page}^2 in a {n}x{n} atlas)\n"
        "[bake]\n"
        "resolution = {side}\n"
        "\n"
        "[[import]]\n"
        'file = "{name}.glb"\n'
        "\n"
        "{props}"
        "[[import.light]]\n"
        'name = "*"\n'
        "radius = {radius}\n"
    ).format(name=name, pages=pages, page=PAGE, n=n, side=n * PAGE, props=props,
               radius=LIGHT_RADIUS_M)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


# --------------------------------------------------------------------------------------------------
# Checking against a reference glb


def read_glb(path):
    with open(path, "rb") as f:
        data = f.read()
    json_length = struct.unpack_from("<I", data, 12)[0]
    gltf = json.loads(data[20:20 + json_length])
    bin_length = struct.unpack_from("<I", data, 20 + json_length)[0]
    blob = data[28 + json_length:28 + json_length + bin_length]
    meshes = {}
    for mesh in gltf["meshes"]:
        primitive = mesh["primitives"][0]
        arrays = {}
        for semantic, index in list(primitive["attributes"].items()) + [("indices", primitive["indices"])]:
            accessor = gltf["accessors"][index]
            view = gltf["bufferViews"][accessor["bufferView"]]
            a = array.array("f" if accessor["componentType"] == GLTF_FLOAT else "I")
            a.frombytes(blob[view["byteOffset"]:view["byteOffset"] + view["byteLength"]])
            arrays[semantic] = a
        meshes[mesh["name"]] = (primitive, arrays, gltf["accessors"][primitive["attributes"]["POSITION"]])
    return gltf, meshes, data


def compare(path, reference):
    """Prints how the written glb differs from the reference."""
    mine, my_meshes, my_bytes = read_glb(path)
    ref, ref_meshes, ref_bytes = read_glb(reference)
    print("  compare with %s: files %s" % (reference, "identical" if my_bytes == ref_bytes else "differ"))
    for name in ("world", "props"):
        if name not in my_meshes or name not in ref_meshes:
            print("    %-5s in mine: %s, in the reference: %s" % (name, name in my_meshes, name in ref_meshes))
            continue
        (mp, ma, mpos), (rp, ra, rpos) = my_meshes[name], ref_meshes[name]
        print("    %-5s triangles %d / ref %d, vertices %d / ref %d, attributes %s / ref %s" % (
            name, len(ma["indices"]) // 3, len(ra["indices"]) // 3, len(ma["POSITION"]) // 3,
            len(ra["POSITION"]) // 3, sorted(mp["attributes"]), sorted(rp["attributes"])))
        print("          bounds %s..%s / ref %s..%s" % (mpos["min"], mpos["max"], rpos["min"], rpos["max"]))
        for key in sorted(ma):
            if key in ra and len(ma[key]) == len(ra[key]):
                diff = max((abs(x - y) for x, y in zip(ma[key], ra[key])), default=0.0)
                print("          %-10s max |difference| %g" % (key, diff))
            elif key in ra:
                print("          %-10s lengths differ" % key)
    ml = mine["extensions"]["KHR_lights_punctual"]["lights"]
    rl = ref["extensions"]["KHR_lights_punctual"]["lights"]
    mn = {n["name"]: n for n in mine["nodes"]}
    rn = {n["name"]: n for n in ref["nodes"]}
    print("    lights %d / ref %d" % (len(ml), len(rl)))
    if len(ml) == len(rl):
        worst = {"position": 0.0, "range": 0.0, "intensity": 0.0, "colour": 0.0}
        names = 0
        for a, b in zip(ml, rl):
            names += a["name"] != b["name"] or a["type"] != b["type"]
            pa, pb = mn[a["name"]]["translation"], rn[b["name"]]["translation"]
            worst["position"] = max(worst["position"], max(abs(x - y) for x, y in zip(pa, pb)))
            worst["range"] = max(worst["range"], abs(a["range"] - b["range"]))
            worst["intensity"] = max(worst["intensity"], abs(a["intensity"] - b["intensity"]))
            worst["colour"] = max(worst["colour"], max(abs(x - y) for x, y in zip(a["color"], b["color"])))
        print("    lights: %d name/type mismatches; max |difference| %s" % (
            names, ", ".join("%s %g" % kv for kv in worst.items())))


# --------------------------------------------------------------------------------------------------


def convert(pack, name, out_dir, reference_dir):
    bsp = Bsp(pack.read("maps/%s.bsp" % name))
    entities = parse_entities(pack.read("sources/maps/%s.map" % name).decode("latin-1"))
    world, props = build_meshes(bsp)
    lights, warnings = make_lights(entities)
    n = atlas_grid(bsp.num_pages)
    glb_path = os.path.join(out_dir, name + ".glb")
    write_glb(glb_path, world, props, lights)
    write_toml(os.path.join(out_dir, name + ".toml"), name, bsp.num_pages, n, bool(props.indices))
    points = sum(light["type"] == "point" for light, _ in lights)
    row = (name, world.triangles, props.triangles, points, len(lights) - points, n * PAGE, bsp.num_pages)
    print("%-10s %7d + %5d triangles, %4d points + %2d spots, atlas %4d^2 (%d pages)" % row)
    for w in warnings:
        print("  warning:", w)
    if reference_dir:
        reference = os.path.join(reference_dir, name + ".glb")
        if os.path.isfile(reference):
            compare(glb_path, reference)
            reference_toml = os.path.join(reference_dir, name + ".toml")
            if os.path.isfile(reference_toml):
                with open(reference_toml, "rb") as f, open(os.path.join(out_dir, name + ".toml"), "rb") as g:
                    print("  compare with %s: %s" % (
                        reference_toml, "identical" if f.read() == g.read() else "differ"))
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("maps", nargs="*", default=MAPS, help="map names (default: all 13)")
    parser.add_argument("--pk3", help="the pack's pk3 (default: found where the package puts it)")
    parser.add_argument("--out", default=DEFAULT_OUT, help="output folder (default %(default)s)")
    parser.add_argument("--compare", metavar="REF_DIR",
                        help="compare each glb with REF_DIR/<map>.glb where it exists")
    args = parser.parse_args()
    pk3 = find_pk3(args.pk3)
    os.makedirs(args.out, exist_ok=True)
    rows = []
    with zipfile.ZipFile(pk3) as pack:
        present = set(pack.namelist())
        for name in args.maps:
            missing = [f % name for f in ("maps/%s.bsp", "sources/maps/%s.map") if f % name not in present]
            if missing:
                sys.exit("openarena_levels.py: %s has no %s (the pack's maps: %s)" % (
                    pk3, " or ".join(missing), " ".join(MAPS)))
        for name in args.maps:
            rows.append(convert(pack, name, args.out, args.compare))
    print()
    print("| map | triangles (world + props) | lights (points, spots) | atlas |")
    print("| --- | --- | --- | --- |")
    for name, w, p, points, spots, side, pages in rows:
        print("| %s | %d + %d | %d (%d, %d) | %d^2 (%d pages) |" % (
            name, w, p, points + spots, points, spots, side, pages))


if __name__ == "__main__":
    main()
