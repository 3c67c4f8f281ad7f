#!/usr/bin/env python3
"""Writes lambert-plane.gltf: a 1 m x 1 m square in the xz plane facing +y (glTF's up), node and
mesh "plane", material "plane", NORMAL, TANGENT (+x) and TEXCOORD_0, buffer embedded."""
import base64, json, struct

P = [(-0.5, 0, 0.5), (0.5, 0, 0.5), (0.5, 0, -0.5), (-0.5, 0, -0.5)]  # u = +x, v = -z, n = +y
N = [(0, 1, 0)] * 4
T = [(1, 0, 0, 1)] * 4
UV = [(0, 0), (1, 0), (1, 1), (0, 1)]
I = [0, 1, 2, 0, 2, 3]  # counter-clockwise seen from +y
chunks = [b"".join(struct.pack("<3f", *p) for p in P), b"".join(struct.pack("<3f", *n) for n in N),
          b"".join(struct.pack("<4f", *t) for t in T), b"".join(struct.pack("<2f", *u) for u in UV),
          struct.pack("<6H", *I) + b"\0\0"]
views, off = [], 0
for c, target in zip(chunks, [34962] * 4 + [34963]):
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(c), "target": target})
    off += len(c)
data = b"".join(chunks)
doc = {
    "asset": {"version": "2.0", "generator": "weft scenes/examples/make_lambert_plane.py"},
    "scene": 0, "scenes": [{"name": "lambert-plane", "nodes": [0]}],
    "nodes": [{"name": "plane", "mesh": 0}],
    "meshes": [{"name": "plane", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TANGENT": 2,
                                                                 "TEXCOORD_0": 3}, "indices": 4, "material": 0}]}],
    "materials": [{"name": "plane"}],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, 0, -0.5], "max": [0.5, 0, 0.5]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC4"},
        {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    "bufferViews": views,
    "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
}
open("lambert-plane.gltf", "w").write(json.dumps(doc, indent=1) + "\n")
