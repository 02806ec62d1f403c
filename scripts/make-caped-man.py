#!/usr/bin/env python3
"""make-caped-man.py — writes assets/CapedMan/CapedMan.glb: CesiumMan with a cape (docs/CLOTH.md).

The cloth sample is made, not downloaded: no public rigged character with a cape was found under a
licence that allows redistribution here, so this script adds one to the bundled CesiumMan (CC-BY 4.0,
Cesium). The cape is a grid hung behind the back from the shoulder line, skinned wholly to the chest
joint (torso_joint_3), with its cloth painted in colour set 1 (glTF COLOR_1, docs/CLOTH.md): red 0 on
the top row (it stays skinned, pinned to the chest) and 1 below (simulated). The ossa cooker fits the
body's colliders from the limb bones near the cloth.

Deterministic (the same input gives the same bytes); `--check` compares with the committed file, which
tests/cooker/cook_cloth_test.cpp does so the sample never drifts from its generator.
Usage: scripts/make-caped-man.py [--source assets/CesiumMan/CesiumMan.glb] [--out FILE] [--check]
"""
import argparse
import json
import struct
import sys

COLUMNS, ROWS = 13, 20           # 260 particles
TOP_Y, BOTTOM_Y = 1.10, 0.42     # metres, the shoulder line to below the knees
TOP_HALF, BOTTOM_HALF = 0.15, 0.26
BACK_Z = -0.125                  # just behind the back (the body's back is at z = -0.10; the front is +z)
CHEST = "torso_joint_3"


def read_glb(path):
    data = open(path, "rb").read()
    magic, version, _ = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2:
        raise SystemExit(f"{path}: not a glTF 2.0 binary")
    json_len, json_type = struct.unpack_from("<I4s", data, 12)
    if json_type != b"JSON":
        raise SystemExit(f"{path}: first chunk is not JSON")
    doc = json.loads(data[20:20 + json_len])
    at = 20 + json_len
    bin_len, bin_type = struct.unpack_from("<I4s", data, at)
    if bin_type != b"BIN\0":
        raise SystemExit(f"{path}: second chunk is not BIN")
    return doc, bytearray(data[at + 8:at + 8 + bin_len])


def write_glb(doc, blob):
    text = json.dumps(doc, separators=(",", ":"), sort_keys=True).encode()
    text += b" " * (-len(text) % 4)
    blob = bytes(blob) + b"\0" * (-len(blob) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(text), b"JSON") + text +
            struct.pack("<I4s", len(blob), b"BIN\0") + blob)


def make_cape(doc, blob):
    nodes = doc["nodes"]
    skin = doc["skins"][0]
    names = [nodes[j].get("name") for j in skin["joints"]]
    if CHEST not in names:
        raise SystemExit(f"the source has no joint '{CHEST}'")
    chest = names.index(CHEST)

    positions, normals, uvs, colours, paint, joints, weights, indices = [], [], [], [], [], [], [], []
    for r in range(ROWS):
        t = r / (ROWS - 1)
        y = TOP_Y + (BOTTOM_Y - TOP_Y) * t
        half = TOP_HALF + (BOTTOM_HALF - TOP_HALF) * t
        for c in range(COLUMNS):
            s = c / (COLUMNS - 1)
            x = -half + 2.0 * half * s
            positions += [x, y, BACK_Z - 0.02 * t]
            normals += [0.0, 0.0, -1.0]
            uvs += [s, t]
            colours += [1.0, 1.0, 1.0, 1.0]
            paint += [0.0 if r == 0 else 1.0, 1.0, 1.0, 1.0]
            joints += [chest, 0, 0, 0]
            weights += [1.0, 0.0, 0.0, 0.0]
    for r in range(ROWS - 1):
        for c in range(COLUMNS - 1):
            v = r * COLUMNS + c
            indices += [v, v + 1, v + COLUMNS, v + 1, v + COLUMNS + 1, v + COLUMNS]

    views, accessors = doc["bufferViews"], doc["accessors"]

    def add(fmt, values, component, kind, count, minmax=False):
        while len(blob) % 4:
            blob.append(0)
        raw = struct.pack("<" + fmt * len(values), *values)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(raw)})
        blob.extend(raw)
        acc = {"bufferView": len(views) - 1, "componentType": component, "count": count, "type": kind}
        if minmax:
            acc["min"] = [min(values[i::3]) for i in range(3)]
            acc["max"] = [max(values[i::3]) for i in range(3)]
        accessors.append(acc)
        return len(accessors) - 1

    n = COLUMNS * ROWS
    attributes = {
        "POSITION": add("f", positions, 5126, "VEC3", n, minmax=True),
        "NORMAL": add("f", normals, 5126, "VEC3", n),
        "TEXCOORD_0": add("f", uvs, 5126, "VEC2", n),
        "COLOR_0": add("f", colours, 5126, "VEC4", n),
        "COLOR_1": add("f", paint, 5126, "VEC4", n),
        "JOINTS_0": add("H", joints, 5123, "VEC4", n),
        "WEIGHTS_0": add("f", weights, 5126, "VEC4", n),
    }
    index_accessor = add("H", indices, 5123, "SCALAR", len(indices))
    doc.setdefault("materials", []).append({
        "name": "Cape", "doubleSided": True,
        "pbrMetallicRoughness": {"baseColorFactor": [0.55, 0.07, 0.09, 1.0], "metallicFactor": 0.0,
                                 "roughnessFactor": 0.8}})
    doc["meshes"].append({"name": "Cape", "primitives": [
        {"attributes": attributes, "indices": index_accessor, "material": len(doc["materials"]) - 1}]})
    nodes.append({"name": "Cape", "mesh": len(doc["meshes"]) - 1, "skin": 0})
    armature = next(i for i, nd in enumerate(nodes) if skin["joints"][0] in nd.get("children", []))
    nodes[armature]["children"].append(len(nodes) - 1)
    doc["buffers"][0]["byteLength"] = len(blob)
    doc["asset"]["generator"] = "ossa scripts/make-caped-man.py from CesiumMan"
    return doc, blob


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--source", default="assets/CesiumMan/CesiumMan.glb")
    p.add_argument("--out", default="assets/CapedMan/CapedMan.glb")
    p.add_argument("--check", action="store_true", help="exit 1 if --out differs from what would be written")
    a = p.parse_args()
    doc, blob = read_glb(a.source)
    data = write_glb(*make_cape(doc, blob))
    if a.check:
        try:
            same = open(a.out, "rb").read() == data
        except OSError as e:
            print(f"{a.out}: {e.strerror}", file=sys.stderr)
            return 1
        if not same:
            print(f"{a.out}: differs from what scripts/make-caped-man.py writes (re-run it)", file=sys.stderr)
        return 0 if same else 1
    with open(a.out + ".tmp", "wb") as f:
        f.write(data)
    import os
    os.replace(a.out + ".tmp", a.out)
    print(f"{a.out}: {COLUMNS * ROWS} cape vertices on '{CHEST}', {len(data)} bytes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
