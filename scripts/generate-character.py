#!/usr/bin/env python3
"""Authors the project's own glTF character (config/characters/blocky.gltf).

Python standard library only: the glTF 2.0 JSON with one embedded base64 buffer.
A skinned figure of boxes, one rigid box per bone, on a Mixamo-named skeleton
(Hips, Spine, ..., LeftUpLeg, with *_End leaves) whose proportions are the default
puppet's (runtime/gait/puppet.cpp) scaled by 1.04, so loading it exercises the
humanoid chain detection (retarget/humanoid.hpp) and the scale fit rather than
a name-for-name copy. It faces +Z with its left on +X, Y up, metres (glTF's
convention), and stands in the rest pose the puppet stands in: legs and arms
straight down.

Usage: scripts/generate-character.py [OUT_FILE]   (default config/characters/blocky.gltf)
The output is deterministic; regenerate and commit when changing it.
"""
import base64
import json
import os
import struct
import sys

SCALE = 1.04
P = dict(pelvis_height=0.95, hip_width=0.18, thigh_length=0.44, shin_length=0.43, ankle_height=0.08,
         foot_length=0.14, toe_length=0.06, spine_length=0.50, neck_length=0.10, head_length=0.22,
         shoulder_width=0.36, upper_arm_length=0.29, forearm_length=0.26, hand_length=0.18)


def skeleton():
    """(name, parent name, offset) in parent-before-child order."""
    seg = P["spine_length"] / 3.0
    j = [("Hips", None, (0, P["pelvis_height"], 0)),
         ("Spine", "Hips", (0, 0.10, 0)),
         ("Spine1", "Spine", (0, seg, 0)),
         ("Spine2", "Spine1", (0, seg, 0)),
         ("Neck", "Spine2", (0, P["spine_length"] - 0.10 - seg, 0)),
         ("Head", "Neck", (0, P["neck_length"], 0)),
         ("HeadTop_End", "Head", (0, P["head_length"], 0))]
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        j += [(side + "Shoulder", "Spine2", (sign * 0.03, seg * 0.8, 0.02)),
              (side + "Arm", side + "Shoulder", (sign * (P["shoulder_width"] * 0.5 - 0.03), 0, -0.02)),
              (side + "ForeArm", side + "Arm", (0, -P["upper_arm_length"], 0)),
              (side + "Hand", side + "ForeArm", (0, -P["forearm_length"], 0)),
              (side + "Hand_End", side + "Hand", (0, -P["hand_length"], 0))]
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        j += [(side + "UpLeg", "Hips", (sign * P["hip_width"] * 0.5, 0, 0)),
              (side + "Leg", side + "UpLeg", (0, -P["thigh_length"], 0)),
              (side + "Foot", side + "Leg", (0, -P["shin_length"], 0)),
              (side + "ToeBase", side + "Foot", (0, -P["ankle_height"], P["foot_length"])),
              (side + "Toe_End", side + "ToeBase", (0, 0, P["toe_length"]))]
    return [(n, p, tuple(SCALE * c for c in o)) for n, p, o in j]


# Boxes: (joint that moves it, from joint, to joint, half width x, half depth z).
def boxes():
    b = [("Hips", "Hips", "Spine", 0.15, 0.10),
         ("Spine", "Spine", "Spine1", 0.14, 0.09),
         ("Spine1", "Spine1", "Spine2", 0.16, 0.10),
         ("Spine2", "Spine2", "Neck", 0.19, 0.11),
         ("Neck", "Neck", "Head", 0.05, 0.05),
         ("Head", "Head", "HeadTop_End", 0.09, 0.10)]
    for s in ("Left", "Right"):
        b += [(s + "Arm", s + "Arm", s + "ForeArm", 0.05, 0.05),
              (s + "ForeArm", s + "ForeArm", s + "Hand", 0.04, 0.04),
              (s + "Hand", s + "Hand", s + "Hand_End", 0.025, 0.05),
              (s + "UpLeg", s + "UpLeg", s + "Leg", 0.075, 0.08),
              (s + "Leg", s + "Leg", s + "Foot", 0.055, 0.06),
              (s + "Foot", s + "Foot", s + "ToeBase", 0.05, 0.05),
              (s + "ToeBase", s + "ToeBase", s + "Toe_End", 0.05, 0.035)]
    return b


def world_positions(joints):
    pos = {}
    for n, p, o in joints:
        base = pos[p] if p else (0.0, 0.0, 0.0)
        pos[n] = tuple(base[i] + o[i] for i in range(3))
    return pos


def box_vertices(a, b, hx, hz):
    """24 vertices (4 per face) of a box spanning a..b with its long side along a→b."""
    ax = [b[i] - a[i] for i in range(3)]
    length = sum(c * c for c in ax) ** 0.5
    d = [c / length for c in ax]
    # A side vector: X unless the bone runs along X, then Y.
    s = (1.0, 0.0, 0.0) if abs(d[0]) < 0.9 else (0.0, 1.0, 0.0)
    dot = sum(s[i] * d[i] for i in range(3))
    u = [s[i] - dot * d[i] for i in range(3)]
    ul = sum(c * c for c in u) ** 0.5
    u = [c / ul for c in u]
    v = [d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]]
    hx *= SCALE
    hz *= SCALE

    def corner(t, su, sv):
        return tuple(a[i] + t * ax[i] + su * hx * u[i] + sv * hz * v[i] for i in range(3))
    faces = [  # (normal, four corners counter-clockwise seen from outside)
        (u, [corner(0, 1, -1), corner(1, 1, -1), corner(1, 1, 1), corner(0, 1, 1)]),
        ([-c for c in u], [corner(0, -1, 1), corner(1, -1, 1), corner(1, -1, -1), corner(0, -1, -1)]),
        (v, [corner(0, 1, 1), corner(1, 1, 1), corner(1, -1, 1), corner(0, -1, 1)]),
        ([-c for c in v], [corner(0, -1, -1), corner(1, -1, -1), corner(1, 1, -1), corner(0, 1, -1)]),
        (d, [corner(1, 1, -1), corner(1, -1, -1), corner(1, -1, 1), corner(1, 1, 1)]),
        ([-c for c in d], [corner(0, 1, 1), corner(0, -1, 1), corner(0, -1, -1), corner(0, 1, -1)]),
    ]
    return faces


def build():
    joints = skeleton()
    names = [n for n, _, _ in joints]
    pos = world_positions(joints)
    positions, normals, joint_ids, weights, indices = [], [], [], [], []
    for mover, a, b, hx, hz in boxes():
        for normal, quad in box_vertices(pos[a], pos[b], hx, hz):
            base = len(positions)
            for c in quad:
                positions.append(c)
                normals.append(tuple(normal))
                joint_ids.append((names.index(mover), 0, 0, 0))
                weights.append((1.0, 0.0, 0.0, 0.0))
            indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    inverse_bind = []
    for n in names:  # rest rotations are identity: the inverse bind is a translation
        p = pos[n]
        inverse_bind.append((1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -p[0], -p[1], -p[2], 1))

    chunks, views, accessors = [], [], []

    def add(data, target, acc):
        offset = sum(len(c) for c in chunks)
        chunks.append(data + b"\0" * (-len(data) % 4))
        view = {"buffer": 0, "byteOffset": offset, "byteLength": len(data)}
        if target:
            view["target"] = target
        views.append(view)
        acc["bufferView"] = len(views) - 1
        accessors.append(acc)
        return len(accessors) - 1

    flat = [c for p in positions for c in p]
    pos_acc = add(struct.pack("<%df" % len(flat), *flat), 34962,
                  {"componentType": 5126, "count": len(positions), "type": "VEC3",
                   "min": [round(min(p[i] for p in positions), 6) for i in range(3)],
                   "max": [round(max(p[i] for p in positions), 6) for i in range(3)]})
    flat = [c for n in normals for c in n]
    nrm_acc = add(struct.pack("<%df" % len(flat), *flat), 34962, {"componentType": 5126, "count": len(normals), "type": "VEC3"})
    flat = [c for j in joint_ids for c in j]
    jnt_acc = add(struct.pack("<%dB" % len(flat), *flat), 34962, {"componentType": 5121, "count": len(joint_ids), "type": "VEC4"})
    flat = [c for w in weights for c in w]
    wgt_acc = add(struct.pack("<%df" % len(flat), *flat), 34962, {"componentType": 5126, "count": len(weights), "type": "VEC4"})
    idx_acc = add(struct.pack("<%dH" % len(indices), *indices), 34963, {"componentType": 5123, "count": len(indices), "type": "SCALAR"})
    flat = [float(c) for m in inverse_bind for c in m]
    ibm_acc = add(struct.pack("<%df" % len(flat), *flat), None, {"componentType": 5126, "count": len(inverse_bind), "type": "MAT4"})

    data = b"".join(chunks)
    nodes = []
    for n, p, o in joints:
        node = {"name": n, "translation": [round(c, 6) for c in o]}
        kids = [i for i, (_, pp, _) in enumerate(joints) if pp == n]
        if kids:
            node["children"] = kids
        nodes.append(node)
    nodes.append({"name": "Body", "mesh": 0, "skin": 0})
    return {
        "asset": {"version": "2.0", "generator": "marionette scripts/generate-character.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, len(nodes) - 1]}],
        "nodes": nodes,
        "meshes": [{"name": "Body", "primitives": [{
            "attributes": {"POSITION": pos_acc, "NORMAL": nrm_acc, "JOINTS_0": jnt_acc, "WEIGHTS_0": wgt_acc},
            "indices": idx_acc, "mode": 4}]}],
        "skins": [{"name": "Blocky", "joints": list(range(len(joints))), "skeleton": 0, "inverseBindMatrices": ibm_acc}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode("ascii")}],
    }


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "config", "characters", "blocky.gltf")
    with open(out, "w", encoding="utf-8") as f:
        json.dump(build(), f, indent=1)
        f.write("\n")
    print("wrote", out)


if __name__ == "__main__":
    main()
