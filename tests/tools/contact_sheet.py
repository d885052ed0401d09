#!/usr/bin/python3
"""Lays the PNG previews of one or more bake folders side by side, with labels, into one PNG
(for the README and docs). Uses OpenImageIO's Python bindings (Debian's python3-openimageio,
so run it with /usr/bin/python3).

usage: tests/tools/contact_sheet.py OUT.png --size 256 --row "label:DIR:name1,name2" [--row ...]
"""
import argparse

import OpenImageIO as oiio


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--row", action="append", required=True,
                    help="LABEL:DIR:name,name,... one row of receivers from one bake folder")
    args = ap.parse_args()
    rows = [r.split(":") for r in args.row]
    cols = max(len(r[2].split(",")) for r in rows)
    s, label_h, gap = args.size, 22, 4
    width = cols * (s + gap) + gap
    height = len(rows) * (s + label_h + gap) + gap
    sheet = oiio.ImageBuf(oiio.ImageSpec(width, height, 3, oiio.UINT8))
    oiio.ImageBufAlgo.fill(sheet, (0.12, 0.12, 0.12))
    for r, (label, folder, names) in enumerate(rows):
        y0 = gap + r * (s + label_h + gap)
        for c, name in enumerate(names.split(",")):
            x0 = gap + c * (s + gap)
            img = oiio.ImageBuf(f"{folder}/{name}.png")
            small = oiio.ImageBufAlgo.resize(img, roi=oiio.ROI(0, s, 0, s, 0, 1, 0, 3))
            oiio.ImageBufAlgo.paste(sheet, x0, y0 + label_h, 0, 0, small)
            oiio.ImageBufAlgo.render_text(sheet, x0 + 2, y0 + 16, f"{label}: {name}", 14,
                                          "", (0.9, 0.9, 0.9))
    if not sheet.write(args.out):
        raise SystemExit(f"{args.out}: {sheet.geterror()}")


if __name__ == "__main__":
    main()
