#!/usr/bin/env python3
"""Summary of a corpus benchmark run (shadowbake_corpus_bench --json FILE), one row per scene,
as docs/performance.md shows it. Usage: tests/tools/corpus_summary.py out/corpus.json

Per scene: whole-scene in-process seconds of the reference at 64 samples, the convolution method
at 64 (its rays where it cannot vouch for its values) and the same method with the convolution
skipped (shaft test + rays, `--no-convolve`); peak memory of a whole convolution bake; and per
receiver (those the lights reach through blockers, RMSE > 0 for the reference at 64): the time
ratio reference-64 / convolution-64 (their RMSE are equal, the traced texels being the
reference's), how many receivers the convolution is slower on, how many the convolution alone
(no rays) is less accurate than the reference at 16 samples, and the equal-error ratio at RMSE
0.005 where both curves reach it by interpolation."""
import json
import statistics
import sys


def main(path):
    runs = json.load(open(path))
    print("| scene | receivers | reference-64 s | convolution-64 s | shaft-rays-64 s | peak MiB "
          "| ref-64 / conv-64 per receiver (min, median, max) | conv-64 slower | shaft-rays slower "
          "| alone worse than ref-16 | equal-error ratio at 0.005 (interpolated) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for run in runs:
        v = run["variants"]
        ref, conv = v["reference-64"]["receivers"], v["convolution-64"]["receivers"]
        shaft = v.get("shaft-rays-64", {}).get("receivers", {})
        alone, ref16 = v["convolution-alone"]["receivers"], v["reference-16"]["receivers"]
        shadowed = [r for r in ref if ref[r]["rmse"] > 0]
        ratios = [ref[r]["seconds"] / conv[r]["seconds"] for r in shadowed]
        slower = sum(1 for r in shadowed if conv[r]["seconds"] > ref[r]["seconds"])
        shaft_slower = sum(1 for r in shadowed if r in shaft and shaft[r]["seconds"] > ref[r]["seconds"])
        worse = sum(1 for r in shadowed
                    if alone[r]["rmse"] > 1.05 * ref16[r]["rmse"] + 5e-4)
        equal = [e["reference_seconds"] / e["convolution_seconds"]
                 for e in run.get("equal_error", {}).values()
                 if e["reference_seconds"] and e["convolution_seconds"] and not e["extrapolated"]]
        eq = (f"{min(equal):.2f}–{max(equal):.2f} ({len(equal)})" if equal else "-")
        peak = max(v[k]["peak_mib"] for k in v if k.startswith("convolution"))
        shaft_s = v["shaft-rays-64"]["scene_seconds"] if "shaft-rays-64" in v else float("nan")
        print(f"| {run['scene']} | {len(shadowed)} of {len(ref)} | "
              f"{v['reference-64']['scene_seconds']:.2f} | {v['convolution-64']['scene_seconds']:.2f} | "
              f"{shaft_s:.2f} | {peak:.0f} | "
              f"{min(ratios):.2f}, {statistics.median(ratios):.2f}, {max(ratios):.2f} | "
              f"{slower} | {shaft_slower} | {worse} | {eq} |")


if __name__ == "__main__":
    main(sys.argv[1])
