"""Reads the triangles of the nodes of a glTF binary (shadowbake's `scene.glb`): positions and
one UV set, as the glTF 2.0 specification lays them out (chunks, accessors, buffer views; sparse
accessors and quantised attributes, which shadowbake does not write, are refused)."""

import json
import struct

import mathutils

_GLB_MAGIC = 0x46546C67  # "glTF"
_CHUNK_JSON = 0x4E4F534A
_CHUNK_BIN = 0x004E4942
_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
_FORMATS = {5121: "B", 5123: "H", 5125: "I", 5126: "f"}


class GlbError(Exception):
    pass


def _read_chunks(path):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 20:
        raise GlbError(f"{path}: not a glTF binary (too short)")
    magic, version, length = struct.unpack_from("<III", data, 0)
    if magic != _GLB_MAGIC or version != 2 or length > len(data):
        raise GlbError(f"{path}: not a glTF 2.0 binary")
    document, binary, offset = None, b"", 12
    while offset + 8 <= length:
        chunk_length, chunk_type = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8:offset + 8 + chunk_length]
        if chunk_type == _CHUNK_JSON:
            document = json.loads(chunk)
        elif chunk_type == _CHUNK_BIN:
            binary = chunk
        offset += 8 + chunk_length
    if document is None:
        raise GlbError(f"{path}: no JSON chunk")
    return document, binary


def _accessor(document, binary, index):
    accessor = document["accessors"][index]
    if "sparse" in accessor or accessor.get("normalized", False):
        raise GlbError(f"accessor {index}: sparse or normalised accessors are not read")
    view = document["bufferViews"][accessor["bufferView"]]
    if view.get("buffer", 0) != 0:
        raise GlbError(f"accessor {index}: only the binary chunk's buffer is read")
    components = _COMPONENTS[accessor["type"]]
    fmt = _FORMATS[accessor["componentType"]]
    item = struct.calcsize("<" + fmt)
    stride = view.get("byteStride", item * components)
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    count = accessor["count"]
    if start + stride * (count - 1) + item * components > len(binary):
        raise GlbError(f"accessor {index}: runs past the binary chunk")
    unpack = struct.Struct("<" + fmt * components).unpack_from
    return [unpack(binary, start + k * stride) for k in range(count)]


def _node_matrix(node):
    if "matrix" in node:
        m = node["matrix"]  # column-major
        return mathutils.Matrix([[m[c * 4 + r] for c in range(4)] for r in range(4)])
    t = mathutils.Matrix.Translation(node.get("translation", (0, 0, 0)))
    x, y, z, w = node.get("rotation", (0, 0, 0, 1))
    r = mathutils.Quaternion((w, x, y, z)).to_matrix().to_4x4()
    sx, sy, sz = node.get("scale", (1, 1, 1))
    s = mathutils.Matrix.Diagonal((sx, sy, sz, 1))
    return t @ r @ s


def node_triangles(path, uv_set):
    """{node name: [(three positions, three UVs)]} for every node with a mesh: positions in the
    file's world (the node hierarchy applied), UVs of TEXCOORD_<uv_set> as the file has them."""
    document, binary = _read_chunks(path)
    nodes = document.get("nodes", [])
    parents = {}
    for index, node in enumerate(nodes):
        for child in node.get("children", []):
            parents[child] = index
    triangles = {}
    for index, node in enumerate(nodes):
        if "mesh" not in node:
            continue
        world = _node_matrix(node)
        p = parents.get(index)
        while p is not None:
            world = _node_matrix(nodes[p]) @ world
            p = parents.get(p)
        out = triangles.setdefault(node.get("name", f"node{index}"), [])
        for primitive in document["meshes"][node["mesh"]]["primitives"]:
            attributes = primitive["attributes"]
            if primitive.get("mode", 4) != 4 or f"TEXCOORD_{uv_set}" not in attributes:
                continue
            positions = [world @ mathutils.Vector(v)
                         for v in _accessor(document, binary, attributes["POSITION"])]
            uvs = _accessor(document, binary, attributes[f"TEXCOORD_{uv_set}"])
            if "indices" in primitive:
                indices = [i[0] for i in _accessor(document, binary, primitive["indices"])]
            else:
                indices = list(range(len(positions)))
            for t in range(0, len(indices) - 2, 3):
                corners = indices[t:t + 3]
                out.append(([positions[i] for i in corners], [uvs[i] for i in corners]))
    return triangles
