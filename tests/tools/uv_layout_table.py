#!/usr/bin/env python3
"""UV layouts of one scene's receivers side by side, from the manifests of bakes that differ only
in their lightmap UVs (docs/methods.md, "Generated lightmap UVs").

    tests/tools/uv_layout_table.py LABEL=BAKE_DIR LABEL=BAKE_DIR ...

Prints a Markdown table, a row per receiver and per layout: charts, stretch, texel density
spread, wasted share of the lightmap (texels no triangle covers), texels within the margin of
another chart, and texels two charts claim; then each layout's totals (counts summed, the rest
as means over receivers).
"""

import json
import sys


def rows(folder):
    with open(folder + "/manifest.json") as f:
        manifest = json.load(f)
    for r in manifest["receivers"]:
        layout = r["uv_layout"]
        side = r["resolution"][0] * r["resolution"][1]
        yield r["name"], {
            "charts": layout["charts"],
            "stretch": layout.get("stretch", 0.0),
            "density_spread": layout.get("density_spread", 0.0),
            "wasted": 1.0 - r["covered_texels"] / side,
            "near": layout["texels_near_other_charts"],
            "overlapping": layout["overlapping_texels"],
        }


def main():
    layouts = [arg.split("=", 1) for arg in sys.argv[1:]]
    tables = [(label, dict(rows(folder))) for label, folder in layouts]
    names = list(tables[0][1])
    print("| receiver | layout | charts | stretch | density spread | wasted | near other chart | overlapping |")
    print("|---|---|---|---|---|---|---|---|")
    for name in names:
        for label, table in tables:
            r = table.get(name)
            if r is None:
                continue
            print(f"| {name} | {label} | {r['charts']} | {r['stretch']:.3f} | "
                  f"{r['density_spread']:.3f} | {r['wasted']:.2f} | {r['near']} | {r['overlapping']} |")
    for label, table in tables:
        mean = lambda key: sum(r[key] for r in table.values()) / len(table)
        print(f"| **all** | {label} | {sum(r['charts'] for r in table.values())} | "
              f"{mean('stretch'):.3f} | {mean('density_spread'):.3f} | {mean('wasted'):.2f} | "
              f"{sum(r['near'] for r in table.values())} | "
              f"{sum(r['overlapping'] for r in table.values())} |")


main()
