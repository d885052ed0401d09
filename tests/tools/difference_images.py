#!/usr/bin/python3
"""Side-by-side images of two bakes of one scene, with their difference in numbers.

Usage: tests/tools/difference_images.py OURS_DIR TRUTH_DIR OUT.png [--gain 10] [--size 256]

For every receiver both folders hold (RECEIVER.exr, visibility or irradiance; OURS_DIR's
RECEIVER.coverage.png marks covered texels), one row of OUT.png: ours, the truth, and the
difference (ours − truth) × gain around mid-grey (red where ours is brighter, blue where darker),
each scaled to --size pixels high (nearest texel, so that seams and banding stay visible). Prints
per receiver the RMSE, the largest difference and the share of covered texels off by more than
1/255 and 0.02, over covered texels of the first channel. Uses Debian's python3-openimageio.
"""
import argparse
import json
import os
import sys

import numpy as np
import OpenImageIO as oiio


def read(path):
    buf = oiio.ImageBuf(path)
    if buf.has_error:
        sys.exit(f"{path}: {buf.geterror()}")
    return buf.get_pixels(oiio.FLOAT)


def scaled(image, size):
    h, w = image.shape[:2]
    rows = (np.arange(size) * h // size).clip(0, h - 1)
    cols = (np.arange(size * w // h) * w // (size * w // h)).clip(0, w - 1)
    return image[rows][:, cols]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("ours")
    parser.add_argument("truth")
    parser.add_argument("out")
    parser.add_argument("--gain", type=float, default=10.0)
    parser.add_argument("--size", type=int, default=256)
    args = parser.parse_args()
    names = [r["name"] for r in json.load(open(os.path.join(args.ours, "manifest.json")))["receivers"]]
    rows, stats = [], {}
    for name in names:
        truth_path = os.path.join(args.truth, name + ".exr")
        if not os.path.exists(truth_path):
            continue
        a = read(os.path.join(args.ours, name + ".exr"))[..., 0]
        b = read(truth_path)[..., 0]
        covered = read(os.path.join(args.ours, name + ".coverage.png"))[..., 0] > 0.5
        d = np.where(covered, a - b, 0.0)
        n = max(int(covered.sum()), 1)
        stats[name] = {
            "rmse": float(np.sqrt((d * d).sum() / n)),
            "max": float(np.abs(d).max()),
            "over_1_255": float((np.abs(d) > 1 / 255).sum() / n),
            "over_0.02": float((np.abs(d) > 0.02).sum() / n),
        }
        print(f"{name:14s} RMSE {stats[name]['rmse']:.5f}  max {stats[name]['max']:.4f}  "
              f"> 1/255: {100 * stats[name]['over_1_255']:.2f} %  "
              f"> 0.02: {100 * stats[name]['over_0.02']:.3f} %")
        scale = max(float(b[covered].max()) if covered.any() else 1.0, 1e-6)
        grey = lambda v: np.repeat((np.clip(v / scale, 0, 1) ** (1 / 2.2))[..., None], 3, -1)
        diff = np.clip(d * args.gain / scale, -0.5, 0.5)
        colour = np.stack([0.5 + diff, 0.5 - np.abs(diff), 0.5 - diff], -1)
        colour[~covered] = 0
        gap = np.ones((args.size, 4, 3))
        rows.append(np.concatenate([scaled(grey(a), args.size), gap, scaled(grey(b), args.size),
                                    gap, scaled(colour, args.size)], 1))
    if not rows:
        sys.exit("no receiver in both folders")
    width = max(r.shape[1] for r in rows)
    rows = [np.pad(r, ((0, 4), (0, width - r.shape[1]), (0, 0)), constant_values=1) for r in rows]
    image = np.concatenate(rows, 0).astype(np.float32)
    out = oiio.ImageBuf(oiio.ImageSpec(image.shape[1], image.shape[0], 3, oiio.FLOAT))
    out.set_pixels(oiio.ROI(), image)
    if not out.write(args.out, oiio.UINT8):
        sys.exit(f"{args.out}: {out.geterror()}")


if __name__ == "__main__":
    main()
