#!/usr/bin/env python3
"""Writes the glTF fuzzing seeds (fuzz/corpus/gltf/): a tiny rigged figure.

The 19 canonical joints (sim/body/skeleton.h names, the importer's "irbench"
convention) in a T-pose 1.72 m tall, and a tetrahedron around each joint
skinned wholly to it: the smallest file that goes all the way through
ImportRiggedAvatar (joint mapping, up axis, re-posing, markers), so mutations
start deep in the importer. Written as figure.glb and as figure.gltf (the
buffer as a data URI). Run from anywhere: python3 fuzz/make_gltf_seeds.py
"""
import base64
import json
import pathlib
import struct

# name, parent, position in the world frame (z up, facing +y, right at +x), metres
JOINTS = [
    ("pelvis", None, (0, 0, 0.95)), ("spine", "pelvis", (0, 0, 1.10)), ("chest", "spine", (0, 0, 1.30)),
    ("neck", "chest", (0, 0, 1.50)), ("head", "neck", (0, 0, 1.60)),
    ("right_clavicle", "chest", (0.05, 0, 1.45)), ("right_shoulder", "right_clavicle", (0.18, 0, 1.45)),
    ("right_elbow", "right_shoulder", (0.46, 0, 1.45)), ("right_wrist", "right_elbow", (0.71, 0, 1.45)),
    ("left_clavicle", "chest", (-0.05, 0, 1.45)), ("left_shoulder", "left_clavicle", (-0.18, 0, 1.45)),
    ("left_elbow", "left_shoulder", (-0.46, 0, 1.45)), ("left_wrist", "left_elbow", (-0.71, 0, 1.45)),
    ("right_hip", "pelvis", (0.10, 0, 0.90)), ("right_knee", "right_hip", (0.10, 0, 0.50)),
    ("right_ankle", "right_knee", (0.10, 0, 0.08)),
    ("left_hip", "pelvis", (-0.10, 0, 0.90)), ("left_knee", "left_hip", (-0.10, 0, 0.50)),
    ("left_ankle", "left_knee", (-0.10, 0, 0.08)),
]


def gltf_from_world(p):
    """World (x, y, z) -> glTF (y up, facing +z): (-x, z, y)."""
    return (-p[0], p[2], p[1])


def build():
    index = {name: i for i, (name, _, _) in enumerate(JOINTS)}
    world = [gltf_from_world(p) for _, _, p in JOINTS]
    positions, joints, weights, indices = [], [], [], []
    for j, (name, _, p) in enumerate(JOINTS):
        r = 0.04
        top = 1.72 - p[2] if name == "head" else r  # the head reaches 1.72 m
        bottom = p[2] if name.endswith("ankle") else r  # the feet touch the floor
        tetra = [(p[0] + r, p[1], p[2] - bottom), (p[0] - r, p[1] + r, p[2] - bottom),
                 (p[0] - r, p[1] - r, p[2] - bottom), (p[0], p[1], p[2] + top)]
        base = len(positions)
        positions += [gltf_from_world(v) for v in tetra]
        joints += [(j, 0, 0, 0)] * 4
        weights += [(255, 0, 0, 0)] * 4
        indices += [base + k for k in (0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3)]
    blobs = [
        b"".join(struct.pack("<3f", *v) for v in positions),
        b"".join(struct.pack("<4B", *v) for v in joints),
        b"".join(struct.pack("<4B", *v) for v in weights),
        struct.pack("<%dB" % len(indices), *indices),
        # Inverse bind matrices: the bind pose has no rotation, so each is a
        # translation by minus the joint's position (column-major).
        b"".join(struct.pack("<16f", 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -w[0], -w[1], -w[2], 1) for w in world),
    ]
    views, offset = [], 0
    for blob in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        offset += (len(blob) + 3) // 4 * 4
    data = b"".join(blob + b"\0" * ((4 - len(blob) % 4) % 4) for blob in blobs)
    lo = [min(v[k] for v in positions) for k in range(3)]
    hi = [max(v[k] for v in positions) for k in range(3)]
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3", "min": lo, "max": hi},
        {"bufferView": 1, "componentType": 5121, "count": len(joints), "type": "VEC4"},
        {"bufferView": 2, "componentType": 5121, "normalized": True, "count": len(weights), "type": "VEC4"},
        {"bufferView": 3, "componentType": 5121, "count": len(indices), "type": "SCALAR"},
        {"bufferView": 4, "componentType": 5126, "count": len(JOINTS), "type": "MAT4"},
    ]
    nodes = []
    for j, (name, parent, _) in enumerate(JOINTS):
        pw = world[index[parent]] if parent else (0, 0, 0)
        node = {"name": name, "translation": [world[j][k] - pw[k] for k in range(3)]}
        children = [index[c] for c, p, _ in JOINTS if p == name]
        if children:
            node["children"] = children
        nodes.append(node)
    nodes.append({"name": "body", "mesh": 0, "skin": 0})
    gltf = {
        "asset": {"version": "2.0", "generator": "irbench fuzz/make_gltf_seeds.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, len(JOINTS)]}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}, "indices": 3}]}],
        "skins": [{"inverseBindMatrices": 4, "joints": list(range(len(JOINTS))), "skeleton": 0}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(data)}],
    }
    return gltf, data


def glb(gltf, data):
    text = json.dumps(gltf, separators=(",", ":")).encode()
    text += b" " * ((4 - len(text) % 4) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(data), 0x004E4942) + data
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def main():
    out = pathlib.Path(__file__).resolve().parent / "corpus" / "gltf"
    out.mkdir(parents=True, exist_ok=True)
    gltf, data = build()
    (out / "figure.glb").write_bytes(glb(gltf, data))
    gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
    (out / "figure.gltf").write_text(json.dumps(gltf, separators=(",", ":")))


if __name__ == "__main__":
    main()
