#!/usr/bin/env python3
"""Summary of a corpus benchmark run (shadowbake_corpus_bench --json FILE), one row per scene,
as docs/performance.md shows it. Usage: tests/tools/corpus_summary.py out/corpus.json

Per scene: the in-process bake seconds (scene loaded → textures in memory) of the default
(backprojection) and of the reference at 64 samples, both medians of the run's repeats; the
scene's RMSE (every receiver's covered texels pooled) of the default and of the reference at 256
samples; the peak memory of a whole default bake and of the reference at 64's; the wrong texels
(off the truth by more than 0.25 where the reference at 64 is within 0.1 of it); and per receiver that a light reaches through blockers (reference-64 RMSE > 0):
the time ratio reference-64 / backprojection (min, median, max), how many receivers the default
is slower than reference-64 on, how many it is less accurate than reference-256 on (RMSE against
the truth), and the equal-error ratios (reference seconds at the error, interpolated on its
samples curve, over the default's seconds) at the run's target RMSE and at the default's
own RMSE, where the curve reaches them (where the default is more accurate than the reference at
most samples run, the ratio at its own RMSE is a lower bound: that reference's time over the
default's)."""
import json
import statistics
import sys


def spread(values):
    if not values:
        return "-"
    return (f"{min(values):.1f}, {statistics.median(values):.1f}, {max(values):.1f} "
            f"({len(values)})")


def main(path):
    runs = json.load(open(path))
    target = runs[0]["target"] if runs else 0.005
    print("| scene | shadowed receivers | bake s: ours, ref-64 (ratio) "
          "| RMSE: ours, ref-256 | peak MiB: ours, ref-64 | wrong texels "
          "| ref-64 / ours per receiver (min, median, max) | slower than ref-64 "
          "| less accurate than ref-256 "
          f"| equal-error ratio at {target} (min, median, max (n)) "
          "| equal-error ratio at own RMSE |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for run in runs:
        recv = run["receivers"]
        shadowed = [r for r in recv if recv[r]["reference-64"]["rmse"] > 0]
        ours = {r: recv[r]["backprojection"] for r in shadowed}
        ratios = [recv[r]["reference-64"]["seconds"] / ours[r]["seconds"] for r in shadowed]
        slower = sum(1 for r in shadowed
                     if ours[r]["seconds"] > recv[r]["reference-64"]["seconds"])
        worse = sum(1 for r in shadowed
                    if ours[r]["rmse"] > recv[r]["reference-256"]["rmse"])
        at_target = [recv[r]["reference_seconds_at_target"] / ours[r]["seconds"]
                     for r in shadowed if recv[r]["reference_seconds_at_target"] is not None]
        # Where the default is more accurate than the most samples run, a lower bound.
        at_own, bounds = [], 0
        for r in shadowed:
            exact = recv[r]["reference_seconds_at_our_rmse"]
            least = recv[r].get("reference_seconds_at_our_rmse_at_least")
            if exact is not None:
                at_own.append(exact / ours[r]["seconds"])
            elif least is not None:
                at_own.append(least / ours[r]["seconds"])
                bounds += 1
        totals = run["scene_totals"]
        ratio_text = (f"{min(ratios):.1f}, {statistics.median(ratios):.1f}, {max(ratios):.1f}"
                      if ratios else "-")
        ours_t, ref_t = (totals[k]["bake_seconds"] for k in ("backprojection", "reference-64"))
        peaks = " / ".join("-" if totals[k]["peak_mib"] is None else f"{totals[k]['peak_mib']:.0f}"
                           for k in ("backprojection", "reference-64"))
        print(f"| {run['scene']} | {len(shadowed)} of {len(recv)} | "
              f"{ours_t:.2f}, {ref_t:.2f} ({ref_t / ours_t:.2f}×) | "
              f"{totals['backprojection']['rmse']:.4f}, {totals['reference-256']['rmse']:.4f} | "
              f"{peaks} | {totals.get('wrong_texels', '-')} | "
              f"{ratio_text} | {slower} | {worse} | "
              f"{spread(at_target)} | {spread(at_own)}"
              f"{f'; {bounds} of them lower bounds' if bounds else ''} |")


if __name__ == "__main__":
    main(sys.argv[1])
