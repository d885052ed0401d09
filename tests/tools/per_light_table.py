#!/usr/bin/python3
"""RMSE per receiver and light between per-light visibility images of several bakes (shadowbake's
`--per-light` folders, or tests/tools/cycles_level_bake.py's output), over the covered texels at
least `--inset` texels inside their chart (Cycles and shadowbake treat a chart's border texels
differently). Uses OpenImageIO's Python bindings: run it with /usr/bin/python3.

    tests/tools/per_light_table.py --coverage BAKE --receivers floor,table --lights bulb,sun \
        "backprojection vs Cycles=BAKE:CYCLES" "reference vs Cycles=REF:CYCLES" ...

Each column compares A/<receiver>.<light>.exr with B/<receiver>.<light>.exr; the coverage is
BAKE/<receiver>.coverage.png. Prints a Markdown table.
"""
import argparse

import numpy as np
import OpenImageIO as oiio


def channel0(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, 0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--coverage", required=True)
    ap.add_argument("--receivers", required=True)
    ap.add_argument("--lights", required=True)
    ap.add_argument("--inset", type=int, default=2)
    ap.add_argument("columns", nargs="+", help="LABEL=A:B")
    args = ap.parse_args()
    columns = [(c.split("=", 1)[0], c.split("=", 1)[1].split(":")) for c in args.columns]
    print("| receiver | light | " + " | ".join(label for label, _ in columns) + " |")
    print("|---|---|" + "---|" * len(columns))
    for receiver in args.receivers.split(","):
        covered = channel0(f"{args.coverage}/{receiver}.coverage.png") > 0.5
        inner = covered.copy()
        for dy in range(-args.inset, args.inset + 1):
            for dx in range(-args.inset, args.inset + 1):
                inner &= np.roll(np.roll(covered, dy, 0), dx, 1)
        for light in args.lights.split(","):
            cells = []
            for _, (a, b) in columns:
                d = channel0(f"{a}/{receiver}.{light}.exr") - channel0(f"{b}/{receiver}.{light}.exr")
                cells.append(f"{np.sqrt((d[inner] ** 2).mean()):.4f}")
            print(f"| {receiver} | {light} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
