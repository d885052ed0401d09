#!/usr/bin/python3
"""Lays the PNG previews of one or more bake folders side by side into one PNG, one row per
folder (for the README and docs). Uses OpenImageIO's Python bindings (Debian's
python3-openimageio, so run it with /usr/bin/python3).

usage: tests/tools/contact_sheet.py OUT.png [--size 256] --row DIR:name1,name2 [--row ...]
"""
import argparse

import OpenImageIO as oiio


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--row", action="append", required=True,
                    help="DIR:name,name,... one row of receivers from one bake folder")
    args = ap.parse_args()
    rows = [r.split(":") for r in args.row]
    cols = max(len(names.split(",")) for _, names in rows)
    s, gap = args.size, 4
    sheet = oiio.ImageBuf(oiio.ImageSpec(cols * (s + gap) + gap, len(rows) * (s + gap) + gap, 3,
                                         oiio.UINT8))
    oiio.ImageBufAlgo.fill(sheet, (0.12, 0.12, 0.12))
    for r, (folder, names) in enumerate(rows):
        for c, name in enumerate(names.split(",")):
            img = oiio.ImageBuf(f"{folder}/{name}.png")
            small = oiio.ImageBufAlgo.resize(img, roi=oiio.ROI(0, s, 0, s, 0, 1, 0, 3))
            oiio.ImageBufAlgo.paste(sheet, gap + c * (s + gap), gap + r * (s + gap), 0, 0, small)
    if not sheet.write(args.out):
        raise SystemExit(f"{args.out}: {sheet.geterror()}")


if __name__ == "__main__":
    main()
