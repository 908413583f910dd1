#!/usr/bin/env python3
"""Writes a glTF of N full-view quads stacked in depth, each a node placing one quad mesh under its own
glTF BLEND material (alpha 0.15, colours cycling), over an opaque backdrop: the transparency pass's
worst case (every layer covers every pixel). Usage: blend_layers.py N OUT.gltf  (docs/gltf.md measures it)."""
import base64, json, struct, sys

n, out = int(sys.argv[1]), sys.argv[2]
pos = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
data = b"".join(struct.pack("<3f", *p) for p in pos) + b"".join(struct.pack("<3f", 0, 0, 1) for _ in pos)
data += struct.pack("<6H", 0, 1, 2, 0, 2, 3)
doc = {
    "asset": {"version": "2.0"},
    "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 96, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                  {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
    "nodes": [{"mesh": 0, "translation": [0, 0, -float(n) * 0.01 - 0.1], "scale": [4, 4, 1]}],
}
colours = [(1, 0.2, 0.2), (0.2, 1, 0.2), (0.2, 0.2, 1), (1, 1, 0.2)]
for i in range(n):
    doc["materials"].append({"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [*colours[i % 4], 0.15], "metallicFactor": 0}})
    doc["meshes"].append({"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": i + 1}]})
    doc["nodes"].append({"mesh": i + 1, "translation": [0, 0, -i * 0.01], "scale": [3, 3, 1]})
doc["scenes"] = [{"nodes": list(range(n + 1))}]
doc["scene"] = 0
json.dump(doc, open(out, "w"))
