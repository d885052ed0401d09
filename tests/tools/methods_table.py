#!/usr/bin/python3
"""The methods table of docs/methods.md: runs `shadowbake report` with every method on the
parallel, table and posts scenes and prints, per scene and method, the median bake time and the
error against the reference (RMSE and max over covered texels, RMSE inside the penumbra) as
Markdown. Each report folder (index.html with the pictures side by side) stays under OUT.

    /usr/bin/python3 tests/tools/methods_table.py [--resolution 256] [--out /tmp/sb_methods]
"""
import argparse
import json
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "shadowbake"
METHODS = "convolution,accumulation,pcf,pcss,adaptive-pcf,erosion,chun-oh"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--resolution", type=int, default=256)
    ap.add_argument("--reference-samples", type=int, default=256)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", type=Path, default=Path("/tmp/sb_methods"))
    ap.add_argument("--scenes", default="parallel,table,posts")
    args = ap.parse_args()
    print(f"Resolution {args.resolution}², reference {args.reference_samples} samples, median of "
          f"{args.repeat} bakes; produced by `/usr/bin/python3 tests/tools/methods_table.py`.\n")
    print("| scene | method | bake s | RMSE | max | penumbra RMSE |")
    print("| --- | --- | --- | --- | --- | --- |")
    for scene in args.scenes.split(","):
        out = args.out / scene
        subprocess.run([str(CLI), "report", str(ROOT / "scenes" / scene / "scene.toml"),
                        "--methods", METHODS, "-o", str(out), "--quiet",
                        "--resolution", str(args.resolution),
                        "--reference-samples", str(args.reference_samples),
                        "--repeat", str(args.repeat)], check=False)
        report = json.loads((out / "report.json").read_text())
        for m in report["methods"]:
            if m.get("error"):
                print(f"| {scene} | {m['method']} | failed: {m['error']} | | | |")
                continue
            cov, pen = m["overall"]["covered"], m["overall"]["penumbra"]
            print(f"| {scene} | {m['method']} | {m['median_seconds']:.3f} | {cov['rmse']:.4f} | "
                  f"{cov['max']:.3f} | {pen['rmse']:.4f} |")


if __name__ == "__main__":
    main()
