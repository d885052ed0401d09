"""A third opinion on a level's per-light visibility, from neither shadowbake's ray tracer nor
Cycles' renderer: V = H / H0 at chosen texels, estimated by Monte Carlo over the light with
Blender's own BVH ray casts (scene.ray_cast) on the level as Blender's glTF importer reads it.

    blender -b --factory-startup -P tests/tools/blender_raycast_check.py -- LEVEL.glb \
        --light NAME --receiver NAME --ours OURS.exr [--against CYCLES.exr] \
        [--res 256] [--count 24] [--samples 4000] [--radius 0]

Texels: those given by --at X,ROW, or `count` texels of the receiver's lightmap (UV set 1, res²) where OURS.exr (shadowbake's
per-light image of that light, row 0 at v = 1) is in the penumbra (0.05 < V < 0.95) and all eight
neighbours are covered too, spread evenly over them. For each, the texel centre's point on the
receiver (the triangle whose UVs hold it) and its face normal; then V = Σ w·v / Σ w over samples of
the light as shadowbake defines it:
- an emissive mesh (rectangle, disc or mesh light): points uniform by area over its triangles,
  w = cos θ_light · cos θ_receiver / r² for a triangle whose front faces the point, else 0;
- a point or spot lamp: a sphere of --radius (0: one ray to its centre), cone-sampled, w = cos θ;
- a sun: directions within Blender's 0.526° about its direction, w = cos θ.
v = 1 where scene.ray_cast from 10⁻⁴ m above the point finds nothing before the light point
(lights and emitters hidden). Prints one line per texel (x, row, world point, brute force, ours,
Cycles) and the RMSE of ours and of Cycles against the brute force, whose own standard error is
about 0.5 / √samples.
"""

import argparse
import math
import random
import sys

import bpy
import mathutils
import numpy

if not hasattr(numpy, "bool"):  # Blender 3.4's glTF importer and Debian 12's numpy 1.24
    numpy.bool = bool

ap = argparse.ArgumentParser(prog="blender_raycast_check.py")
ap.add_argument("level")
ap.add_argument("--light", required=True)
ap.add_argument("--receiver", required=True)
ap.add_argument("--ours", required=True)
ap.add_argument("--against")  # Cycles' image (Blender claims --cycles-*)
ap.add_argument("--res", type=int, default=256)
ap.add_argument("--count", type=int, default=24)
ap.add_argument("--samples", type=int, default=4000)
ap.add_argument("--radius", type=float, default=0.0)
ap.add_argument("--at", action="append", default=[],
                help="X,ROW: this texel instead of penumbra texels picked from OURS (repeatable)")
args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:])

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
bpy.ops.import_scene.gltf(filepath=args.level)
light = scene.objects[args.light]
receiver = scene.objects[args.receiver]
res = args.res


def emits(obj):
    if obj.type != "MESH":
        return False
    for slot in obj.material_slots:
        m = slot.material
        if m is None or not m.use_nodes:
            continue
        for node in m.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED" and max(node.inputs["Emission"].default_value[:3]) > 0 \
                    and node.inputs["Emission Strength"].default_value > 0:
                return True
            if node.type == "EMISSION" and node.inputs["Strength"].default_value > 0:
                return True
    return False


# The light's own geometry, in world space, before it is hidden.
triangles = []  # (a, b, c, unit normal, area)
if light.type == "MESH":
    mesh = light.data
    mesh.calc_loop_triangles()
    for tri in mesh.loop_triangles:
        a, b, c = (light.matrix_world @ mesh.vertices[i].co for i in tri.vertices)
        cross = (b - a).cross(c - a)
        if cross.length > 0:
            triangles.append((a, b, c, cross.normalized(), cross.length / 2))
    cumulative = numpy.cumsum([t[4] for t in triangles])
for obj in scene.objects:
    if obj.type == "LIGHT" or emits(obj):
        obj.hide_viewport = True
depsgraph = bpy.context.evaluated_depsgraph_get()


def image_pixels(path):
    image = bpy.data.images.load(path)
    pixels = numpy.array(image.pixels[:]).reshape(image.size[1], image.size[0], image.channels)
    return pixels[::-1, :, 0]  # row 0 at v = 1, as shadowbake writes


ours = image_pixels(args.ours)
cycles = image_pixels(args.against) if args.against else None

# The receiver's triangles in its lightmap UVs (set 1), for the texel centres' points.
rmesh = receiver.data
rmesh.calc_loop_triangles()
uv = rmesh.uv_layers[1].data
rtris = []
for tri in rmesh.loop_triangles:
    uvs = [mathutils.Vector(uv[loop].uv) for loop in tri.loops]
    points = [receiver.matrix_world @ rmesh.vertices[i].co for i in tri.vertices]
    normal = (points[1] - points[0]).cross(points[2] - points[0]).normalized()
    rtris.append((uvs, points, normal))


def texel_point(x, row):
    p = mathutils.Vector(((x + 0.5) / res, 1 - (row + 0.5) / res))
    for uvs, points, normal in rtris:
        a, b, c = uvs
        det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y)
        if det == 0:
            continue
        s = ((p.x - a.x) * (c.y - a.y) - (c.x - a.x) * (p.y - a.y)) / det
        t = ((b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y)) / det
        if s >= 0 and t >= 0 and s + t <= 1:
            return points[0] + s * (points[1] - points[0]) + t * (points[2] - points[0]), normal
    return None, None


def visible(origin, target):
    direction = target - origin
    distance = direction.length
    hit = scene.ray_cast(depsgraph, origin, direction / distance, distance=distance - 2e-4)[0]
    return 0.0 if hit else 1.0


def brute_force(y, n, rng):
    origin = y + 1e-4 * n
    num = den = 0.0
    for _ in range(args.samples):
        if light.type == "MESH":
            k = int(numpy.searchsorted(cumulative, rng.random() * cumulative[-1], side="right"))
            a, b, c, normal, _area = triangles[min(k, len(triangles) - 1)]
            su, v = math.sqrt(rng.random()), rng.random()
            x = (1 - su) * a + su * ((1 - v) * b + v * c)
            d = x - y
            r2 = d.length_squared
            cos_l, cos_r = -d.dot(normal) / math.sqrt(r2), d.dot(n) / math.sqrt(r2)
            if cos_l <= 0 or cos_r <= 0:
                continue
            w, target = cos_l * cos_r / r2, x
        else:
            if light.data.type == "SUN":
                axis = -(light.matrix_world.to_3x3() @ mathutils.Vector((0, 0, -1))).normalized()
                cos_max, distance = math.cos(math.radians(0.526) / 2), 1e4
            else:
                to = light.matrix_world.translation - y
                distance = to.length
                axis = to / distance
                cos_max = math.sqrt(max(0.0, 1 - (args.radius / distance) ** 2))
            ct = 1 - rng.random() * (1 - cos_max)
            st = math.sqrt(max(0.0, 1 - ct * ct))
            phi = 2 * math.pi * rng.random()
            e1 = axis.orthogonal().normalized()
            e2 = axis.cross(e1)
            direction = ct * axis + st * (math.cos(phi) * e1 + math.sin(phi) * e2)
            w = direction.dot(n)
            if w <= 0:
                continue
            # To the sphere's near side (or the sun's far point); a point lamp: its centre.
            proj = direction.dot(axis) * distance
            reach = distance if light.data.type == "SUN" else \
                proj - math.sqrt(max(0.0, args.radius ** 2 - (distance ** 2 - proj ** 2)))
            target = y + direction * reach
        num += w * visible(origin, target)
        den += w
    return num / den if den > 0 else float("nan")


candidates = []
for row in range(1, res - 1):
    for x in range(1, res - 1):
        if 0.05 < ours[row, x] < 0.95:
            candidates.append((x, row))
if args.at:
    candidates = [tuple(int(c) for c in at.split(",")) for at in args.at]
rng = random.Random(1)
picked = []
step = max(1, len(candidates) // max(1, args.count))
for x, row in candidates[::step]:
    y, n = texel_point(x, row)
    if y is None or (not args.at and any(texel_point(x + dx, row + dy)[0] is None
                                         for dx in (-1, 0, 1) for dy in (-1, 0, 1))):
        continue
    picked.append((x, row, y, n))
    if len(picked) == args.count:
        break
sq_ours = sq_cycles = 0.0
for x, row, y, n in picked:
    v = brute_force(y, n, rng)
    line = f"TEXEL {x:4d} {row:4d}  ({y.x:7.3f} {y.y:7.3f} {y.z:7.3f})  brute {v:.3f}  ours {ours[row, x]:.3f}"
    sq_ours += (ours[row, x] - v) ** 2
    if cycles is not None:
        line += f"  cycles {cycles[row, x]:.3f}"
        sq_cycles += (cycles[row, x] - v) ** 2
    print(line, flush=True)
if picked:
    summary = f"RMSE against the brute force over {len(picked)} texels: ours {math.sqrt(sq_ours / len(picked)):.4f}"
    if cycles is not None:
        summary += f", Cycles {math.sqrt(sq_cycles / len(picked)):.4f}"
    print(summary + f" (brute force's own standard error ~{0.5 / math.sqrt(args.samples):.4f})")
