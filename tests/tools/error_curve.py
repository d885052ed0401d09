#!/usr/bin/python3
"""The convolution's error against the reference as error_texels falls, on the subdivision
scenes (docs/methods.md): bakes each scene with `reference` (SAMPLES samples) once and with
`convolution` at each error_texels, compares them with `shadowbake compare` over covered texels
and over the penumbra, prints a Markdown table, and writes a picture per scene (convolution,
reference, difference) to docs/images/subdivision-<scene>.png. Run with /usr/bin/python3 (it
needs OpenImageIO's bindings) from the repository root after building:

    /usr/bin/python3 tests/tools/error_curve.py [--samples 256] [--targets 16,4,1]
"""
import argparse
import json
import subprocess
import tempfile
import time
from pathlib import Path

import OpenImageIO as oiio

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "shadowbake"


def bake(scene, out, *args):
    start = time.monotonic()
    subprocess.run([str(CLI), "bake", str(scene), "-o", str(out), "--quiet", "--no-cache", *args],
                   check=True, stderr=subprocess.DEVNULL)
    return json.loads((out / "manifest.json").read_text())["bake_seconds"], time.monotonic() - start


def compare(a, b, mask, out):
    subprocess.run([str(CLI), "compare", str(a), str(b), "--mask", str(mask), "-o", str(out)],
                   check=True, stdout=subprocess.DEVNULL)
    return json.loads((out / "compare.json").read_text())


def side_by_side(paths, out):
    bufs = [oiio.ImageBuf(str(p)) for p in paths]
    h = 256
    sheet = oiio.ImageBuf(oiio.ImageSpec(len(bufs) * (h + 4), h + 36, 3, oiio.UINT8))
    oiio.ImageBufAlgo.fill(sheet, (1, 1, 1))
    for i, b in enumerate(bufs):
        w = int(b.spec().width * h / b.spec().height)
        small = oiio.ImageBufAlgo.resize(b, roi=oiio.ROI(0, w, 0, h, 0, 1, 0, 3))
        oiio.ImageBufAlgo.paste(sheet, i * (h + 4), 0, 0, 0, small)
    for i, label in enumerate(["convolution", "reference", "difference"]):
        oiio.ImageBufAlgo.render_text(sheet, i * (h + 4) + 8, h + 26, label, 18, "", (0, 0, 0))
    sheet.write(str(out))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=256)
    ap.add_argument("--targets", default="16,4,1")
    ap.add_argument("--scenes", default="table,posts,bracket")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="sb_curve_"))
    print("| scene | receiver | method | bake s | RMSE | max | penumbra RMSE |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name in args.scenes.split(","):
        scene = ROOT / "scenes" / name / "scene.toml"
        ref = tmp / f"{name}-ref"
        ref64 = tmp / f"{name}-ref64"
        t_ref, _ = bake(scene, ref, "--method", "reference", "--samples", str(args.samples))
        t_64, _ = bake(scene, ref64, "--method", "reference", "--samples", "64")
        receivers = sorted(p.stem for p in ref.glob("*.exr"))
        rows = [("reference-64", ref64, t_64)]
        for target in args.targets.split(","):
            out = tmp / f"{name}-conv-{target}"
            t, _ = bake(scene, out, "--error-texels", target)
            rows.append((f"convolution, error_texels {target}", out, t))
        for label, out, t in rows:
            for r in receivers:
                c = compare(out / f"{r}.exr", ref / f"{r}.exr", ref / f"{r}.coverage.png",
                            tmp / f"cmp-{name}-{r}")
                cov, pen = c["covered"]["overall"], c["penumbra"]["overall"]
                print(f"| {name} | {r} | {label} | {t:.3f} | {cov['rmse']:.4f} | {cov['max']:.3f} "
                      f"| {pen['rmse']:.4f} |")
        r = receivers[0]
        last = rows[-1][1]
        compare(last / f"{r}.exr", ref / f"{r}.exr", ref / f"{r}.coverage.png", tmp / "pic")
        side_by_side([last / f"{r}.png", ref / f"{r}.png", tmp / "pic" / "difference.png"],
                     ROOT / "docs" / "images" / f"subdivision-{name}.png")
    print(f"(reference: {args.samples} samples; bake s: manifest bake_seconds)")


if __name__ == "__main__":
    main()
