#!/usr/bin/env python3
"""Writes the bad-input corpus under tests/bad_inputs/: one folder per case with its scene.toml and
files, and cases.json, which tests/pipeline/bad_inputs_test.cpp reads: per case the command, the exit code
(docs/cli.md) and a phrase the one-line error (or warning) must contain. Cases that need files git
cannot hold (a FIFO, a symbolic-link loop, /dev/zero) are made by the test itself.

Standard library only; the same bytes on every run:

    python3 tests/bad_inputs/make_corpus.py
"""

import base64
import json
import random
import shutil
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent

QUAD_OBJ = """v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
"""

LIGHT = """
[[light]]
name = "panel"
shape = "rectangle"
position = [0.5, 0.5, 1.5]
normal = [0, 0, -1]
size = [0.5, 0.5]
power = 100.0
"""


def scene(objects, bake="", lights=LIGHT):
    text = "[bake]\nresolution = 32\nmethod = \"reference\"\nsamples = 4\n" + bake + "\n"
    for o in objects:
        text += "[[object]]\n" + "".join(f"{k} = {v}\n" for k, v in o.items()) + "\n"
    return text + lights


def obj(name, mesh, **extra):
    d = {"name": json.dumps(name), "mesh": json.dumps(mesh)}
    d.update(extra)
    return d


def gltf(positions, uvs, indices):
    """A .gltf with an embedded buffer: float positions and TEXCOORD_0, uint16 indices."""
    pos = b"".join(struct.pack("<3f", *p) for p in positions)
    uv = b"".join(struct.pack("<2f", *t) for t in uvs)
    idx = b"".join(struct.pack("<H", i) for i in indices)
    idx += b"\0" * (-len(idx) % 4)
    blob = pos + uv + idx
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2}]}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": len(uv)},
            {"buffer": 0, "byteOffset": len(pos) + len(uv), "byteLength": len(indices) * 2},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
             "min": [min(p[i] for p in positions) for i in range(3)],
             "max": [max(p[i] for p in positions) for i in range(3)]},
            {"bufferView": 1, "componentType": 5126, "count": len(uvs), "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        ],
    }
    return json.dumps(doc, indent=1) + "\n"


QUAD_POSITIONS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
QUAD_UVS = [(0, 1), (1, 1), (1, 0), (0, 0)]  # glTF t runs down

# A file the fuzzer made (tests/fuzz): a PLY header named .glb, on which Assimp 5.2.5 crashes (its
# PLY reader, picked by the file's signature, segfaults). Read in the mesh reader's child process,
# it must come back as an error.
ASSIMP_CRASH = base64.b64decode(
    "cGx5CmZvcm1hdCBhc2NpaSAxLjAKZWxlbWVudCB2ZXJ0ZXggMjAwMDAwMDAwMApwcm9wZXJ0eSBmbG9hdCB4CnByciBpbnQg"
    "dmVydGV4X2luW2ljZXMKZToxLCJjb21wb25lbnRUeXBlIjo1MTI2LCJjb3VudCI6MjQsInR5cGUiOiJWRUMyIn0seyJidWZm"
    "ZXJWaWV3IjoyLCJjb21wb25lbnRUeXBlIjo1MTI2LCJjb3VudCI6MjQsInR5cGUiOiJWRUMyIn0seyJidWZmZXJWaWV3Ijoz"
    "LCJjb21wb25lbnRUeXBlIjo1MTI2LCJjb3VudCI6MjQsInR5cGUiOiJWRUMzIn0seyJidWZmZXJWaWV3Ijo0LCJjb21wb25l"
    "ZGFleXBlIjo1MTIzLCJjb3VudCI6MzYsInR5cGUiOiJTQ0FMQVIifV0sImJ1ZmZlclZpZXdzIjpbeyJidWZmZXIiOjAsImJ5"
    "dGVMZW5ndGgiOjI4OCwiYnl0ZU9mZnNldCI6MCwidGFyZ2V0IjozNDk2Mn0seyJidWZmZXIiOjAsImJ5dGVMZW5ndGgiOjE5"
    "MiwiYnl0ZU9mZnNldCI6Mjg4LCJ0YXJnZXQiOjM0OTYyfSx7ImJ1ZmZlciI6MCwiYnl0ZUxlbmd0aCI6MTkyLCJieXRlT2Zm"
    "c2V0Ijo0ODAsInRhcmdldG4gMzIKbWV0aG9kID0gInJlZmVyZW5jZSIKc2FtcGxlcyA9IDxhbWY0CgogIm1lc2gucGp5IgoK"
    "CltbIjozNDk2Mn0seyJidWZmZXIiOjAsImJ5dGVMZW5ndGgiOjI4OCwiYnl0ZU9mZnNldCI6NjcyLCJ0YXJnZXQiOjM0OTYy"
    "fSx7ImJ1ZmZlciI6MCwiYnl0ZUxlbmd0aCI6NzIsImJ5dGVPZmZzZXQiOjk2MCwidGFyZ2V0IjozNDk2M31dLCJidWZmZXJz"
    "IjpbeyJieXRlTGVuZ3RoIjoxMDMyfV19ICAgCAQAAEJJTgAAAADAAAAAADQz878AAADAAAAAADQz878AAADAAAAAADQz878A"
    "AADAAAAgQDQz878AAADAAAAgQDQz878AAADAAgAgQDQz878AAADAAAAAAAAAAMAAAADAAAAAAAAAAMAAAADAAAAAAAAAAMAA"
    "AADAAAAgQAAAAMAAAADAAAAgQAAAAMAAAADAAAAgQAAAbGlnaHRdXQDAAAAAQAAAAAA0M/O/AAAAQAAAAAA0M/O/AAAAQAAA"
    "AAA0M/O/AAAAQAAAIEA0M/O/AAAAQAAAIEA0M/O/AAAAQAAAIEA0M/O/AAAAQAAAAAAAAADAAAAAQAAAAAAAAADAAAAAQAAA"
    "AAAAAADAAAAAQAAAIEAAAADAAAAAQAAAIEAAAADAAAAAQAAAIEAAAADAAAAAPgAAgD4AAMA+AAAAAAAAwD4AAIA/AAAgPwAA"
    "AAAAACA/AACAPwAAYD8AAIA+AAAAPgAAAD8AAMA+AABAPwAAwD4AAEA/AAAgPwAAQD8AACA/AABAPwAAYD8AAAA/AADAPgAA"
    "gD4AAMA+AACAPgAAwD4AAIA+AAAgPwAAgD4AACA/AACAPgAAID8AAIA+AADAPgAAAD8AAMA+AAAAPwAAwD4AAAA/AAAgPwAA"
    "AD8AACA/AAAAPwAAID8AAAA/kyhmP6RwfT/cCWE/pHB9P6BwfT+kcH0/8LfoPqRwfT+gcH0/wMIQPyugbz9AG58+c4FqP6Rw"
    "fT+Aet4+QBufPsAXeT+kcH0/ANcjPEAbnz7AF3k/wMIQPwv5cz9AG58+3AlhP0Abnz6TKGY/QBufPsIXeT8IpAs/8LfoPkAb"
    "nz4roG8/pHB9P8IXeT8osfc9gHrePqRwfT9zgWo/QBufPqJwfT8IpAs/ANcjPKRwfT8L+XM/pHB9P6JwfT8osfc9AAAAAAAA"
    "gL8AAACAAAAAAAAAAAAAAIA/AACAvwAAAAAAAACAAAAAAAAAAAAAAIA/AACAvwAAAAAAAACAAAAAAAAAgD8AAACAAAAAAAAA"
    "gL8AAACAAAAAAAAAAApuYW1lID0gInBhbmVsIgpzAAAAgL8AAIC/AAAAAAAAAIAAAAAAAAAAAAAAgL8AAIC/AAAAAAAAAIAA"
    "AAAAAACAPwAAAIAAAAAAAAAAAAAAgD8AAAAAAACAvwAAAIAAAIA/AAAAAAAAAIAAAAAAAAAAAAAAgD8AAAAAAABoYXBlID0g"
    "InJlY3RhbmdsZSIKcG9zaXRpb24gPSBbMC41LCAwZF9oZWFkZXIKMCAwIDCAPwAAAIAAAIA/AAAAAAAAAIAKAAAAAAAAAAAA"
    "AIC/AAAAAAAAgL8AAACAAACAPwAAAAAAAACAAAAAAAAAAAAAAIC/AAAAAAAAgD8AAACAAACAPwAAAAAAAACAAgAEAAoAAgAK"
    "AAgABwAJABUAbXBsZXMgPSA2NAoKW1tvYmplY3RdXQpuYW1lID0gImZsb29yIgptZXNoID0gImZsb29yLmdsYiIKdXYgPSAx"
    "CnJvdGF0ZV9kZWcgPSBbOTAsIDAsIDBdCgpbW29iamVjdF1dCm5hbWUgPSAiYmFja193YWxsIgptZXNoID0gIm1lc2guZ2xi"
    "Igp1diA9IDEKcm90YXRlX2RlZyA9IFs5MCwgMCwgMF0KCltbb2JqZWN0XV0KbmFtZSA9ICJzaWRlX3dhbGwiCm1lc2ggPSAi"
    "c2lkZV93YWxsLmdsYiIKdXYgPSAxCnJvdGF0ZV9kZWcgPSBbOTAsIDAsIDBdCgpbW29iamVjdF1dCm5hbWUgPSAiY2hhaXIi"
    "Cm1nc2ggPSAiY2hhaXIuZ2xiIgp1diA9IDEKcm90YXRlX2RlZyA9IFs5MCwgMCwgMF0KCltbb2JqZWN0XV0KbmFtZSA9ICJi"
    "YWxsIgptZXNoID0gImJhbGwuZ2xiIgp1diA9IDAKcm90YXRlX2RlZyA9IFs5MCwgMCwgMF0KCltbbGlnaHRdXQpuYW1lID0g"
    "IndpbmRvdyIKc2hhcGUgPSAicmVjdGFuZ2xlIgpwb3NpdGlvbiA9IFswLjIsIDEuNiwgMi4yXQpub3JtYWwgPSBbMCwgLTAu"
    "NiwgLTFdCnVwID0gWzAsIDEsIDBdCnNpemUgPSBbMSwgMC41XQpwb3dlciA9IDE1MAoAZ2xURgIAAAAoCAAABAQAAEpTT057"
    "ImFzc2V0Ijp7ImdlbmVyYXRvciI6Iktocm9ub3MgZ2xURiBCbGVuZGVyIEkvTyB2My40LjUwIiwidmVyc2lvbiI6IjIuMCJ9"
    "LCJzY2VuZSI6MCwic2NlbmVzIjpbeyJuYW1lIjoiU2NlbmUiLCJub2RlcyI6YDBdfV0sIm5vZGVzIjpbeyJtZXNoIjowLCJu"
    "YW1lIjoiYmFja193YWxsIn1dLCJtZXNoZXMiOlt7Im5hbWUiOiJDdWJlIiwicHJpbWl0aXZlcyI6W3siYXR0cmlidXRlcyI6"
    "eyJQT1NJVElPTiI6MCwiVEVYQ09PUkRfMCI6MSwiVEVYQ09PUkRfMSI6MiwiTk9STUFMIjozfSwiaW5kaWNlcyI6NH1dfV0s"
    "ImFjY2Vzc29ycyI6W3siYnVmZmVyVmlldyI6MCwiY29tcG9uZW50VHlwZSI6NTEyNiwiY291bnQiOjI0LCJtYXgiOlsyLDIu"
    "NSwtMS45MDAwMDAwOTUzNjc0MzE2XSwibWluIjpbLTIsMCwtMl0sInR5cGUiOiJWRUMzIn0seyJidWZmZXJWaWV3IgoKW1ts"
    "aWdodF1dCm5hbWUgPSAicGFuZWwiCnNoYXBlID0gInJlY3RhbmdsZSIKcG9zaXRpb24gPSBbMC41LCAwLjUsIDEuNV0Kbgpw"
    "b3dlciA9IDEwMC4wCgBwbHkKZm9ybWF0IGFzY2lpIDEuMAplbGVtZW50IHZlcnRleCAyMDAwMDAwMDAwCnByb3BlcnR5IGZs"
    "b2F0IHgKcHJyIGludCB2ZXJ0ZXhfaW5baWNlcwplOjEsImNvbXBvbmVudFR5cGUiOjUxMjYsImNvdW50IjoyNCwidHlwZSI6"
    "IlZFQzIifSx7ImJ1ZmZlclZpZXciOjIsImNvbXBvbmVudFR5cGUiOjUxMjYsImNvdW50IjoyNCwidHlwZSI6IlZFQzIifSx7"
    "ImJ1ZmZlclZpZXciOjMsImNvbXBvbmVudFR5cGUiOjUxMjYsImNvdW50IjoyNCwidHlwZSI6IlZFQzMifSx7ImJ1ZmZlclZp"
    "ZXciOjQsImNvbXBvbmVkYWV5cGUiOjUxMjMsImNvdW50IjozNiwidHlwZSI6IlNDQUxBUiJ9XSwiYnVmZmVyVmlld3MiOlt7"
    "ImJ1ZmZlciI6MCwiYnl0ZUxlbmd0aCI6Mjg4LCJieXRlT2Zmc2V0IjowLCJ0YXJnZXQiOjM0OTYyfSx7ImJ1ZmZlciI6MCwi"
    "Ynl0ZUxlbmd0aCI6MTkyLCJieXRlT2Zmc2V0IjoyODgsInRhcmdldCI6MzQ5NjJ9LHsiYnVmZmVyIjowLCJieXRlTGVuZ3Ro"
    "IjoxOTIsImJ5dGVPZmZzZXQiOjQ4MCwidGFyZ2V0biAzMgptZXRob2QgPSAicmVmZXJlbmNlIgpzYW1wbGVzID0gPGFtZjQK"
    "CiAibWVzaC5wankiCgoKW1siOjM0OTYyfSx7ImJ1ZmZlciI6MCwiYnl0ZUxlbmd0aCI6Mjg4LCJieXRlT2Zmc2V0Ijo2NzIs"
    "InRhcmdldCI6MzQ5NjJ9LHsiYnVmZmVyIjowLCJieXRlTGVuZ3RoIjo3MiwiYnl0ZU9mZnNldCI6OTYwLCJ0YXJnZXQiOjM0"
    "OTYzfV0sImJ1ZmZlcnMiOlt7ImJ5dGVMZW5ndGgiOjEwMzJ9XX0gICAIBAAAQklOAAAAAMAAAAAANDPzvwAAAMAAAAAANDPz"
    "vwAAAMAAAAAANDPzvwAAAMAAACBANDPzvwAAAMAAACBANDPzvwAAAMACACBANDPzvwAAAMAAAAAAAAAAwAAAAMAAAAAAAAAA"
    "wAAAAMAAAAAAAAAAwAAAAMAAACBAAAAAwAAAAMAAACBAAAAAwAAAAMAAACBAAABsaWdodF1dAMAAAABAAAAAADQz878AAABA"
    "AAAAADQz878AAABAAAAAADQz878AAABAAAAgQDQz878AAABAAAAgQDQz878AAABAAAAgQDQz878AAABAAAAAAAAAAMAAAABA"
    "AAAAAAAAAMAAAABAAAAAAAAAAMAAAABAAAAgQAAAAMAAAABAAAAgQAAAAMAAAABAAAAgQAAAAMAAAAA+AACAPgAAwD4AAAAA"
    "AADAPgAAgD8AACA/AAAAAAAAID8AAIA/AABgPwAAgD4AAAA+AAAAPwAAwD4AAEA/AADAPgAAQD8AACA/AABAPwAAID8AAEA/"
    "AABgPwAAAD8AAMA+AACAPgAAwD4AAIA+AADAPgAAgD4AACA/AACAPgAAID8AAIA+AAAgPwAAgD4AAMA+AAAAPwAAwD4AAAA/"
    "AADAPgAAAD8AACA/AAAAPwAAID8AAAA/AAAgPwAAAD+TKGY/pHB9P9wJYT+kcH0/oHB9P6RwfT/wt+g+pHB9P6BwfT/AwhA/"
    "K6BvP0Abnz5zgWo/pHB9P4B63j5AG58+wBd5P6RwfT8A1yM8QBufPsAXeT/AwhA/C/lzP0Abnz7cCWE/QBufPpMoZj9AG58+"
    "whd5PwikCz/wt+g+QBufPiugbz+kcH0/whd5Pyix9z2Aet4+pHB9P3OBaj9AG58+onB9PwikCz8A1yM8pHB9Pwv5cz+kcH0/"
    "onB9Pyix9z0AAAAAAACAvwAAAIAAAAAAAAAAAAAAgD8AAIC/AAAAAAAAAIAAAAAAAAAAAAAAgD8AAIC/AAAAAAAAAIAAAAAA"
    "AACAPwAAAIAAAAAAAACAvwAAAIAAAAAAAAAACm5hbWUgPSAicGFuZWwiCnMAAACAvwAAgL8AAAAAAAAAgAAAAAAAAAAAAACA"
    "vwAAgL8AAAAAAAAAgAAAAAAAAIA/AAAAgAAAAAAAAAAAAACAPwAAAAAAAIC/AAAAgAAAgD8AAAAAAAAAgAAAAAAAAAAAAACA"
    "PwAAAAAAAGhhcGUgPSAicmVjdGFuZ2xlIgpwb3NpdGlvbiA9IFswLjUsIDBkX2hlYWRlcgowIDAgMIA/AAAAgAAAgD8AAAAA"
    "AAAAgAoAAAAAAAAAAAAAgL8AAAAAAACAvwAAAIAAAIA/AAAAAAAAAIAAAAAAAAAAAAAAgL8AAAAAAACAPwAAAIAAAIA/AAAA"
    "AAAAAIACAAQACgACAAoACAAHAAkAFQAHABUAEgAUABcAEQAUABEADgAMAA8AAwAMAAMAAQAGABMADQAGAA0AAAAWAAsxAAUA"
    "FgAFABAA")

cases = []


def case(name, files, expect_code, expect_text, command="bake", kind="error"):
    """kind: "error" (one line 'shadowbake: error:', no output) or "warning" (exit 0, the
    warning on stderr, the bake published)."""
    folder = HERE / name
    folder.mkdir(parents=True, exist_ok=True)
    for file, content in files.items():
        data = content if isinstance(content, bytes) else content.encode()
        (folder / file).parent.mkdir(parents=True, exist_ok=True)
        (folder / file).write_bytes(data)
    cases.append({"name": name, "command": command, "code": expect_code, "text": expect_text,
                  "kind": kind})


for old in HERE.iterdir():
    if old.is_dir():
        shutil.rmtree(old)

# Not a case: the good bake every case's output folder holds before the case runs.
(HERE / "good").mkdir()
(HERE / "good" / "scene.toml").write_text(scene([obj("floor", "quad.obj")]))
(HERE / "good" / "quad.obj").write_text(QUAD_OBJ)

# The scene file itself.
case("toml_syntax", {"scene.toml": "[bake\nresolution = 32\n"}, 3, "TOML syntax error")
case("unknown_key", {"scene.toml": scene([obj("floor", "quad.obj", recever="true")]),
                     "quad.obj": QUAD_OBJ}, 3, "unknown key 'recever'")
case("no_receiver", {"scene.toml": scene([obj("floor", "quad.obj", receiver="false")]),
                     "quad.obj": QUAD_OBJ}, 3, "nothing to bake")
case("bad_max_memory", {"scene.toml": scene([obj("floor", "quad.obj")], bake='max_memory = "lots"'),
                        "quad.obj": QUAD_OBJ}, 3, "'max_memory' must be a size")
case("memory_budget", {"scene.toml": scene([obj("floor", "quad.obj")], bake='max_memory = "64 MiB"').replace(
    "resolution = 32", "resolution = 4096"), "quad.obj": QUAD_OBJ}, 3, "max_memory")
case("resolution_16384", {"scene.toml": scene([obj("floor", "quad.obj")]).replace(
    "resolution = 32", "resolution = 16384"), "quad.obj": QUAD_OBJ}, 3, "[bake] max_memory: the bake needs")
case("names_collide", {"scene.toml": scene([obj("a", "quad.obj"), obj("a.coverage", "quad.obj")]),
                       "quad.obj": QUAD_OBJ}, 3, "is also a file of object 'a'")

# [output] and the lightmap sizes.
def with_output(output, bake="", lights=LIGHT):
    return scene([obj("floor", "quad.obj")], bake=bake, lights=lights) + "\n[output]\n" + output + "\n"


case("output_unknown_key", {"scene.toml": with_output("shadowmasks = true"), "quad.obj": QUAD_OBJ},
     3, "[output]: unknown key 'shadowmasks'")
case("output_bad_encoding", {"scene.toml": with_output('encoding = "jpeg"'), "quad.obj": QUAD_OBJ},
     3, "'encoding' must be \"linear-exr\", \"half-exr\", \"png\" or \"rgbm-png\", got \"jpeg\"")
case("output_atlas_no_padding", {"scene.toml": with_output("atlas = { size = 1024, padding = 0 }"),
                                 "quad.obj": QUAD_OBJ}, 3, "'padding' must be an integer from 1 to 256")
case("output_mask_rgbm", {"scene.toml": with_output('shadowmask_encoding = "rgbm-png"'),
                          "quad.obj": QUAD_OBJ}, 3, "'shadowmask_encoding' must be")
case("resolution_and_density", {"scene.toml": scene([obj("floor", "quad.obj")], bake="texels_per_metre = 20"),
                                "quad.obj": QUAD_OBJ}, 3, "not both")
case("per_light_bad_name", {"scene.toml": with_output("per_light = true",
                                                      lights=LIGHT.replace('"panel"', '"panel 1"')),
                            "quad.obj": QUAD_OBJ}, 3, "light 'panel 1': [output] per_light names a file")
case("per_light_collides", {"scene.toml": with_output('per_light = true\nencoding = "png"',
                                                      lights=LIGHT.replace('"panel"', '"coverage"')),
                            "quad.obj": QUAD_OBJ}, 3, "its output file 'floor.coverage.png' is also a file of")
case("bad_shadowmask_range", {"scene.toml": scene([obj("floor", "quad.obj")],
                                                  lights=LIGHT + "shadowmask_range = -1\n"),
                              "quad.obj": QUAD_OBJ}, 3, "'shadowmask_range' must be a number > 0")
case("bad_lightmap_scale", {"scene.toml": scene([obj("floor", "quad.obj", lightmap_scale="0")]),
                            "quad.obj": QUAD_OBJ}, 3, "'lightmap_scale' must be a number > 0")

# Meshes.
case("mesh_missing", {"scene.toml": scene([obj("floor", "nowhere.obj")])}, 3, "not found")
case("mesh_is_folder", {"scene.toml": scene([obj("floor", "folder.obj")]),
                        "folder.obj/keep": ""}, 3, "is not a regular file")
rng = random.Random(1)
case("garbage_ply", {"scene.toml": scene([obj("floor", "garbage.ply")]),
                     "garbage.ply": b"ply\nformat binary_little_endian 1.0\nelement vertex 400000000\n"
                                    b"property float x\nproperty float y\nproperty float z\nend_header\n"
                                    + bytes(rng.randrange(256) for _ in range(3800))},
     3, "declares 400000000 'vertex' element(s)")
case("huge_ascii_ply", {"scene.toml": scene([obj("floor", "huge.ply")]),
                        "huge.ply": "ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\n"
                                    "property float y\nproperty float z\nelement face 2000000000\n"
                                    "property list uchar int vertex_indices\nend_header\n0 0 0\n"},
     3, "declares 2000000000 'vertex' element(s)")
case("random_bytes_obj", {"scene.toml": scene([obj("floor", "noise.obj")]),
                          "noise.obj": bytes(rng.randrange(256) for _ in range(4096))}, 3, "noise.obj")
case("assimp_crash", {"scene.toml": scene([obj("floor", "crash.glb")]), "crash.glb": ASSIMP_CRASH},
     3, "cannot read mesh")
case("obj_nan_uv", {"scene.toml": scene([obj("floor", "nan.obj")]),
                    "nan.obj": QUAD_OBJ.replace("vt 1 1", "vt nan 1")}, 3, "'nan' where a finite number must be")
case("obj_inf_vertex", {"scene.toml": scene([obj("floor", "inf.obj")]),
                        "inf.obj": QUAD_OBJ.replace("v 1 1 0", "v 1 inf 0")}, 3, "'inf' where a finite number must be")
# Finite, but beyond any level: Embree's float arithmetic overflows on it (it aborted the process).
case("obj_huge_vertex", {"scene.toml": scene([obj("floor", "huge.obj")]),
                         "huge.obj": QUAD_OBJ.replace("v 1 1 0", "v 1 1e30 0")}, 3,
     "lies beyond 1e+06 m of the origin")
case("transform_huge_scale", {"scene.toml": scene([obj("floor", "quad.obj", scale="[1e25, 1e25, 1e25]")]),
                              "quad.obj": QUAD_OBJ}, 3, "lies beyond 1e+06 m of the origin")
case("obj_uv_index_out_of_range", {"scene.toml": scene([obj("floor", "uvindex.obj")]),
                                   "uvindex.obj": QUAD_OBJ.replace("3/3/1 4/4/1", "3/3/1 4/9/1")},
     3, "face references UV index 9, but the file has 4 'vt' line(s)")
case("obj_vertex_index_out_of_range", {"scene.toml": scene([obj("floor", "vindex.obj")]),
                                       "vindex.obj": QUAD_OBJ.replace("f 1/1/1 2/2/1 3/3/1", "f 1/1/1 2/2/1 7/3/1")},
     3, "face references vertex index 7")
case("gltf_index_out_of_range", {"scene.toml": scene([obj("floor", "quad.gltf")]),
                                 "quad.gltf": gltf(QUAD_POSITIONS, QUAD_UVS, [0, 1, 2, 0, 2, 9])},
     3, "out-of-range indices")
case("gltf_nan_uv", {"scene.toml": scene([obj("floor", "quad.gltf")]),
                     "quad.gltf": gltf(QUAD_POSITIONS, [(0, 1), (1, 1), (float("nan"), 0), (0, 0)],
                                       [0, 1, 2, 0, 2, 3])},
     3, "non-finite UV")
case("degenerate_mesh", {"scene.toml": scene([obj("floor", "flat.obj")]),
                         "flat.obj": "v 0 0 0\nv 1 0 0\nv 2 0 0\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\n"},
     3, "zero area")
case("no_uv_channel_1", {"scene.toml": scene([obj("floor", "quad.obj", uv="1")]), "quad.obj": QUAD_OBJ},
     3, "needs lightmap UVs in channel 1")
case("uvs_all_identical", {"scene.toml": scene([obj("floor", "same.obj")]),
                           "same.obj": QUAD_OBJ.replace("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1",
                                                        "vt 0.5 0.5\nvt 0.5 0.5\nvt 0.5 0.5\nvt 0.5 0.5")},
     3, "cover no texel")
case("uvs_outside_unit_square", {"scene.toml": scene([obj("floor", "out.obj")]),
                                 "out.obj": QUAD_OBJ.replace("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1",
                                                             "vt 2 2\nvt 3 2\nvt 3 3\nvt 2 3")},
     3, "cover no texel")

# Lights.
case("light_power_overflow", {"scene.toml": scene([obj("floor", "quad.obj")], lights=LIGHT.replace(
    "power = 100.0", "power = 1e308")), "quad.obj": QUAD_OBJ}, 3, "exitance")
case("light_zero_size", {"scene.toml": scene([obj("floor", "quad.obj")], lights=LIGHT.replace(
    "size = [0.5, 0.5]", "size = [0.5, 0]")), "quad.obj": QUAD_OBJ}, 3, "'size' must be 2 positive numbers")
case("light_zero_normal", {"scene.toml": scene([obj("floor", "quad.obj")], lights=LIGHT.replace(
    "normal = [0, 0, -1]", "normal = [0, 0, 0]")), "quad.obj": QUAD_OBJ}, 3, "not all zero")
case("light_texture_truncated", {"scene.toml": scene([obj("floor", "quad.obj")], lights=LIGHT + 'texture = "half.png"\n'),
                                 "quad.obj": QUAD_OBJ,
                                 "half.png": b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x10\0\0\0\x10\x08\x02\0\0\0"},
     3, "half.png")

# Warnings: the bake is published, and stderr says what is doubtful.
case("warn_overlapping_uvs", {"scene.toml": scene([obj("floor", "overlap.obj")]),
                              "overlap.obj": QUAD_OBJ + "f 1/1/1 2/2/1 3/3/1\n"},
     0, "claimed by two UV triangles", kind="warning")
case("warn_light_reaches_nothing", {"scene.toml": scene([obj("floor", "quad.obj")], lights=LIGHT.replace(
    "normal = [0, 0, -1]", "normal = [0, 0, 1]")), "quad.obj": QUAD_OBJ},
     0, "reaches no texel of any receiver", kind="warning")
case("warn_uv_area_outside", {"scene.toml": scene([obj("floor", "half_out.obj")]),
                              "half_out.obj": QUAD_OBJ.replace("vt 1 0\nvt 1 1", "vt 2 0\nvt 2 1")},
     0, "lies outside [0, 1]", kind="warning")
case("warn_allow_uncovered", {"scene.toml": scene([obj("floor", "same.obj", allow_uncovered="true")]),
                              "same.obj": QUAD_OBJ.replace("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1",
                                                           "vt 0.5 0.5\nvt 0.5 0.5\nvt 0.5 0.5\nvt 0.5 0.5")},
     0, "its lightmap is black", kind="warning")

(HERE / "cases.json").write_text(json.dumps(cases, indent=1) + "\n")
print(f"{len(cases)} cases in {HERE}")
