#!/usr/bin/env python3
"""Times an incremental rebake against a full bake: bakes SCENE into a fresh folder, changes the
scene (one edit), bakes the changed scene into that folder (taking what it can from the first
bake) and into a second fresh folder with --no-cache (the full bake), checks that the two give
the same lightmap bytes, and prints the medians of the in-process bake times (manifest
bake_seconds) and which receivers were reused. Developer tool; figures go to
docs/performance.md.

usage: tests/tools/bench_incremental.py SCENE.toml EDIT [--runs 3] [--method M]
       [--resolution N] [--cli build/shadowbake]
EDIT is one of
  --move OBJECT DX DY DZ       give [[object]] OBJECT a translate (it must have none)
  --recolour LIGHT R G B       give [[light]] LIGHT a color (it must have none)
  --add MESH X Y Z             append a blocker [[object]] "added_crate" of MESH at (X, Y, Z)
"""
import argparse
import json
import re
import statistics
import subprocess
import tempfile
from pathlib import Path


def with_key(text, table, name, key, values):
    """text with `key = [values]` added to the [[table]] named `name`, which must not have it."""
    pattern = re.compile(r'(\[\[' + table + r'\]\]\nname = "' + re.escape(name) +
                         r'"\n(?:[^\[\n][^\n]*\n)*)')
    m = pattern.search(text)
    if not m or key in m.group(1):
        raise SystemExit(f"no [[{table}]] {name} without a {key}")
    return text[:m.end()] + f"{key} = [{', '.join(values)}]\n" + text[m.end():]


def edited(text, args):
    if args.move:
        return with_key(text, "object", args.move[0], "translate", args.move[1:])
    if args.recolour:
        return with_key(text, "light", args.recolour[0], "color", args.recolour[1:])
    mesh, *p = args.add
    return text + (f'\n[[object]]\nname = "added_crate"\nmesh = "{mesh}"\nreceiver = false\n'
                   f"translate = [{', '.join(p)}]\n")


def bake(cli, scene, out, extra):
    subprocess.run([cli, "bake", str(scene), "-o", str(out), "--quiet"] + extra, check=True,
                   stderr=subprocess.DEVNULL)
    return json.loads((Path(out) / "manifest.json").read_text())


def lightmaps(folder):
    return {p.name: p.read_bytes() for p in Path(folder).iterdir()
            if p.is_file() and p.name != "manifest.json"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    edit = ap.add_mutually_exclusive_group(required=True)
    edit.add_argument("--move", nargs=4)
    edit.add_argument("--recolour", nargs=4)
    edit.add_argument("--add", nargs=4)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--method", default=None)
    ap.add_argument("--resolution", type=int, default=None)
    ap.add_argument("--cli", default="build/shadowbake")
    args = ap.parse_args()
    extra = (["--method", args.method] if args.method else []) + \
        (["--resolution", str(args.resolution)] if args.resolution else [])

    scene = Path(args.scene)
    changed = scene.with_name(scene.stem + ".changed.toml")  # beside it: its paths resolve
    changed.write_text(edited(scene.read_text(), args))
    try:
        full, rebake = [], []
        for _ in range(args.runs):
            with tempfile.TemporaryDirectory() as tmp:
                inc, ref = Path(tmp) / "inc", Path(tmp) / "full"
                bake(args.cli, scene, inc, extra)
                m = bake(args.cli, changed, inc, extra)
                rebake.append(m["bake_seconds"])
                f = bake(args.cli, changed, ref, extra + ["--no-cache"])
                full.append(f["bake_seconds"])
                same = lightmaps(inc) == lightmaps(ref)
                reused = [r["name"] for r in m["receivers"] if r["bake"]["reused"]]
                baked = [r["name"] for r in m["receivers"] if not r["bake"]["reused"]]
        print(f"scene {scene}, {args.runs} runs, medians; edit: "
              f"{' '.join(args.move or args.recolour or args.add)}")
        print(f"full bake {statistics.median(full):.2f} s, rebake {statistics.median(rebake):.2f} s "
              f"({statistics.median(full) / max(statistics.median(rebake), 1e-9):.1f}x); "
              f"lightmaps byte-identical: {same}")
        print(f"baked again ({len(baked)}): {', '.join(baked)}")
        print(f"reused ({len(reused)}): {', '.join(reused)}")
    finally:
        changed.unlink()


if __name__ == "__main__":
    main()
