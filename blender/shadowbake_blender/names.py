"""Blender object names as shadowbake names them, and back.

shadowbake names an object of a level after its glTF node (the Blender object's name) with every
byte a file name cannot hold made '_' (src/scene/level_file.cpp, safe_name; docs/scene-format.md,
"Levels"). Where two names become the same it puts parents' names in front; the add-on refuses
such a scene instead, so that every shadowbake name leads back to one Blender object.
"""

_FILE_NAME_BYTES = frozenset(b"abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-")


def shadowbake_name(blender_name):
    """The name shadowbake gives a glTF node called `blender_name` (bytes of its UTF-8)."""
    out = "".join(chr(b) if b in _FILE_NAME_BYTES else "_" for b in blender_name.encode("utf-8"))
    if not out:
        out = "node"
    if out[0] == ".":
        out = "_" + out[1:]
    return out


class NameMap:
    """shadowbake's names of the exported objects and lights, each to its Blender object."""

    def __init__(self):
        self.to_blender = {}

    def add(self, blender_name):
        """The shadowbake name of `blender_name`; a ValueError when another takes it already."""
        name = shadowbake_name(blender_name)
        other = self.to_blender.get(name)
        if other is not None and other != blender_name:
            raise ValueError(
                f'"{blender_name}" and "{other}" both become "{name}" in shadowbake, which '
                "keeps letters, digits, '_', '.' and '-' of a name: rename one of them")
        self.to_blender[name] = blender_name
        return name

    def blender(self, name):
        return self.to_blender.get(name, name)
