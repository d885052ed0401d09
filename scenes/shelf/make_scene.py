"""A bookshelf against a wall, as an artist blocks it out: a 3 x 3 m floor, a wall (a thin box,
2.5 m tall) and a 1 x 0.32 x 1.8 m bookshelf (two sides, a top, a plinth, three shelves and a
back panel: boxes joined into one object, slightly bevelled), holding books (boxes of seeded
random sizes, upright, one leaning and a small stack lying flat; joined into one object). Lightmap
UVs (Smart UV Project, charts a fixed fraction of the atlas apart) in channel 1, Blender's own
texture UVs in channel 0, each object exported as Y-up glTF binary.

Lit by a 0.9 x 0.6 m panel in front of the shelf and above it, tilted towards it: the shelf's
compartments are non-convex, so the shelves shadow the books and the back panel below them.

    blender -b --factory-startup -P scenes/shelf/make_scene.py
"""

import math
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()
ba.reset()
rng = random.Random(7)

# Floor x, y in [-1.5, 1.5]; the wall's face at y = 1.0; the shelf's back 1 cm in front of it.
bpy.ops.mesh.primitive_plane_add(size=3.0, location=(0, 0, 0))
floor = bpy.context.active_object
floor.name = "floor"
wall = ba.box_between("wall", (-1.5, 1.0, 0.0), (1.5, 1.1, 2.5))

x0, x1 = -0.5, 0.5          # outer width 1 m
y0, y1 = 0.67, 0.99         # front edge, back (against the wall)
board = 0.02                # sides, top, shelves
back = 0.01                 # back panel
height = 1.8
shelf_tops = [0.08, 0.5, 0.92, 1.34]  # plinth top and three shelves' top faces
parts = [ba.box_between("side_left", (x0, y0, 0.0), (x0 + board, y1, height)),
         ba.box_between("side_right", (x1 - board, y0, 0.0), (x1, y1, height)),
         ba.box_between("top", (x0 + board, y0, height - board), (x1 - board, y1 - back, height)),
         ba.box_between("back", (x0 + board, y1 - back, 0.0), (x1 - board, y1, height - board)),
         ba.box_between("plinth", (x0 + board, y0 + 0.02, 0.0), (x1 - board, y1 - back, shelf_tops[0]))]
for i, top in enumerate(shelf_tops[1:]):
    parts.append(ba.box_between(f"shelf_{i + 1}", (x0 + board, y0, top - board), (x1 - board, y1 - back, top)))
shelf = ba.join(parts, "shelf")
ba.bevel(shelf, width=0.002, segments=1)
ba.canonical_order(shelf)

# Books: a row on each level, left to right, with seeded sizes; the last book of the second row
# leans against its neighbour; a small stack lies flat at the right end of the top shelf.
books = []
inner_left, inner_right = x0 + board + 0.01, x1 - board - 0.01
for level, base in enumerate(shelf_tops):
    clearance = (shelf_tops[level + 1] - board if level + 1 < len(shelf_tops) else height - board) - base
    x = inner_left + rng.uniform(0.0, 0.04)
    row_end = inner_right - {1: 0.15, 3: 0.25}.get(level, rng.uniform(0.05, 0.15))
    while True:
        width = rng.uniform(0.022, 0.05)
        if x + width > row_end:
            break
        tall = rng.uniform(0.55, 0.85) * clearance
        deep = rng.uniform(0.16, 0.24)
        y_front = y1 - back - 0.005 - deep
        books.append(ba.box_between(f"book_{len(books)}", (x, y_front, base), (x + width, y_front + deep, base + tall)))
        x += width + rng.uniform(0.0, 0.004)
    if level == 1:
        # Lean a book 20 degrees to the left, on its lower left edge, clear of the row's last
        # book: built upright with that edge on the y axis, turned about y, then moved.
        width, tall, deep = 0.03, 0.6 * clearance, 0.2
        lean = math.radians(20.0)
        book = ba.box("book_leaning", (width, deep, tall), (width / 2, 0.0, tall / 2))
        book.rotation_euler = (0.0, -lean, 0.0)
        book.location = (x + tall * math.sin(lean) + 0.002, y1 - back - 0.005 - deep / 2, base)
        ba.apply_transform(book)
        books.append(book)
    if level == 3:
        z = base
        for k in range(3):
            w, d, t = rng.uniform(0.16, 0.2), rng.uniform(0.18, 0.22), rng.uniform(0.025, 0.045)
            cx = inner_right - 0.12 + rng.uniform(-0.01, 0.01)
            books.append(ba.box_between(f"book_flat_{k}", (cx - w / 2, y1 - back - 0.01 - d, z),
                                        (cx + w / 2, y1 - back - 0.01, z + t)))
            z += t
book_count = len(books)
books = ba.join(books, "books")
ba.canonical_order(books)

ba.shade_smooth(shelf, auto_smooth_deg=30.0)
objects = [floor, wall, shelf, books]
for obj in objects:
    ba.lightmap_uvs_smart(obj, gap=0.01)

total = 0
for obj in objects:
    ba.export_glb(obj, here, obj.name)
    total += ba.triangle_count(obj)
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles")
print(f"books: {book_count}; total: {total} triangles")

ba.write_scene_toml(
    os.path.join(here, "scene.toml"),
    """written by scenes/shelf/make_scene.py (Blender); edit that script, not this file.
A bookshelf (non-convex: sides, top, plinth, three shelves, back panel) holding books, against a
wall on a 3 x 3 m floor; all receivers, glTF binaries exported Y up with lightmap UVs in channel 1
(Smart UV Project); rotate_deg stands them back up in this Z-up scene. Lit by a 0.9 x 0.6 m panel
in front of the shelf and above it, tilted towards it.""",
    [{"name": obj.name, "mesh": obj.name + ".glb"} for obj in objects],
    [dict(name="panel", shape="rectangle", position=(0.35, -0.9, 2.3), normal=(-0.2, 1.0, -0.75),
          up=(0, 0, 1), size=(0.9, 0.6), power=150.0)])
