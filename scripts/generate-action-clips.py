#!/usr/bin/env python3
"""Authors the default puppet's action clips (config/clips/*.bvh).

Python standard library only. The hierarchy mirrors runtime/gait/puppet.cpp's
make_puppet_skeleton() with the default [puppet] proportions of
runtime/sim/sim_config.hpp (same joint names, order and offsets), so the clips import
with runtime/formats/bvh.hpp onto the puppet's own skeleton. Each clip is 30 Hz, starts
and ends in the idle standing pose (arms hanging slightly out, elbows a little
bent, as the gait stands) so the motion graph finds transitions into and out of it, and eases every
curve in and out (smoothstep envelopes); secondary motion (head lag, counter
sway, breathing) keeps it from looking rigid.

Usage: scripts/generate-action-clips.py [OUT_DIR]   (default config/clips)
The output is deterministic; regenerate and commit when changing a clip.
"""
import math
import os
import sys

RATE = 30
P = dict(pelvis_height=0.95, hip_width=0.18, thigh_length=0.44, shin_length=0.43, ankle_height=0.08,
         foot_length=0.14, toe_length=0.06, spine_length=0.50, neck_length=0.10, head_length=0.22,
         shoulder_width=0.36, upper_arm_length=0.29, forearm_length=0.26, hand_length=0.18)


def skeleton():
    """(name, parent, offset, end_site_offset or None) in runtime/gait/puppet.cpp's order."""
    seg = P["spine_length"] / 3.0
    j = [("pelvis", -1, (0, P["pelvis_height"], 0), None),
         ("spine_01", 0, (0, 0.10, 0), None),
         ("spine_02", 1, (0, seg, 0), None),
         ("spine_03", 2, (0, seg, 0), None),
         ("neck", 3, (0, P["spine_length"] - 0.10 - seg, 0), None),
         ("head", 4, (0, P["neck_length"], 0), (0, P["head_length"], 0))]
    for side, sign in (("l", 1.0), ("r", -1.0)):
        c = len(j)
        j += [("clavicle_" + side, 3, (sign * 0.03, seg * 0.8, 0.02), None),
              ("upperarm_" + side, c, (sign * (P["shoulder_width"] * 0.5 - 0.03), 0, -0.02), None),
              ("forearm_" + side, c + 1, (0, -P["upper_arm_length"], 0), None),
              ("hand_" + side, c + 2, (0, -P["forearm_length"], 0), (0, -P["hand_length"], 0))]
    for side, sign in (("l", 1.0), ("r", -1.0)):
        t = len(j)
        j += [("thigh_" + side, 0, (sign * P["hip_width"] * 0.5, 0, 0), None),
              ("shin_" + side, t, (0, -P["thigh_length"], 0), None),
              ("foot_" + side, t + 1, (0, -P["shin_length"], 0), None),
              ("toe_" + side, t + 2, (0, -P["ankle_height"], P["foot_length"]), (0, 0, P["toe_length"]))]
    return j


JOINTS = skeleton()
INDEX = {name: i for i, (name, _, _, _) in enumerate(JOINTS)}


def smooth(x):
    """Smoothstep ease on [0, 1], clamped."""
    x = min(max(x, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)


def window(t, t0, t1, t2, t3):
    """0 before t0, eases up to 1 by t1, holds, eases back to 0 from t2 to t3."""
    if t < t1:
        return smooth((t - t0) / (t1 - t0))
    return 1.0 - smooth((t - t2) / (t3 - t2))


# Standing pose, degrees (z, x, y) per joint; LEG_BEND is its hip/knee/ankle angle.
STAND_PELVIS = 0.8425
LEG_BEND = math.radians(28.79)
STAND = {"spine_01": (0, -0.2865, 0), "spine_02": (0, -0.2865, 0), "spine_03": (0, -0.2865, 0),
         "neck": (0, 0.2865, 0), "head": (0, 0.2865, 0),
         "upperarm_l": (8.218, 14.744, -17.306), "forearm_l": (0, -35.606, 0),
         "upperarm_r": (-8.218, 14.744, 17.306), "forearm_r": (0, -35.606, 0),
         "thigh_l": (0, -28.429, 0), "shin_l": (0, 57.581, 0), "foot_l": (0, -29.152, 0),
         "thigh_r": (0, -28.429, 0), "shin_r": (0, 57.581, 0), "foot_r": (0, -29.152, 0)}


class Frame:
    """One pose: root position and per-joint (z, x, y) Euler angles in radians."""

    def __init__(self, t, duration):
        self.root = [0.0, P["pelvis_height"], 0.0]
        self.rot = {name: [0.0, 0.0, 0.0] for name, _, _, _ in JOINTS}
        # The gait's idle standing pose (runtime/gait/gait.cpp with the default [gait]
        # settings: pelvis 0.8425 m, knees soft, arms hanging forward and out; read
        # off `graph path --bvh` of the default graph's idle clip) with a slow
        # breath that starts and ends at zero over the clip.
        self.root[1] = STAND_PELVIS
        for name, (z, x, y) in STAND.items():
            self.add(name, z=math.radians(z), x=math.radians(x), y=math.radians(y))
        breath = math.sin(2.0 * math.pi * t / duration)
        self.root[1] += 0.004 * breath
        self.add("spine_02", x=-0.015 * breath)
        self.add("spine_03", x=-0.02 * breath)
        self.add("head", x=0.02 * breath)
        self.add("upperarm_l", z=0.01 * breath)
        self.add("upperarm_r", z=-0.01 * breath)

    def add(self, name, z=0.0, x=0.0, y=0.0):
        r = self.rot[name]
        r[0] += z
        r[1] += x
        r[2] += y


def wave(f, t, d):
    up = window(t, 0.1, 1.1, d - 1.1, d - 0.1)
    # Right arm rises out to the side and up, elbow bent; the forearm swings.
    f.add("clavicle_r", z=-0.15 * up)
    f.add("upperarm_r", z=-2.3 * up, x=-0.25 * up)
    swing = math.sin(2.0 * math.pi * 1.6 * (t - 1.1)) * window(t, 1.0, 1.3, d - 1.3, d - 1.0)
    f.add("forearm_r", z=-(0.5 + 0.4 * swing) * up, x=0.15 * up)
    f.add("hand_r", z=-0.25 * swing * up)
    # Secondary: the torso leans away a little, the head tilts toward the hand.
    f.add("spine_02", z=0.04 * up)
    f.add("spine_03", z=0.03 * up)
    f.add("head", z=-0.10 * up, y=-0.15 * up)
    f.add("upperarm_l", z=0.03 * up)


def bow(f, t, d):
    down = window(t, 0.2, 1.0, d - 1.1, d - 0.2)
    lag = window(t, 0.35, 1.15, d - 1.0, d - 0.1)  # the head follows a little late
    f.add("spine_01", x=0.25 * down)
    f.add("spine_02", x=0.25 * down)
    f.add("spine_03", x=0.2 * down)
    f.add("neck", x=0.15 * lag)
    f.add("head", x=0.2 * lag)
    # Hips back and knees soft to keep the balance; arms hang forward.
    f.root[2] -= 0.05 * down
    f.root[1] -= 0.01 * down
    for side in ("l", "r"):
        f.add("thigh_" + side, x=-0.12 * down)
        f.add("shin_" + side, x=0.06 * down)
        f.add("foot_" + side, x=0.06 * down)
        f.add("upperarm_" + side, x=-0.6 * lag)
        f.add("forearm_" + side, x=-0.1 * lag)


def leg_bend(f, a):
    """Knees bend 2a more, hips and ankles a more: feet stay flat under the pelvis."""
    legs = P["thigh_length"] + P["shin_length"]
    f.root[1] -= legs * (math.cos(LEG_BEND) - math.cos(LEG_BEND + a))
    for side in ("l", "r"):
        f.add("thigh_" + side, x=-a)
        f.add("shin_" + side, x=2.0 * a)
        f.add("foot_" + side, x=-a)
    f.add("spine_01", x=0.5 * a)


def jump(f, t, d):
    take_off, landing, height = 0.9, 1.35, 0.22
    crouch = 0.55 * window(t, 0.2, 0.75, 0.75, take_off) + 0.6 * window(t, landing, landing + 0.25, landing + 0.3, d - 0.2)
    leg_bend(f, crouch)
    if take_off < t < landing:
        u = (t - take_off) / (landing - take_off)
        f.root[1] += 4.0 * height * u * (1.0 - u)
        # Toes point in the air, legs tuck slightly at the top.
        tuck = math.sin(math.pi * u)
        for side in ("l", "r"):
            f.add("thigh_" + side, x=-0.25 * tuck)
            f.add("shin_" + side, x=0.4 * tuck)
            f.add("foot_" + side, x=0.35 * tuck)
    # Arms swing back in the crouch and forward-up through the flight.
    swing = -0.4 * window(t, 0.2, 0.7, 0.7, 1.0) + 1.1 * window(t, 0.7, 1.15, 1.3, 2.1)
    for side in ("l", "r"):
        f.add("upperarm_" + side, x=-swing)
    f.add("head", x=0.2 * crouch)


def look_around(f, t, d):
    # Head turns left, holds, sweeps right, returns; the neck and upper spine share it.
    turn = 0.9 * window(t, 0.2, 0.9, 1.2, 1.8) - 0.9 * window(t, 1.5, 2.2, 2.5, d - 0.2)
    lag = 0.9 * window(t, 0.3, 1.0, 1.3, 1.9) - 0.9 * window(t, 1.6, 2.3, 2.6, d - 0.1)
    f.add("head", y=0.5 * turn, x=-0.05 * abs(turn))
    f.add("neck", y=0.3 * lag)
    f.add("spine_03", y=0.2 * lag)
    f.add("spine_02", y=0.1 * lag)
    # Weight shifts a little toward the side looked at.
    f.root[0] += 0.02 * lag
    f.add("upperarm_l", z=-0.02 * lag)
    f.add("upperarm_r", z=-0.02 * lag)


CLIPS = {"wave": (3.0, wave), "bow": (2.6, bow), "jump": (2.4, jump), "look_around": (3.0, look_around)}


def bvh_text(duration, pose):
    frames = int(round(duration * RATE)) + 1
    out = ["HIERARCHY"]
    children = {i: [] for i in range(len(JOINTS))}
    for i, (_, parent, _, _) in enumerate(JOINTS):
        if parent >= 0:
            children[parent].append(i)

    def emit(i, depth):
        name, parent, off, end = JOINTS[i]
        pad = "  " * depth
        out.append(pad + ("ROOT " if parent < 0 else "JOINT ") + name)
        out.append(pad + "{")
        out.append(pad + "  OFFSET %.6f %.6f %.6f" % off)
        if parent < 0:
            out.append(pad + "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation")
        else:
            out.append(pad + "  CHANNELS 3 Zrotation Xrotation Yrotation")
        for c in children[i]:
            emit(c, depth + 1)
        if end is not None:
            out.append(pad + "  End Site")
            out.append(pad + "  {")
            out.append(pad + "    OFFSET %.6f %.6f %.6f" % end)
            out.append(pad + "  }")
        out.append(pad + "}")

    emit(0, 0)
    out.append("MOTION")
    out.append("Frames: %d" % frames)
    out.append("Frame Time: %.8f" % (1.0 / RATE))
    for k in range(frames):
        t = k / RATE
        f = Frame(t, duration)
        pose(f, t, duration)
        values = list(f.root)
        for name, _, _, _ in JOINTS:
            values += [math.degrees(a) for a in f.rot[name]]
        out.append(" ".join("%.4f" % (v + 0.0) for v in values))
    return "\n".join(out) + "\n"


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "config", "clips")
    os.makedirs(out_dir, exist_ok=True)
    for name, (duration, pose) in CLIPS.items():
        path = os.path.join(out_dir, name + ".bvh")
        with open(path, "w", newline="\n") as fh:
            fh.write(bvh_text(duration, pose))
        print("wrote", os.path.normpath(path))


if __name__ == "__main__":
    main()
