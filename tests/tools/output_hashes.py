#!/usr/bin/env python3
"""Hashes of what `shadowbake bake` writes, for every scene in scenes/ and every method.

Run it before and after a change that must not change outputs and diff the two lists:

    tests/tools/output_hashes.py --build build > /tmp/before.txt
    ... change, rebuild ...
    tests/tools/output_hashes.py --build build > /tmp/after.txt
    diff /tmp/before.txt /tmp/after.txt && echo identical

Each line is `scene method file sha256`. Image files are hashed as written; the manifest is hashed
in its own key order with its timings (every key naming seconds) left out, since those differ on
every run. Scenes bake at --resolution (default 96) and --samples (default 16) so that the whole
grid takes a few minutes.
"""
import argparse
import hashlib
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

METHODS = ["backprojection", "convolution", "reference", "accumulation", "pcf", "pcss",
           "adaptive-pcf", "erosion",
           "chun-oh"]


def without_timings(value):
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items()
                if "seconds" not in k}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build", help="build folder holding shadowbake")
    parser.add_argument("--resolution", type=int, default=96)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--scenes", nargs="*", help="scene files (default: scenes/*/*.toml)")
    parser.add_argument("--methods", nargs="*", default=METHODS)
    parser.add_argument("--flags", default="",
                        help="more bake flags, e.g. '--per-light --shadowmask'")
    args = parser.parse_args()
    root = pathlib.Path(__file__).resolve().parents[2]
    exe = (pathlib.Path(args.build) / "shadowbake").resolve()
    scenes = args.scenes or sorted(str(p.relative_to(root)) for p in root.glob("scenes/*/*.toml"))
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            for method in args.methods:
                out = pathlib.Path(tmp) / "out"
                shutil.rmtree(out, ignore_errors=True)
                proc = subprocess.run(
                    [str(exe), "bake", scene, "-o", str(out), "--method", method, "-q",
                     "--resolution", str(args.resolution), "--samples", str(args.samples),
                     "--threads", "2", "--no-cache"] + args.flags.split(),
                    cwd=root, capture_output=True, text=True)
                if proc.returncode != 0:
                    last = (proc.stderr.strip().splitlines() or ["?"])[-1]
                    print(f"{scene} {method} exit {proc.returncode}: {last}")
                    failures += 1
                    continue
                for f in sorted(os.listdir(out)):
                    data = (out / f).read_bytes()
                    if f == "manifest.json":
                        data = json.dumps(without_timings(json.loads(data))).encode()
                    print(scene, method, f, hashlib.sha256(data).hexdigest())
                sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
