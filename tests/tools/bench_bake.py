#!/usr/bin/env python3
"""Times `shadowbake bake` on a scene: median of several runs of the in-process bake time
(scene loaded -> textures in memory, from manifest.json), the write time, the whole-process
time, and shadow rays per second. Developer tool; figures go to docs/performance.md.

usage: tests/tools/bench_bake.py SCENE.toml [--runs 5] [--samples N ...] [--method M]
       [--resolution N] [--cli build/shadowbake]
"""
import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--samples", type=int, nargs="+", default=[64])
    ap.add_argument("--method", default=None)
    ap.add_argument("--resolution", type=int, default=None)
    ap.add_argument("--cli", default="build/shadowbake")
    args = ap.parse_args()

    print(f"scene {args.scene}, {args.runs} runs each, medians")
    print(f"{'samples':>8} {'bake s':>9} {'load s':>8} {'process s':>10} {'Mrays/s':>9}  receivers")
    for samples in args.samples:
        bake, load, process, rate = [], [], [], []
        with tempfile.TemporaryDirectory() as out:
            for _ in range(args.runs):
                # --no-cache: every run bakes (an incremental rebake would reuse the last run).
                cmd = [args.cli, "bake", args.scene, "-o", out, "--quiet", "--no-cache",
                       "--samples", str(samples)]
                if args.method:
                    cmd += ["--method", args.method]
                if args.resolution:
                    cmd += ["--resolution", str(args.resolution)]
                start = time.perf_counter()
                subprocess.run(cmd, check=True)
                process.append(time.perf_counter() - start)
                m = json.loads((Path(out) / "manifest.json").read_text())
                bake.append(m["bake_seconds"])
                load.append(m["load_seconds"])
                rate.append(m["shadow_rays"] / m["bake_seconds"] / 1e6 if m["bake_seconds"] > 0 else 0)
            names = ",".join(r["name"] for r in m["receivers"])
        print(f"{samples:>8} {statistics.median(bake):>9.3f} {statistics.median(load):>8.3f} "
              f"{statistics.median(process):>10.3f} {statistics.median(rate):>9.2f}  {names}")


if __name__ == "__main__":
    main()
