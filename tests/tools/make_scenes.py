#!/usr/bin/env python3
"""Writes the example scenes under scenes/: meshes (OBJ, and one glTF 2.0) and scene.toml files.

Z is up, lengths are metres. Every mesh carries a lightmap UV layout in its first UV set: each
object's surface is cut into charts that unfold with little distortion (planar faces as they are;
a sphere as two equal-area polar caps and four equirectangular quarters of its equatorial band; a
torus as eight equal-area arcs; a cone as its developed side and its base), all charts of an object
are scaled by one factor (so texel density is nearly uniform) and shelf-packed into [0, 1]^2 with a
gutter of GUTTER_TEXELS texels at 512^2 between charts and half that at the border. The packer
checks its own result (every UV inside [0, 1], chart boxes apart by the gutter, no folded
triangle) and the script prints each object's triangle count and density spread.

Standard library only; the output is the same bytes on every run.

    python3 tests/tools/make_scenes.py [--out DIR]     # DIR defaults to the repository's scenes/
"""

import argparse
import base64
import json
import math
import struct
from pathlib import Path

RESOLUTION = 512  # texels per side the layouts are made for
GUTTER_TEXELS = 12  # between charts; at least 8 so two charts' 4-texel margins never meet
BORDER_TEXELS = 6  # between a chart and the edge of the texture

HEADER = "written by tests/tools/make_scenes.py; edit that script, not this file"


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def scale(a, s):
    return tuple(x * s for x in a)


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a):
    length = math.sqrt(dot(a, a))
    return tuple(x / length for x in a)


def signed_area_2d(a, b, c):
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


class Chart:
    """A connected piece of surface with its own flat coordinates (metres, `local`)."""

    def __init__(self):
        self.positions = []
        self.normals = []
        self.local = []  # 2D chart coordinates, metres
        self.uv = []  # filled by pack()
        self.triangles = []

    def vertex(self, position, normal, local):
        self.positions.append(tuple(position))
        self.normals.append(normalize(normal))
        self.local.append(tuple(local))
        return len(self.positions) - 1

    def triangle(self, a, b, c):
        """Adds triangle a, b, c wound counter-clockwise seen from the side its normals face."""
        p = self.positions
        face_normal = cross(sub(p[b], p[a]), sub(p[c], p[a]))
        vertex_normal = add(add(self.normals[a], self.normals[b]), self.normals[c])
        if dot(face_normal, vertex_normal) < 0:
            b, c = c, b
        self.triangles.append((a, b, c))

    def area_3d(self):
        p = self.positions
        return sum(0.5 * math.sqrt(dot(n, n)) for n in (
            cross(sub(p[b], p[a]), sub(p[c], p[a])) for a, b, c in self.triangles))

    def area_local(self):
        q = self.local
        return sum(signed_area_2d(q[a], q[b], q[c]) for a, b, c in self.triangles)


class Shape:
    def __init__(self, name, charts):
        self.name = name
        self.charts = charts

    def triangle_count(self):
        return sum(len(c.triangles) for c in self.charts)


# --- Surfaces -------------------------------------------------------------------------------


def grid_chart(origin, du, dv, nu, nv):
    """A planar parallelogram origin + s du + t dv, s, t in [0, 1], as nu × nv quads; its normal is
    du × dv and its chart coordinates are metres along du and dv."""
    chart = Chart()
    normal = normalize(cross(du, dv))
    lu, lv = math.sqrt(dot(du, du)), math.sqrt(dot(dv, dv))
    index = {}
    for j in range(nv + 1):
        for i in range(nu + 1):
            s, t = i / nu, j / nv
            position = add(origin, add(scale(du, s), scale(dv, t)))
            index[i, j] = chart.vertex(position, normal, (s * lu, t * lv))
    for j in range(nv):
        for i in range(nu):
            a, b, c, d = index[i, j], index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]
            chart.triangle(a, b, c)
            chart.triangle(a, c, d)
    return chart


def box_charts(size_x, size_y, size_z, segments):
    """A box centred on the z axis with its bottom face at z = 0; one chart per face."""
    a, b, h = size_x / 2, size_y / 2, size_z
    faces = [
        ((-a, -b, h), (2 * a, 0, 0), (0, 2 * b, 0)),  # top, +z
        ((-a, b, 0), (2 * a, 0, 0), (0, -2 * b, 0)),  # bottom, -z
        ((a, -b, 0), (0, 2 * b, 0), (0, 0, h)),  # +x
        ((-a, b, 0), (0, -2 * b, 0), (0, 0, h)),  # -x
        ((a, b, 0), (-2 * a, 0, 0), (0, 0, h)),  # +y
        ((-a, -b, 0), (2 * a, 0, 0), (0, 0, h)),  # -y
    ]
    return [grid_chart(o, du, dv, segments, segments) for o, du, dv in faces]


def moved(charts, offset):
    """The charts translated by offset (metres)."""
    for chart in charts:
        chart.positions = [add(p, offset) for p in chart.positions]
    return charts


def prism_charts(profile, length, segments):
    """A prism: the polygon `profile` (x, z points, counter-clockwise seen from -y, made of the
    rectangles `profile_rects` for the caps) extruded along y over [-length/2, length/2].
    profile is ((x, z), ...) for the sides; caps are given as rectangles (x0, z0, x1, z1)."""
    points, rects = profile
    half = length / 2
    charts = []
    n = len(points)
    for i in range(n):
        (x0, z0), (x1, z1) = points[i], points[(i + 1) % n]
        origin = (x0, -half, z0)
        du = (x1 - x0, 0.0, z1 - z0)
        dv = (0.0, length, 0.0)
        # Counter-clockwise seen from -y: the outward normal of edge (dx, dz) is (dz, -dx).
        outward = (z1 - z0, 0.0, -(x1 - x0))
        if dot(cross(du, dv), outward) < 0:
            origin, du = (x1, -half, z1), scale(du, -1)
        edge = math.hypot(x1 - x0, z1 - z0)
        charts.append(grid_chart(origin, du, dv, max(1, round(segments * edge)), segments))
    for x0, z0, x1, z1 in rects:
        # -y cap: normal (0, -1, 0) = du × dv with du along x, dv along z.
        charts.append(grid_chart((x0, -half, z0), (x1 - x0, 0, 0), (0, 0, z1 - z0), 4, 4))
        charts.append(grid_chart((x1, half, z0), (x0 - x1, 0, 0), (0, 0, z1 - z0), 4, 4))
    return charts


def uv_sphere_charts(radius, n_lon, n_lat):
    """A latitude-longitude sphere centred at the origin, poles on the z axis (a single vertex
    each). Charts: the polar caps beyond ±45° in Lambert's azimuthal equal-area projection, and
    the band between in four equirectangular quarters. n_lat must be a multiple of 4, n_lon of 4."""
    assert n_lat % 4 == 0 and n_lon % 4 == 0
    lat_of = [-math.pi / 2 + math.pi * k / n_lat for k in range(n_lat + 1)]
    lon_of = [2 * math.pi * j / n_lon for j in range(n_lon + 1)]

    def point(k, j):
        lat, lon = lat_of[k], lon_of[j]
        n = (math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat))
        if k == 0:
            n = (0.0, 0.0, -1.0)
        if k == n_lat:
            n = (0.0, 0.0, 1.0)
        return scale(n, radius), n

    charts = []
    cap_rings = n_lat // 4
    for pole in (0, n_lat):
        chart = Chart()
        step = 1 if pole == 0 else -1
        position, normal = point(pole, 0)
        centre = chart.vertex(position, normal, (0.0, 0.0))
        rings = []
        for r in range(1, cap_rings + 1):
            k = pole + step * r
            colatitude = math.pi / 2 - abs(lat_of[k])  # from this cap's pole
            rho = 2 * radius * math.sin(colatitude / 2)
            ring = []
            for j in range(n_lon):
                position, normal = point(k, j)
                lon = lon_of[j]
                local = (rho * math.cos(lon), rho * math.sin(lon))
                ring.append(chart.vertex(position, normal, local))
            rings.append(ring)
        for j in range(n_lon):
            chart.triangle(centre, rings[0][j], rings[0][(j + 1) % n_lon])
        for r in range(cap_rings - 1):
            inner, outer = rings[r], rings[r + 1]
            for j in range(n_lon):
                j1 = (j + 1) % n_lon
                chart.triangle(inner[j], outer[j], outer[j1])
                chart.triangle(inner[j], outer[j1], inner[j1])
        charts.append(chart)

    quarter = n_lon // 4
    for q in range(4):
        chart = Chart()
        index = {}
        for k in range(cap_rings, n_lat - cap_rings + 1):
            for j in range(q * quarter, (q + 1) * quarter + 1):
                position, normal = point(k, j)
                local = (radius * lon_of[j], radius * lat_of[k])
                index[k, j] = chart.vertex(position, normal, local)
        for k in range(cap_rings, n_lat - cap_rings):
            for j in range(q * quarter, (q + 1) * quarter):
                a, b, c, d = index[k, j], index[k, j + 1], index[k + 1, j + 1], index[k + 1, j]
                chart.triangle(a, b, c)
                chart.triangle(a, c, d)
        charts.append(chart)
    return charts


def torus_charts(major, minor, n_major, n_minor, n_charts):
    """A torus around the z axis, centred at the origin. Minor angle θ = 0 on the outer equator;
    the minor seam is on the inner equator. Each of n_charts arcs maps (φ, θ) to
    ((φ − φ_c)(R + r cos θ), r θ), which preserves area (its Jacobian is the torus's area element
    r (R + r cos θ))."""
    assert n_major % n_charts == 0
    per_chart = n_major // n_charts
    charts = []
    for c in range(n_charts):
        chart = Chart()
        phi_centre = 2 * math.pi * (c + 0.5) / n_charts
        index = {}
        for j in range(c * per_chart, (c + 1) * per_chart + 1):
            phi = 2 * math.pi * j / n_major
            for k in range(n_minor + 1):
                theta = -math.pi + 2 * math.pi * k / n_minor
                ring = major + minor * math.cos(theta)
                position = (ring * math.cos(phi), ring * math.sin(phi), minor * math.sin(theta))
                normal = (math.cos(theta) * math.cos(phi), math.cos(theta) * math.sin(phi),
                          math.sin(theta))
                local = ((phi - phi_centre) * ring, minor * theta)
                index[j, k] = chart.vertex(position, normal, local)
        for j in range(c * per_chart, (c + 1) * per_chart):
            for k in range(n_minor):
                a, b, cc, d = index[j, k], index[j + 1, k], index[j + 1, k + 1], index[j, k + 1]
                chart.triangle(a, b, cc)
                chart.triangle(a, cc, d)
        charts.append(chart)
    return charts


def cone_charts(radius, height, segments, side_rings, base_rings):
    """A cone standing on z = 0 with its apex on the z axis. Charts: the side, developed into a
    circular sector (exact: a cone is developable), and the base disk."""
    slant = math.hypot(radius, height)
    sector = radius / slant  # developed angle per radian around the axis
    side = Chart()
    index = {}
    for i in range(1, side_rings + 1):
        t = i / side_rings
        for j in range(segments + 1):
            phi = 2 * math.pi * j / segments
            position = (t * radius * math.cos(phi), t * radius * math.sin(phi), height * (1 - t))
            normal = (height * math.cos(phi), height * math.sin(phi), radius)
            angle = phi * sector
            index[i, j] = side.vertex(position, normal,
                                      (t * slant * math.cos(angle), t * slant * math.sin(angle)))
    for j in range(segments):
        # The apex has no single normal: one apex vertex per segment, with the segment's normal.
        mid = 2 * math.pi * (j + 0.5) / segments
        apex_normal = (height * math.cos(mid), height * math.sin(mid), radius)
        apex = side.vertex((0.0, 0.0, height), apex_normal, (0.0, 0.0))
        side.triangle(apex, index[1, j], index[1, j + 1])
    for i in range(1, side_rings):
        for j in range(segments):
            a, b, c, d = index[i, j], index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]
            side.triangle(a, b, c)
            side.triangle(a, c, d)

    base = Chart()
    down = (0.0, 0.0, -1.0)
    centre = base.vertex((0.0, 0.0, 0.0), down, (0.0, 0.0))
    rings = []
    for i in range(1, base_rings + 1):
        rho = radius * i / base_rings
        ring = []
        for j in range(segments):
            phi = 2 * math.pi * j / segments
            p = (rho * math.cos(phi), rho * math.sin(phi), 0.0)
            ring.append(base.vertex(p, down, (p[0], p[1])))
        rings.append(ring)
    for j in range(segments):
        base.triangle(centre, rings[0][j], rings[0][(j + 1) % segments])
    for i in range(base_rings - 1):
        inner, outer = rings[i], rings[i + 1]
        for j in range(segments):
            j1 = (j + 1) % segments
            base.triangle(inner[j], outer[j], outer[j1])
            base.triangle(inner[j], outer[j1], inner[j1])
    return [side, base]


# --- Lightmap packing ----------------------------------------------------------------------


def pack(shape, gutter_texels=GUTTER_TEXELS, border_texels=BORDER_TEXELS):
    """Places every chart of shape in [0, 1]^2 at one common scale, as large as a shelf packing
    allows, charts apart by the gutter. Charts whose chart coordinates run clockwise (seen from
    the surface's front) are mirrored first, so every UV triangle is counter-clockwise."""
    gutter = gutter_texels / RESOLUTION
    border = border_texels / RESOLUTION
    for chart in shape.charts:
        if chart.area_local() < 0:
            chart.local = [(-x, y) for x, y in chart.local]
    boxes = []
    for chart in shape.charts:
        xs = [q[0] for q in chart.local]
        ys = [q[1] for q in chart.local]
        boxes.append((min(xs), min(ys), max(xs) - min(xs), max(ys) - min(ys)))
    order = sorted(range(len(boxes)), key=lambda i: (-boxes[i][3], -boxes[i][2], i))

    def place(s):
        """Chart offsets at scale s, or None when they do not fit."""
        limit = 1 - border
        x, y, shelf = border, border, 0.0
        offsets = {}
        for i in order:
            w, h = boxes[i][2] * s, boxes[i][3] * s
            if x + w > limit and x > border:
                x, y, shelf = border, y + shelf + gutter, 0.0
            if x + w > limit or y + h > limit:
                return None
            offsets[i] = (x, y)
            x += w + gutter
            shelf = max(shelf, h)
        return offsets

    lo, hi = 0.0, 1.0 / max(max(b[2], b[3]) for b in boxes)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if place(mid) else (lo, mid)
    s = lo
    offsets = place(s)
    for i, chart in enumerate(shape.charts):
        ox, oy = offsets[i]
        x0, y0 = boxes[i][0], boxes[i][1]
        chart.uv = [(ox + (x - x0) * s, oy + (y - y0) * s) for x, y in chart.local]
    check_layout(shape, gutter)
    return s


def check_layout(shape, gutter):
    extents = []
    for chart in shape.charts:
        for u, v in chart.uv:
            assert -1e-12 <= u <= 1 + 1e-12 and -1e-12 <= v <= 1 + 1e-12, (shape.name, u, v)
        for a, b, c in chart.triangles:
            assert signed_area_2d(chart.uv[a], chart.uv[b], chart.uv[c]) > 0, (shape.name, "fold")
        us = [q[0] for q in chart.uv]
        vs = [q[1] for q in chart.uv]
        extents.append((min(us), min(vs), max(us), max(vs)))
    for i in range(len(extents)):
        for j in range(i + 1, len(extents)):
            a, b = extents[i], extents[j]
            gap = max(b[0] - a[2], a[0] - b[2], b[1] - a[3], a[1] - b[3])
            assert gap >= gutter - 1e-9, (shape.name, i, j, gap)


def density_spread(shape):
    """Max / min over charts of UV area per square metre (1 = perfectly uniform)."""
    densities = []
    for chart in shape.charts:
        uv_area = sum(signed_area_2d(chart.uv[a], chart.uv[b], chart.uv[c])
                      for a, b, c in chart.triangles)
        densities.append(uv_area / chart.area_3d())
    return max(densities) / min(densities)


def single_chart_uv(shape, uv_of_position):
    """For a layout fixed by the scene's purpose (the closed-form test floors): UV as a function of
    position."""
    for chart in shape.charts:
        chart.uv = [uv_of_position(p) for p in chart.positions]
    check_layout(shape, 0.0)


# --- Writers -------------------------------------------------------------------------------


def fmt(x):
    """Fixed six decimals (micrometres), without a negative zero."""
    text = f"{x:.6f}"
    return "0.000000" if text == "-0.000000" else text


def obj_text(shape):
    lines = [f"# {shape.name}: {HEADER}", f"# {shape.triangle_count()} triangles, "
             f"{len(shape.charts)} lightmap chart(s) in UV set 0", f"o {shape.name}"]
    tables = {"v": {}, "vt": {}, "vn": {}}
    body = {"v": [], "vt": [], "vn": []}

    def ref(kind, values):
        key = " ".join(fmt(x) for x in values)
        table = tables[kind]
        if key not in table:
            table[key] = len(table) + 1
            body[kind].append(f"{kind} {key}")
        return table[key]

    faces = []
    for chart in shape.charts:
        corner = [(ref("v", p), ref("vt", uv), ref("vn", n))
                  for p, uv, n in zip(chart.positions, chart.uv, chart.normals)]
        for tri in chart.triangles:
            faces.append("f " + " ".join("%d/%d/%d" % corner[i] for i in tri))
    return "\n".join(lines + body["v"] + body["vt"] + body["vn"] + ["s off"] + faces) + "\n"


def gltf_text(shape, y_up=True):
    """glTF 2.0 with one embedded (base64 data: URI) buffer: POSITION, NORMAL, TEXCOORD_0 and
    indices. With y_up the Z-up positions and normals are written as glTF's Y-up (x, z, −y);
    rotate the object by +90° about X in the scene to stand it back up. TEXCOORD_0 follows glTF's
    top-left origin: t = 1 − v (Assimp flips it back)."""
    def to_file(p):
        return (p[0], p[2], -p[1]) if y_up else p

    positions, normals, texcoords, indices = [], [], [], []
    for chart in shape.charts:
        base = len(positions)
        positions += [to_file(p) for p in chart.positions]
        normals += [to_file(n) for n in chart.normals]
        texcoords += [(u, 1.0 - v) for u, v in chart.uv]
        indices += [base + i for tri in chart.triangles for i in tri]
    index_format, index_type = ("<H", 5123) if len(positions) < 65536 else ("<I", 5125)

    blob = bytearray()
    views = []

    def view(data, target):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data),
                      "target": target})
        blob.extend(data)
        return len(views) - 1

    def floats(rows):
        return b"".join(struct.pack("<%df" % len(r), *r) for r in rows)

    pos_view = view(floats(positions), 34962)
    nrm_view = view(floats(normals), 34962)
    uv_view = view(floats(texcoords), 34962)
    idx_view = view(b"".join(struct.pack(index_format, i) for i in indices), 34963)
    f32 = [[struct.unpack("<f", struct.pack("<f", x))[0] for x in p] for p in positions]
    document = {
        "asset": {"version": "2.0", "generator": "shadowbake tests/tools/make_scenes.py"},
        "extras": {"note": HEADER},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": shape.name, "mesh": 0}],
        "meshes": [{"name": shape.name, "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": 3, "mode": 4}]}],
        "accessors": [
            {"bufferView": pos_view, "componentType": 5126, "count": len(positions),
             "type": "VEC3", "min": [min(p[i] for p in f32) for i in range(3)],
             "max": [max(p[i] for p in f32) for i in range(3)]},
            {"bufferView": nrm_view, "componentType": 5126, "count": len(normals), "type": "VEC3"},
            {"bufferView": uv_view, "componentType": 5126, "count": len(texcoords),
             "type": "VEC2"},
            {"bufferView": idx_view, "componentType": index_type, "count": len(indices),
             "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," +
                     base64.b64encode(bytes(blob)).decode("ascii")}],
    }
    return json.dumps(document, indent=1) + "\n"


def toml_number(x):
    if float(x).is_integer():
        return str(int(x))
    return repr(round(x, 6))


def toml_vec(values):
    return "[" + ", ".join(toml_number(x) for x in values) + "]"


def bake_table(samples, method="reference"):
    return ["[bake]", "resolution = 512", f'method = "{method}"', 'quantity = "visibility"',
            f"samples = {samples}", "margin = 4", ""]


def object_table(name, mesh, receiver, blocker, translate=None, rotate_deg=None, comment=None):
    lines = ["[[object]]"]
    if comment:
        lines.insert(0, f"# {comment}")
    lines += [f'name = "{name}"', f'mesh = "{mesh}"', f"receiver = {str(receiver).lower()}",
              f"blocker = {str(blocker).lower()}", "uv = 0"]
    if translate:
        lines.append(f"translate = {toml_vec(translate)}")
    if rotate_deg:
        lines.append(f"rotate_deg = {toml_vec(rotate_deg)}")
    return lines + [""]


def light_table(name, shape, position, normal=None, up=None, size=None, radius=None,
                color=(1, 1, 1), power=100.0, comment=None):
    lines = ["[[light]]"]
    if comment:
        lines.insert(0, f"# {comment}")
    lines += [f'name = "{name}"', f'shape = "{shape}"', f"position = {toml_vec(position)}"]
    if normal:
        lines.append(f"normal = {toml_vec(normal)}")
    if up:
        lines.append(f"up = {toml_vec(up)}")
    if size:
        lines.append(f"size = {toml_vec(size)}")
    if radius is not None:
        lines.append(f"radius = {toml_vec([radius])}")
    lines += [f"color = {toml_vec(color)}", f"power = {float(power)!r}", ""]
    return lines


# --- Scenes --------------------------------------------------------------------------------


class Writer:
    def __init__(self, root):
        self.root = root

    def write(self, relative, text):
        path = self.root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "w", encoding="utf-8", newline="\n") as out:
            out.write(text)
        return path

    def mesh(self, folder, shape, file_format="obj", note=""):
        name = f"{shape.name}.{file_format}"
        text = obj_text(shape) if file_format == "obj" else gltf_text(shape)
        path = self.write(Path(folder) / name, text)
        spread = density_spread(shape)
        print(f"wrote {path.relative_to(self.root.parent)}: {shape.triangle_count()} triangles, "
              f"{len(shape.charts)} chart(s), density spread {spread:.2f}{note}")
        return name

    def scene(self, folder, lines):
        path = self.write(Path(folder) / "scene.toml", "\n".join(lines).rstrip("\n") + "\n")
        print(f"wrote {path.relative_to(self.root.parent)}")


def write_showcase(w):
    folder = "showcase"
    floor = Shape("floor", [grid_chart((-2, -2, 0), (4, 0, 0), (0, 4, 0), 16, 16)])
    wall = Shape("wall", [grid_chart((-2, 2, 0), (4, 0, 0), (0, 0, 2.5), 16, 10)])
    box = Shape("box", box_charts(0.5, 0.4, 0.6, 4))
    sphere = Shape("sphere", uv_sphere_charts(0.35, 64, 32))
    torus = Shape("torus", torus_charts(0.28, 0.07, 64, 24, 8))
    cone = Shape("cone", cone_charts(0.2, 0.55, 48, 4, 3))
    for shape in (floor, wall, box, sphere, torus, cone):
        pack(shape)
    total = sum(s.triangle_count() for s in (floor, wall, box, sphere, torus, cone))
    assert total < 20000

    panel_normal = normalize((0.1, 0.15, -1.0))
    lines = [f"# {HEADER}.",
             "# Showcase. Z up, metres. A corner of a room: floor, back wall and four objects",
             "# resting on the floor, lit by a tilted panel above and a small warm sphere light",
             "# low at the front left. Baked with the default method; samples serve",
             "# --method reference and the sampling baselines.", ""]
    lines += bake_table(64, "backprojection")
    lines += object_table("floor", w.mesh(folder, floor), True, True, comment="4 x 4 m, z = 0")
    lines += object_table("wall", w.mesh(folder, wall), True, True,
                          comment="4 x 2.5 m at y = 2, facing -y")
    lines += object_table("box", w.mesh(folder, box), True, True, translate=(-0.8, 0.6, 0),
                          rotate_deg=(0, 0, 25), comment="0.5 x 0.4 x 0.6 m, bottom face on z = 0")
    lines += object_table("sphere", w.mesh(folder, sphere, "gltf", " (glTF 2.0, Y up)"), True,
                          True, translate=(0.3, 0.4, 0.35), rotate_deg=(90, 0, 0),
                          comment="radius 0.35 m, touching the floor at one point; glTF is Y up, "
                          "rotate_deg stands it in Z up")
    lines += object_table("torus", w.mesh(folder, torus), False, True,
                          translate=(0.6, -0.8, 0.07),
                          comment="R 0.28 m, r 0.07 m, lying on the floor")
    lines += object_table("cone", w.mesh(folder, cone), False, True, translate=(-0.5, -0.5, 0),
                          comment="radius 0.2 m, height 0.55 m, standing on the floor")
    lines += light_table("panel", "rectangle", (0.1, 0, 1.8), normal=panel_normal, up=(0, 1, 0),
                         size=(0.8, 0.5), comment="0.8 x 0.5 m panel 1.8 m up, tilted slightly")
    # A 100 W sphere light spreads its power over all directions and sits further away than the
    # panel: 600 W makes its irradiance on the back wall about equal to the panel's, so its long
    # shadows (box, sphere and cone on the wall; the cone's across the sphere) show.
    lines += light_table("bulb", "sphere", (-1.2, -1.6, 0.8), radius=0.12, color=(1, 0.85, 0.7),
                         power=600, comment="a small warm sphere light low down, front left; "
                         "600 W to match the panel on the wall")
    w.scene(folder, lines)


def parallel_floor():
    """The 2 × 2 m floor of the closed-form scenes: two triangles, u = (x + 1)/2, v = (y + 1)/2."""
    shape = Shape("floor", [grid_chart((-1, -1, 0), (2, 0, 0), (0, 2, 0), 1, 1)])
    single_chart_uv(shape, lambda p: ((p[0] + 1) / 2, (p[1] + 1) / 2))
    return shape


def parallel_blocker():
    """A 0.6 m square, zero thickness, at z = 0.5 centred on the axis, facing the light."""
    shape = Shape("blocker", [grid_chart((-0.3, -0.3, 0.5), (0.6, 0, 0), (0, 0.6, 0), 1, 1)])
    single_chart_uv(shape, lambda p: ((p[0] + 0.3) / 0.6, (p[1] + 0.3) / 0.6))
    return shape


def write_closed_form_scenes(w):
    floor_comment = "2 x 2 m at z = 0; uv = ((x + 1) / 2, (y + 1) / 2)"
    blocker_comment = "0.6 x 0.6 m square, zero thickness, at z = 0.5, parallel to the floor"

    lines = [f"# {HEADER}.", "# An unoccluded floor under a square light. Irradiance has a closed "
             "form here", "# (Lambert's polygon formula); visibility is 1 everywhere.", ""]
    lines += bake_table(256)
    lines += object_table("floor", w.mesh("plane", parallel_floor()), True, False,
                          comment=floor_comment)
    lines += light_table("panel", "rectangle", (0, 0, 1.5), normal=(0, 0, -1), up=(0, 1, 0),
                         size=(0.5, 0.5), comment="0.5 x 0.5 m, 1.5 m up, facing down")
    w.scene("plane", lines)

    lights = {
        "parallel": (["# Three parallel planes: light, blocker and floor (design notes,",
                      "# section 2). The shadow is a convolution with a closed form; along the",
                      "# x axis the penumbra spans |x| in [0.325, 0.575]."],
                     light_table("panel", "rectangle", (0, 0, 1.5), normal=(0, 0, -1), up=(0, 1, 0),
                                 size=(0.5, 0.5), comment="0.5 x 0.5 m, 1.5 m up, facing down")),
        "disk": (["# The parallel-plane case with a disk light of radius 0.25 m."],
                 light_table("disk", "disk", (0, 0, 1.5), normal=(0, 0, -1), radius=0.25,
                             comment="radius 0.25 m, 1.5 m up, facing down")),
        "sphere": (["# The parallel-plane case with a sphere light of radius 0.25 m."],
                   light_table("bulb", "sphere", (0, 0, 1.5), radius=0.25,
                               comment="radius 0.25 m, centred 1.5 m up")),
    }
    for folder, (intro, light) in lights.items():
        lines = [f"# {HEADER}."] + intro + [""]
        lines += bake_table(256)
        lines += object_table("floor", w.mesh(folder, parallel_floor()), True, False,
                              comment=floor_comment)
        lines += object_table("blocker", w.mesh(folder, parallel_blocker()), False, True,
                              comment=blocker_comment)
        lines += light
        w.scene(folder, lines)


def write_subdivision_scenes(w):
    """The scenes of the convolution's error-driven subdivision and of the baselines' table:
    geometry touching its receiver, a tilted off-axis light, an object that shadows itself."""
    floor_comment = "3 x 3 m at z = 0"

    floor = Shape("floor", [grid_chart((-1.5, -1.5, 0), (3, 0, 0), (0, 3, 0), 12, 12)])
    top = moved(box_charts(1.0, 0.6, 0.04, 2), (0, 0, 0.72))
    legs = []
    for x in (-0.45, 0.45):
        for y in (-0.25, 0.25):
            legs += moved(box_charts(0.05, 0.05, 0.72, 2), (x, y, 0))
    table = Shape("table", top + legs)
    for shape in (floor, table):
        pack(shape)
    lines = [f"# {HEADER}.", "# A table on a floor: a top 0.76 m up on four legs that touch the floor,",
             "# so its shadow is sharp at the feet and soft under the top.", ""]
    lines += bake_table(256, "convolution")
    lines += object_table("floor", w.mesh("table", floor), True, True, comment=floor_comment)
    lines += object_table("table", w.mesh("table", table), False, True,
                          comment="1 x 0.6 m top, 4 cm thick, on four 5 cm legs 0.72 m long")
    lines += light_table("panel", "rectangle", (0.3, -0.2, 2.0), normal=normalize((-0.1, 0.05, -1)),
                         up=(0, 1, 0), size=(0.6, 0.6), comment="0.6 x 0.6 m, 2 m up, off-centre")
    w.scene("table", lines)

    floor = Shape("floor", [grid_chart((-2, -2, 0), (4, 0, 0), (0, 4, 0), 16, 16)])
    posts = []
    for x, y, h in ((-1.0, -0.6, 1.0), (-0.3, 0.5, 1.2), (0.4, -0.3, 0.8), (1.0, 0.6, 1.0),
                    (0.0, -1.2, 0.6)):
        posts += moved(box_charts(0.08, 0.08, h, 4), (x, y, 0))
    posts = Shape("posts", posts)
    for shape in (floor, posts):
        pack(shape)
    lines = [f"# {HEADER}.", "# Posts standing on a floor under a long, tilted strip light off to the",
             "# side: each shadow is sharp at the post's foot and widens towards its tip.", ""]
    lines += bake_table(256, "convolution")
    lines += object_table("floor", w.mesh("posts", floor), True, True, comment="4 x 4 m at z = 0")
    lines += object_table("posts", w.mesh("posts", posts), False, True,
                          comment="five 8 cm square posts, 0.6 to 1.2 m tall")
    lines += light_table("strip", "rectangle", (1.4, -1.0, 2.2), normal=normalize((-0.45, 0.3, -1)),
                         up=normalize((1, 1, 0)), size=(1.4, 0.12),
                         comment="1.4 x 0.12 m strip, 2.2 m up, off to the side, tilted towards "
                         "the posts")
    w.scene("posts", lines)

    floor = Shape("floor", [grid_chart((-1.5, -1.5, 0), (3, 0, 0), (0, 3, 0), 12, 12)])
    # An L-shaped bracket: a 1 m base 10 cm thick with a 12 cm wall 0.8 m tall at its -x end.
    profile = (((0, 0), (1.0, 0), (1.0, 0.1), (0.12, 0.1), (0.12, 0.8), (0, 0.8)),
               ((0, 0, 1.0, 0.1), (0, 0.1, 0.12, 0.8)))
    bracket = Shape("bracket", moved(prism_charts(profile, 1.2, 8), (-0.5, 0, 0)))
    for shape in (floor, bracket):
        pack(shape)
    lines = [f"# {HEADER}.", "# An L-shaped bracket that shadows itself: its wall casts a shadow across",
             "# its own base and onto the floor beyond.", ""]
    lines += bake_table(256, "convolution")
    lines += object_table("floor", w.mesh("bracket", floor), True, True, comment=floor_comment)
    lines += object_table("bracket", w.mesh("bracket", bracket), True, True,
                          comment="L-shaped prism 1.2 m long: base 1 x 0.1 m, wall 0.12 x 0.8 m")
    lines += light_table("panel", "rectangle", (-1.1, -0.3, 1.4), normal=normalize((0.5, 0.1, -1)),
                         up=(0, 1, 0), size=(0.6, 0.4), comment="0.6 x 0.4 m, 1.4 m up, to the "
                         "wall's side so the wall shades the base")
    w.scene("bracket", lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    default = Path(__file__).resolve().parents[2] / "scenes"
    parser.add_argument("--out", type=Path, default=default,
                        help="scenes folder (default: %(default)s)")
    args = parser.parse_args()
    writer = Writer(args.out.resolve())
    write_showcase(writer)
    write_closed_form_scenes(writer)
    write_subdivision_scenes(writer)


if __name__ == "__main__":
    main()
