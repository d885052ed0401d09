#!/usr/bin/env python3
"""How a bake's time and memory grow with a level's lights (docs/performance.md, "Many lights").

Usage: tests/tools/many_lights_table.py SCENE.toml [--shares 0.1,0.25,0.5,1]
           [--methods backprojection,reference] [--samples 64] [--repeat 3] [--build build]

For each share of SCENE.toml's lights (tests/tools/light_subset.py keeps an evenly spaced share,
turning the rest off with `enabled = false`) and each method, bakes the scene with `shadowbake
bake --no-cache -q` (the reference at --samples), --repeat times, the methods interleaved, and
prints a Markdown table: lights kept, the bake's time (the manifest's bake_seconds, in-process,
the median of the runs), the process's peak resident memory (the largest of the runs, from
/usr/bin/time's %M), the most lights that reach one texel (the manifest's most_lights_per_texel)
and, for the default method, the share of (light, texel) pairs each route took.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import light_subset  # noqa: E402  (this folder's)


def bake(cli, scene, out, method, samples):
    timing = out + ".time"
    command = ["/usr/bin/time", "-f", "%M", "-o", timing, cli, "bake", scene, "-o", out,
               "--no-cache", "-q", "--method", method]
    if method == "reference":
        command += ["--samples", str(samples)]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(timing) as f:
        peak_mib = int(f.read().split()[-1]) / 1024
    with open(os.path.join(out, "manifest.json")) as f:
        manifest = json.load(f)
    receivers = manifest["receivers"]
    return {
        "seconds": manifest["bake_seconds"],
        "peak_mib": peak_mib,
        "most": max(r.get("most_lights_per_texel", 0) for r in receivers),
        "stats": receivers[0].get("method_stats", {}),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--shares", default="0.1,0.25,0.5,1")
    parser.add_argument("--methods", default="backprojection,reference")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--build", default="build")
    args = parser.parse_args()
    cli = os.path.abspath(os.path.join(args.build, "shadowbake"))
    methods = args.methods.split(",")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for share in [float(s) for s in args.shares.split(",")]:
            scene = os.path.join(tmp, f"share_{share}.toml")
            kept, total = light_subset.write_subset(args.scene, share, scene)
            runs = {m: [] for m in methods}
            for _ in range(args.repeat):
                for m in methods:
                    runs[m].append(bake(cli, scene, os.path.join(tmp, f"out_{m}"), m,
                                        args.samples))
            rows.append((share, kept, total, runs))
    print(f"{args.scene}: bake time in-process (median of {args.repeat}), peak memory of the "
          "process (largest)\n")
    header = "| lights |"
    rule = "|---|"
    for m in methods:
        label = m if m != "reference" else f"reference-{args.samples}"
        header += f" {label} s | {label} peak MiB |"
        rule += "---|---|"
    header += " most lights at a texel | clear / umbra / exact / interpolated |"
    rule += "---|---|"
    print(header)
    print(rule)
    for share, kept, total, runs in rows:
        line = f"| {kept} of {total} ({100 * share:g} %) |"
        for m in methods:
            line += (f" {statistics.median(r['seconds'] for r in runs[m]):.2f} |"
                     f" {max(r['peak_mib'] for r in runs[m]):.0f} |")
        first = runs[methods[0]][0]
        stats = first["stats"]
        routes = " / ".join(f"{stats.get(k + '_fraction', 0):.2f}"
                            for k in ("clear", "umbra", "exact", "interpolated"))
        line += f" {first['most']} | {routes} |"
        print(line)


if __name__ == "__main__":
    main()
