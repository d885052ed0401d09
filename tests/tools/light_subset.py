#!/usr/bin/env python3
"""A scene file that bakes a level with a share of its lights: the growth of a bake's time and
memory with the number of lights, on one level (docs/performance.md, "Many lights").

Usage: tests/tools/light_subset.py SCENE.toml SHARE OUT.toml

SCENE.toml imports one glTF level (its first [[import]]); OUT.toml is SCENE.toml with
`[[import.light]] name = "..." enabled = false` for every light of the level but an evenly
spaced SHARE (0 < SHARE <= 1) of them, in the file's order (light k is kept where
floor(k * SHARE) > floor((k - 1) * SHARE), so 0.25 keeps every fourth). The level's path is
made absolute, so OUT.toml may live anywhere. Prints how many lights it keeps.
"""
import json
import math
import os
import re
import struct
import sys


def gltf_json(path):
    with open(path, "rb") as f:
        data = f.read()
    if path.lower().endswith(".gltf"):
        return json.loads(data)
    length = struct.unpack("<I", data[12:16])[0]
    return json.loads(data[20 : 20 + length])


def light_names(level):
    """The names the bake gives the level's punctual lights: their nodes' names, in node order."""
    doc = gltf_json(level)
    return [
        node["name"]
        for node in doc.get("nodes", [])
        if "KHR_lights_punctual" in node.get("extensions", {}) and "name" in node
    ]


def write_subset(scene, share, out):
    """Writes OUT: SCENE with all but an evenly spaced SHARE of its level's lights turned off.
    Returns (lights kept, lights)."""
    if not 0 < share <= 1:
        sys.exit("SHARE must be in (0, 1]")
    text = open(scene).read()
    match = re.search(r'^\s*file\s*=\s*"([^"]+)"', text, re.MULTILINE)
    if not match:
        sys.exit(f"{scene}: no [[import]] file")
    level = os.path.join(os.path.dirname(os.path.abspath(scene)), match.group(1))
    text = text[: match.start(1)] + os.path.abspath(level) + text[match.end(1) :]
    names = light_names(level)
    kept = [k for k in range(len(names)) if math.floor(k * share) > math.floor((k - 1) * share)]
    off = sorted(set(range(len(names))) - set(kept))
    with open(out, "w") as f:
        f.write(text.rstrip("\n") + "\n")
        for k in off:
            f.write(f'\n[[import.light]]\nname = "{names[k]}"\nenabled = false\n')
    return len(kept), len(names)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    scene, share, out = sys.argv[1], float(sys.argv[2]), sys.argv[3]
    kept, total = write_subset(scene, share, out)
    print(f"{out}: {kept} of {total} lights")


if __name__ == "__main__":
    main()
