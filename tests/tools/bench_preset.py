#!/usr/bin/env python3
"""Times `--preset preview` against `--preset final` on a scene and measures how far the preview
is from the final bake: medians of the in-process bake times (manifest bake_seconds), and per
receiver the RMSE of the preview, resized to the final bake's side (oiiotool --resize, a
bilinear-like triangle filter, as a renderer's texture lookup would stretch it), against the final
bake over the final bake's covered texels (`shadowbake compare`). Developer tool; figures go to
docs/cli.md ("Presets") and docs/performance.md.

usage: tests/tools/bench_preset.py SCENE.toml [--runs 3] [--cli build/shadowbake]
"""
import argparse
import json
import math
import re
import statistics
import subprocess
import tempfile
from pathlib import Path


def bake(cli, scene, out, preset):
    subprocess.run([cli, "bake", scene, "-o", str(out), "--quiet", "--no-cache", "--no-atlas",
                    "--preset", preset], check=True, stderr=subprocess.DEVNULL)
    return json.loads((Path(out) / "manifest.json").read_text())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--cli", default="build/shadowbake")
    args = ap.parse_args()
    times = {"final": [], "preview": []}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for _ in range(args.runs):
            for preset in times:
                m = bake(args.cli, args.scene, tmp / preset, preset)
                times[preset].append(m["bake_seconds"])
        final = json.loads((tmp / "final" / "manifest.json").read_text())
        preview = json.loads((tmp / "preview" / "manifest.json").read_text())
        sides = {r["name"]: r["resolution"] for r in final["receivers"]}
        total, count, rows = 0.0, 0, []
        for r in preview["receivers"]:
            name = r["name"]
            lightmap = r["files"]["lightmap"]["file"]
            w, h = sides[name]
            up = tmp / f"up_{name}.exr"
            subprocess.run(["oiiotool", str(tmp / "preview" / lightmap), "--resize:filter=triangle",
                            f"{w}x{h}", "-o", str(up)], check=True)
            out = subprocess.run([args.cli, "compare", str(up), str(tmp / "final" / lightmap)],
                                 check=True, capture_output=True, text=True).stdout
            line = next(l for l in out.splitlines() if l.startswith("covered"))
            texels, rmse = int(line.split()[1]), float(line.split()[2])
            total += texels * rmse * rmse
            count += texels
            rows.append((name, r["resolution"][0], w, rmse))
    f, p = statistics.median(times["final"]), statistics.median(times["preview"])
    print(f"scene {args.scene}, {args.runs} runs, medians")
    print(f"final {f:.2f} s, preview {p:.2f} s ({p / f:.3f} of the final bake's time); "
          f"preview RMSE against final {math.sqrt(total / max(count, 1)):.4f} over {count} texels")
    for name, ps, fs, rmse in rows:
        print(f"  {name:<16} {ps}² -> {fs}²  RMSE {rmse:.4f}")


if __name__ == "__main__":
    main()
