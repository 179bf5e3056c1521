"""A GLB reader of the tests' own (struct, json, numpy; not the writer's library), so that what a
file says is read back the way a viewer reads it: header, JSON and BIN chunks, accessors,
node hierarchy, animation keyframes."""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

_DTYPES = {5126: np.float32, 5123: np.uint16, 5125: np.uint32}
_WIDTH = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}


@dataclass
class Glb:
    doc: dict[str, Any]
    blob: bytes

    def accessor(self, index: int) -> np.ndarray:
        acc = self.doc["accessors"][index]
        view = self.doc["bufferViews"][acc["bufferView"]]
        dtype = np.dtype(_DTYPES[acc["componentType"]])
        width = _WIDTH[acc["type"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        data = np.frombuffer(self.blob, dtype, acc["count"] * width, start)
        return data.reshape(acc["count"], width) if width > 1 else data

    def node_index(self, name: str) -> int:
        names = [n.get("name") for n in self.doc["nodes"]]
        return names.index(name)

    def parent_of(self) -> dict[int, int]:
        return {c: i for i, n in enumerate(self.doc["nodes"]) for c in n.get("children", [])}

    def keyframes(self, animation: str, node: int, path: str) -> tuple[np.ndarray, np.ndarray]:
        """(times, values) of one channel of the named animation."""
        anim = next(a for a in self.doc["animations"] if a["name"] == animation)
        for channel in anim["channels"]:
            if channel["target"]["node"] == node and channel["target"]["path"] == path:
                sampler = anim["samplers"][channel["sampler"]]
                return self.accessor(sampler["input"]), self.accessor(sampler["output"])
        raise KeyError(f"no {path} channel for node {node} in {animation}")

    def world_of_parent(self, node: int) -> Rotation:
        """The rotation above ``node`` (its ancestors carry rotations only, no translation)."""
        parents = self.parent_of()
        rotation = Rotation.identity()
        at = parents.get(node)
        while at is not None:
            n = self.doc["nodes"][at]
            assert "translation" not in n and "scale" not in n, "ancestors only rotate"
            rotation = Rotation.from_quat(n.get("rotation", [0, 0, 0, 1])) * rotation
            at = parents.get(at)
        return rotation


def read_glb(path: str | Path) -> Glb:
    data = Path(path).read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2 and length == len(data)
    offset, doc, blob = 12, None, b""
    while offset < length:
        size, kind = struct.unpack_from("<I4s", data, offset)
        chunk = data[offset + 8 : offset + 8 + size]
        if kind == b"JSON":
            doc = json.loads(chunk)
        elif kind == b"BIN\x00":
            blob = chunk
        offset += 8 + size
    assert doc is not None
    return Glb(doc, blob)
