#!/usr/bin/env python3
"""Measures sharded bakes on this machine (docs/distributed.md):

1. speed-up: one `shadowbake bake` on all cores against N shard processes (one thread each, as
   many at a time as there are cores, as Slurm runs an array on one node) plus their merge, wall
   time from the first start to the merged files;
2. balance: each shard of an N-way split baked alone on all cores (as on N farm machines), by
   cost (the default: receivers dearer than a shard's share split into tiles of rows), by cost
   with receivers kept whole (--shard-tiles off), and by count (round robin); the split's
   makespan is its slowest shard.

Medians of --repeat runs. Standard library only:

    python3 tests/tools/shard_bench.py --build build [--scene scenes/hall/scene_level.toml]
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def single(binary, scene, extra, out):
    start = time.perf_counter()
    run([binary, "bake", scene, "-o", out, "-q", "--no-cache", *extra])
    return time.perf_counter() - start


def sharded(binary, scene, extra, out, n, workers):
    start = time.perf_counter()
    folders = [f"{out}.shard_{k}" for k in range(n)]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        list(pool.map(lambda k: run([binary, "bake", scene, "--shard", f"{k}/{n}", "--threads",
                                     "1", "-o", folders[k], "-q", *extra]), range(n)))
    run([binary, "merge", *folders, "-o", out, "-q"])
    return time.perf_counter() - start


SPLITS = {  # name: the bake options that make it
    "cost": ["--shard-balance", "cost"],
    "whole": ["--shard-balance", "cost", "--shard-tiles", "off"],
    "count": ["--shard-balance", "count", "--shard-tiles", "off"],
}


def shard_times(binary, scene, extra, out, n, split):
    """Each shard alone on all cores: wall seconds per shard."""
    times = []
    for k in range(n):
        start = time.perf_counter()
        run([binary, "bake", scene, "--shard", f"{k}/{n}", *SPLITS[split], "-o",
             f"{out}.{split}_{n}_{k}", "-q", *extra])
        times.append(time.perf_counter() - start)
    return times


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--scene", default="scenes/hall/scene_level.toml")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--bake-args", default="", help="extra bake options, one string")
    args = parser.parse_args()
    binary = os.path.join(args.build, "shadowbake")
    extra = args.bake_args.split()
    cores = os.cpu_count() or 1
    scratch = tempfile.mkdtemp(prefix="shard_bench_")
    try:
        print(f"scene {args.scene} {' '.join(extra)}; {cores} cores; medians of {args.repeat}")
        base = statistics.median(single(binary, args.scene, extra, f"{scratch}/single_{i}")
                                 for i in range(args.repeat))
        print(f"\n| processes | wall (s) | speed-up |\n|---|---|---|\n| 1 bake, {cores} threads | "
              f"{base:.2f} | 1.00 |")
        for n in (2, 4, 8):
            t = statistics.median(sharded(binary, args.scene, extra, f"{scratch}/sh{n}_{i}", n, cores)
                                  for i in range(args.repeat))
            print(f"| {n} shards (1 thread each, {cores} at a time) + merge | {t:.2f} | {base / t:.2f} |")
        print("\n| N | makespan by cost, tiles (s) | by cost, whole receivers (s) | by count (s) "
              "| shard times: by cost, tiles | whole | by count |")
        print("|---|---|---|---|---|---|---|")
        for n in (2, 4, 8):
            rows = {}
            for split in SPLITS:
                runs = [shard_times(binary, args.scene, extra, f"{scratch}/b{i}", n, split)
                        for i in range(args.repeat)]
                rows[split] = [statistics.median(r[k] for r in runs) for k in range(n)]
            fmt = lambda xs: " ".join(f"{x:.2f}" for x in xs)
            print(f"| {n} | {max(rows['cost']):.2f} | {max(rows['whole']):.2f} | "
                  f"{max(rows['count']):.2f} | {fmt(rows['cost'])} | {fmt(rows['whole'])} | "
                  f"{fmt(rows['count'])} |")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
