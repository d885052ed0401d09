#!/usr/bin/env python3
"""Times `shadowbake bake` on a scene: median of several runs of the in-process bake time
(scene loaded -> textures in memory, from manifest.json), the write time, the whole-process
time, and shadow rays per second. Developer tool; figures go to docs/performance.md.

usage: tests/tools/bench_bake.py SCENE.toml [--runs 5] [--samples N ...] [--method M]
       [--resolution N] [--cli build/shadowbake] [--versus METHOD:SAMPLES] [--memory warm|cold]

With --versus, each run of the bake (the first --samples) is followed by one of METHOD at
SAMPLES, so that both see the machine in the same state, and the ratio of their medians is
printed with each pair's own ratio: how many times faster the first is, side by side.

--memory sets the state of the machine's free memory before each bake. On a virtual machine
that hands freed memory back to its host within seconds (this one: tests/tools/fresh_memory.cpp),
a bake's first touch of its arrays costs from nothing to most of a second a gigabyte depending on
how long ago memory was last freed. `warm`: fresh_memory.cpp (compiled with g++) touches and frees 2 GiB right before each
bake (memory freed a moment ago, as on a machine whose memory stays backed); `cold`: it waits
6 s before each bake. Without it, each bake starts after the previous process wrote its files.
"""
import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path


FRESH_MEMORY = None  # the compiled tests/tools/fresh_memory.cpp, for --memory warm


def set_memory(state):
    """Before a bake: free memory warm (2 GiB touched on two threads on 2 MiB pages, as the
    executable advises its own, and freed) or cold (a 6 s pause)."""
    global FRESH_MEMORY
    if state == "warm":
        if FRESH_MEMORY is None:
            FRESH_MEMORY = Path(tempfile.mkdtemp()) / "fresh_memory"
            source = Path(__file__).with_name("fresh_memory.cpp")
            subprocess.run(["g++", "-O2", "-pthread", str(source), "-o", str(FRESH_MEMORY)],
                           check=True)
        subprocess.run([str(FRESH_MEMORY), "2", "2", "0"], check=True, stdout=subprocess.DEVNULL)
    elif state == "cold":
        time.sleep(6)


def bake_once(args, out, samples, method):
    """One bake into `out`; its in-process bake seconds."""
    set_memory(args.memory)
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
    ap.add_argument("--memory", choices=["warm", "cold"], default=None,
                    help="free memory's state before each bake (see above)")
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
                set_memory(args.memory)
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
