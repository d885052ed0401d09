#!/usr/bin/python3
"""Checks docs/manifest.schema.json against real bakes: every manifest the bakes below write is
valid, every file it names exists, and manifests broken on purpose are refused (so the schema can
fail). Run by CTest (ManifestSchema.RealBakesValidate) with Debian's python3 and python3-jsonschema:

    /usr/bin/python3 tests/formats/manifest_schema_test.py build/shadowbake
"""

import copy
import json
import pathlib
import subprocess
import sys
import tempfile

import jsonschema

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCHEMA = json.loads((ROOT / "docs" / "manifest.schema.json").read_text())
jsonschema.Draft202012Validator.check_schema(SCHEMA)
VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)

# Bakes covering every shape the manifest takes: the default files, the convolution's own
# entries, per-light images and masks with a light left out, atlases with glTF and RGBM,
# irradiance, and a level's mesh lights.
BAKES = {
    "default": ["scenes/showcase/scene.toml", "--resolution", "32", "--samples", "4"],
    "convolution": ["scenes/showcase/scene.toml", "--resolution", "32", "--samples", "4",
                    "--method", "convolution"],
    "six_lights": ["scenes/hall/scene_six_lights.toml", "--resolution", "32", "--samples", "2"],
    "atlas": ["scenes/room/scene.toml", "--texels-per-metre", "20", "--atlas", "512", "--gltf",
              "--shadowmask", "--per-light", "--encoding", "rgbm-png", "--quantity", "irradiance",
              "--samples", "2"],
    "half": ["scenes/showcase/scene.toml", "--resolution", "32", "--samples", "4",
             "--encoding", "half-exr", "--quantity", "irradiance", "--per-light"],
    "mesh_lights": ["scenes/level/lamp.glb", "--resolution", "16", "--per-light", "--shadowmask"],
}


def errors_of(manifest):
    return sorted(VALIDATOR.iter_errors(manifest), key=lambda e: list(e.path))


def named_files(manifest):
    def of(files):
        yield files["lightmap"]["file"]
        yield files["coverage"]["file"]
        if "preview" in files:
            yield files["preview"]["file"]
        if "shadowmask" in files:
            yield files["shadowmask"]["file"]
        for entry in files.get("per_light", {}).values():
            yield entry["file"]

    for atlas in manifest.get("atlases", []):
        yield from of(atlas["files"])
    for receiver in manifest["receivers"]:
        if "files" in receiver:
            yield from of(receiver["files"])
    if "gltf" in manifest:
        yield manifest["gltf"]


def main():
    if len(sys.argv) != 2:
        sys.exit(f"usage: {sys.argv[0]} SHADOWBAKE")
    binary = sys.argv[1]
    failures = []
    manifests = {}
    with tempfile.TemporaryDirectory() as scratch:
        for name, args in BAKES.items():
            out = pathlib.Path(scratch) / name
            run = subprocess.run([binary, "bake", *args, "-o", str(out), "-q"], cwd=ROOT,
                                 capture_output=True, text=True)
            if run.returncode != 0:
                failures.append(f"{name}: bake failed ({run.returncode}): {run.stderr.strip()}")
                continue
            manifest = json.loads((out / "manifest.json").read_text())
            manifests[name] = manifest
            for error in errors_of(manifest):
                failures.append(f"{name}: {'/'.join(map(str, error.path))}: {error.message}")
            for file in named_files(manifest):
                if not (out / file).is_file():
                    failures.append(f"{name}: manifest names {file}, which is not in the folder")
            print(f"{name}: valid, {sum(1 for _ in named_files(manifest))} files named")

    # The bakes did write what they should, so that the schema saw each shape.
    if "six_lights" in manifests:
        channels = [l.get("shadowmask_channel") for l in manifests["six_lights"]["lights"]]
        if channels != ["R", "G", "B", "A", None, None]:
            failures.append(f"six_lights: shadowmask channels {channels}")
    if "atlas" in manifests and not manifests["atlas"].get("atlases"):
        failures.append("atlas: no atlases in the manifest")

    # Broken on purpose: each must be refused.
    if "atlas" in manifests and "default" in manifests:
        broken = {}
        m = copy.deepcopy(manifests["default"])
        del m["receivers"][0]["files"]["coverage"]
        broken["no coverage file"] = m
        m = copy.deepcopy(manifests["default"])
        m["receivers"][0]["files"]["lightmap"]["encoding"] = "jpeg"
        broken["unknown encoding"] = m
        m = copy.deepcopy(manifests["atlas"])
        m["receivers"][0]["files"] = manifests["default"]["receivers"][0]["files"]
        broken["files and an atlas place at once"] = m
        m = copy.deepcopy(manifests["atlas"])
        m["lights"][0]["shadowmask_channel"] = "X"
        broken["a fifth channel"] = m
        m = copy.deepcopy(manifests["atlas"])
        m["receivers"][0]["atlas"]["scale_offset"] = [1, 2, 3]
        broken["a short scale_offset"] = m
        m = copy.deepcopy(manifests["default"])
        m["output"]["atlas"] = {"size": 2048}
        broken["an atlas without padding"] = m
        for what, manifest in broken.items():
            if not errors_of(manifest):
                failures.append(f"the schema accepts a manifest with {what}")
            else:
                print(f"refused, as it should be: {what}")

    if failures:
        for f in failures:
            print("FAIL:", f, file=sys.stderr)
        sys.exit(1)
    print(f"manifest schema: {len(manifests)} bakes valid, broken manifests refused")


if __name__ == "__main__":
    main()
