#!/usr/bin/env python3
"""Times `shadowbake bake` on a scene: median of several runs of the in-process bake time
(scene loaded -> textures in memory, from manifest.json), the write time, the whole-process
time, and shadow rays per second. Developer tool; figures go to docs/performance.md.

usage: tests/tools/bench_bake.py SCENE.toml [--runs 5] [--samples N ...] [--method M]
       [--resolution N] [--cli build/shadowbake] [--versus METHOD:SAMPLES]

With --versus, each run of the bake (the first --samples) is followed by one of METHOD at
SAMPLES, so that both see the machine in the same state, and the ratio of their medians is
printed with each pair's own ratio: how many times faster the first is, side by side.
"""
import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path


def bake_once(args, out, samples, method):
    """One bake into `out`; its in-process bake seconds."""
    cmd = [args.cli, "bake", args.scene, "-o", out, "--quiet", "--no-cache", "--samples", str(samples)]
    if method:
        cmd += ["--method", method]
    if args.resolution:
        cmd += ["--resolution", str(args.resolution)]
    subprocess.run(cmd, check=True)
    return json.loads((Path(out) / "manifest.json").read_text())["bake_seconds"]


def side_by_side(args):
    other, other_samples = args.versus.rsplit(":", 1)
    mine, theirs = [], []
    label = args.method or "the scene's method"
    print(f"scene {args.scene}: {label} at {args.samples[0]} samples, then {other} at "
          f"{other_samples}, {args.runs} pairs")
    with tempfile.TemporaryDirectory() as out:
        for _ in range(args.runs):
            mine.append(bake_once(args, out, args.samples[0], args.method))
            theirs.append(bake_once(args, out, int(other_samples), other))
            print(f"  {mine[-1]:8.3f} s  {theirs[-1]:8.3f} s  {theirs[-1] / mine[-1]:6.2f}x")
    a, b = statistics.median(mine), statistics.median(theirs)
    print(f"medians {a:.3f} s and {b:.3f} s: {b / a:.2f}x")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--samples", type=int, nargs="+", default=[64])
    ap.add_argument("--method", default=None)
    ap.add_argument("--resolution", type=int, default=None)
    ap.add_argument("--cli", default="build/shadowbake")
    ap.add_argument("--versus", default=None, help="METHOD:SAMPLES run after each run, side by side")
    args = ap.parse_args()
    if args.versus:
        side_by_side(args)
        return

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
