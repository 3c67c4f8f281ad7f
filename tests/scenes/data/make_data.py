#!/usr/bin/env python3
"""Writes the small glTF files the scene tests load (run from this folder; outputs are committed).

Each file is built from first principles here so its expected contents are known exactly:
  cube_tangents.gltf   unit cube (24 vertices, 12 triangles) with NORMAL, TANGENT, TEXCOORD_0,
                       node TRS hierarchy, an orthographic camera, KHR_lights_punctual lights
                       and an emissive material (KHR_materials_emissive_strength)
  cube_no_tangents.gltf same cube without TANGENT: tangents are derived from the UVs
  quad_no_uv.gltf      one quad with NORMAL only (no UVs): tangents from an arbitrary frame;
                       placed with a column-major matrix (translation + mirror)
  quad_external.gltf   one quad whose buffer is the external file quad_external.bin
  truncated.gltf       the first half of cube_tangents.gltf (malformed JSON)
  missing_buffer.gltf  references a .bin file that does not exist
  bad_accessor.gltf    a primitive whose POSITION accessor index is out of range
  bad_index.gltf       an index that exceeds the vertex count
  sparse.gltf          a quad whose POSITION accessor is sparse: vertices 1 and 3 moved to y = 2
                       and y = 3 (glTF 2.0 section 3.6.2.3)
  sparse_zeros.gltf    the same sparse accessor without a bufferView: the other vertices are zero
  blender_sun.gltf     laid out as Blender's glTF exporter writes a scene (Y up, a 2 m "Plane"
                       with a Principled "Material", a "Camera" 2 m above looking down, a "Sun" of
                       1000 lux shining 30 degrees off the vertical, KHR_lights_punctual)
"""
import base64, json, math, struct

def pack(fmt, values):
    return b"".join(struct.pack("<" + fmt, *v) if isinstance(v, (list, tuple)) else struct.pack("<" + fmt, v)
                    for v in values)

class Doc:
    def __init__(self):
        self.bin = bytearray()
        self.d = {"asset": {"version": "2.0", "generator": "weft tests make_data.py"},
                  "buffers": [], "bufferViews": [], "accessors": [], "meshes": [], "nodes": [],
                  "materials": [], "scenes": [{"nodes": []}], "scene": 0}

    def view(self, data, target):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.d["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data),
                                      "target": target})
        self.bin += data
        return len(self.d["bufferViews"]) - 1

    def floats(self, rows, typ):
        n = len(rows[0])
        v = self.view(pack("f" * n, rows), 34962)
        acc = {"bufferView": v, "componentType": 5126, "count": len(rows), "type": typ}
        if typ == "VEC3":
            acc["min"] = [min(r[i] for r in rows) for i in range(3)]
            acc["max"] = [max(r[i] for r in rows) for i in range(3)]
        self.d["accessors"].append(acc)
        return len(self.d["accessors"]) - 1

    def indices(self, idx):
        v = self.view(pack("H", idx), 34963)
        self.d["accessors"].append({"bufferView": v, "componentType": 5123, "count": len(idx), "type": "SCALAR"})
        return len(self.d["accessors"]) - 1

    def finish(self, path, external=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        buf = {"byteLength": len(self.bin)}
        if external:
            buf["uri"] = external
            open(external, "wb").write(self.bin)
        else:
            buf["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.bin)).decode()
        self.d["buffers"] = [buf]
        text = json.dumps(self.d, indent=1) + "\n"
        open(path, "w").write(text)
        return text

def cube():
    """Unit cube [-0.5, 0.5]^3; per face: normal, tangent along +u, uvs, CCW seen from outside."""
    faces = [  # normal, u axis, v axis
        ((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
        ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
        ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0))]
    P, N, T, UV, I = [], [], [], [], []
    for n, u, v in faces:
        base = len(P)
        for (a, b) in ((0, 0), (1, 0), (1, 1), (0, 1)):
            P.append([0.5 * n[k] + (a - 0.5) * u[k] + (b - 0.5) * v[k] for k in range(3)])
            N.append(list(n)); T.append(list(u) + [1.0]); UV.append([a, b])
        I += [base, base + 1, base + 2, base, base + 2, base + 3]  # u x v = n: CCW from outside
    return P, N, T, UV, I

def quad():
    P = [[-0.5, 0, 0.5], [0.5, 0, 0.5], [0.5, 0, -0.5], [-0.5, 0, -0.5]]  # u = +x, v = -z, n = +y
    return P, [[0, 1, 0]] * 4, [[1, 0, 0, 1]] * 4, [[0, 0], [1, 0], [1, 1], [0, 1]], [0, 1, 2, 0, 2, 3]

def cube_doc(with_tangents):
    d = Doc()
    P, N, T, UV, I = cube()
    attrs = {"POSITION": d.floats(P, "VEC3"), "NORMAL": d.floats(N, "VEC3"), "TEXCOORD_0": d.floats(UV, "VEC2")}
    if with_tangents:
        attrs["TANGENT"] = d.floats(T, "VEC4")
    d.d["materials"] = [{"name": "cube_mat"},
                        {"name": "glow", "emissiveFactor": [1.0, 0.5, 0.25], "doubleSided": True,
                         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}]
    d.d["extensionsUsed"] = ["KHR_lights_punctual", "KHR_materials_emissive_strength"]
    d.d["meshes"] = [{"name": "cube_mesh", "primitives": [{"attributes": attrs, "indices": d.indices(I), "material": 0}]}]
    qp, qn, qt, quv, qi = quad()
    d.d["meshes"].append({"name": "lamp_mesh", "primitives": [{"attributes": {
        "POSITION": d.floats(qp, "VEC3"), "NORMAL": d.floats(qn, "VEC3")}, "indices": d.indices(qi), "material": 1}]})
    # Hierarchy: root (translation (10, 0, 0)) -> child (scale 2, rotation 90 deg about +y) -> cube.
    s = 0.5 ** 0.5
    d.d["nodes"] = [
        {"name": "root", "translation": [10, 0, 0], "children": [1, 2, 3, 4, 5]},
        {"name": "child", "scale": [2, 2, 2], "rotation": [0, s, 0, s], "mesh": 0},
        {"name": "ortho_cam", "translation": [0, 0, 5], "camera": 0},
        {"name": "sun", "rotation": [-s, 0, 0, s], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "bulb", "translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"name": "lamp", "translation": [0, 4, 0], "mesh": 1}]
    d.d["cameras"] = [{"name": "ortho", "type": "orthographic",
                       "orthographic": {"xmag": 1.5, "ymag": 1.0, "znear": 0.01, "zfar": 100}}]
    d.d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "sun", "type": "directional", "color": [1, 1, 1], "intensity": 3},
        {"name": "bulb", "type": "point", "color": [1, 0.5, 0.5], "intensity": 2}]}}
    d.d["scenes"][0]["nodes"] = [0]
    return d

def quad_doc(uvs=True):
    d = Doc()
    P, N, T, UV, I = quad()
    attrs = {"POSITION": d.floats(P, "VEC3"), "NORMAL": d.floats(N, "VEC3")}
    if uvs:
        attrs["TEXCOORD_0"] = d.floats(UV, "VEC2")
    d.d["materials"] = [{"name": "quad_mat"}]
    d.d["meshes"] = [{"name": "quad_mesh", "primitives": [{"attributes": attrs, "indices": d.indices(I), "material": 0}]}]
    d.d["nodes"] = [{"name": "quad", "mesh": 0}]
    d.d["scenes"][0]["nodes"] = [0]
    return d

cube_doc(True).finish("cube_tangents.gltf")
cube_doc(False).finish("cube_no_tangents.gltf")
d = quad_doc(uvs=False)
# Column-major matrix: mirror x (x -> -x) and translate by (1, 2, 3).
d.d["nodes"][0]["matrix"] = [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 2, 3, 1]
d.finish("quad_no_uv.gltf")
quad_doc().finish("quad_external.gltf", external="quad_external.bin")

text = open("cube_tangents.gltf").read()
open("truncated.gltf", "w").write(text[: len(text) // 2])
d = quad_doc()
d.finish("missing_buffer.gltf", external="does_not_exist.bin")
import os
os.remove("does_not_exist.bin")
d = quad_doc()
d.d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 42
d.finish("bad_accessor.gltf")
d = quad_doc()
d.indices([0, 1, 7])
d.d["meshes"][0]["primitives"][0]["indices"] = len(d.d["accessors"]) - 1
d.finish("bad_index.gltf")

def sparse_doc(zeros):
    d = Doc()
    base = [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]]
    pos = d.floats(base, "VEC3")
    acc = d.d["accessors"][pos]
    if zeros:
        del acc["bufferView"]
    idx_view = d.view(pack("H", [1, 3]), None)
    val_view = d.view(pack("fff", [[1, 2, 0], [0, 3, 1]]), None)
    for v in (idx_view, val_view):
        del d.d["bufferViews"][v]["target"]
    acc["sparse"] = {"count": 2, "indices": {"bufferView": idx_view, "componentType": 5123},
                     "values": {"bufferView": val_view}}
    acc["min"], acc["max"] = [0, 0, 0], [1, 3, 1]
    d.d["materials"] = [{"name": "quad_mat"}]
    d.d["meshes"] = [{"name": "sparse_mesh", "primitives": [
        {"attributes": {"POSITION": pos}, "indices": d.indices([0, 1, 2, 0, 2, 3]), "material": 0}]}]
    d.d["nodes"] = [{"name": "quad", "mesh": 0}]
    d.d["scenes"][0]["nodes"] = [0]
    return d

sparse_doc(False).finish("sparse.gltf")
sparse_doc(True).finish("sparse_zeros.gltf")

def blender_doc():
    d = Doc()
    d.d["asset"] = {"generator": "Khronos glTF Blender I/O v4.2.70", "version": "2.0"}
    # Blender's default plane (2 m) after the exporter's +Y-up conversion: normal +y.
    P = [[-1, 0, 1], [1, 0, 1], [-1, 0, -1], [1, 0, -1]]
    attrs = {"POSITION": d.floats(P, "VEC3"), "NORMAL": d.floats([[0, 1, 0]] * 4, "VEC3"),
             "TEXCOORD_0": d.floats([[0, 0], [1, 0], [0, 1], [1, 1]], "VEC2")}
    d.d["materials"] = [{"name": "Material", "doubleSided": True, "pbrMetallicRoughness": {
        "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0, "roughnessFactor": 0.5}}]
    d.d["meshes"] = [{"name": "Plane", "primitives": [
        {"attributes": attrs, "indices": d.indices([0, 1, 3, 0, 3, 2]), "material": 0}]}]
    s = 0.5 ** 0.5
    # The sun's -z axis turned by -60 degrees about x: it shines along (0, -0.866, -0.5).
    h = math.radians(-60) / 2
    d.d["nodes"] = [
        {"name": "Plane", "mesh": 0},
        {"name": "Camera", "camera": 0, "translation": [0, 2, 0], "rotation": [-s, 0, 0, s]},
        {"name": "Sun", "rotation": [math.sin(h), 0, 0, math.cos(h)], "translation": [0, 5, 0],
         "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    d.d["cameras"] = [{"name": "Camera", "type": "perspective",
                       "perspective": {"aspectRatio": 1.0, "yfov": 0.6, "znear": 0.1, "zfar": 100}}]
    d.d["extensionsUsed"] = ["KHR_lights_punctual"]
    d.d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "Sun", "type": "directional", "color": [1, 1, 1], "intensity": 1000}]}}
    d.d["scenes"][0]["nodes"] = [0, 1, 2]
    d.d["scenes"][0]["name"] = "Scene"
    return d

blender_doc().finish("blender_sun.gltf")
