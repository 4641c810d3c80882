#!/usr/bin/env python3
"""Independent reference forward kinematics for BVH and ASF/AMC clips.

Plain Python 3 standard library only (no numpy).  Deliberately written with
3x3 rotation matrices and Euler-angle products, NOT quaternions, so that it is
independent of the C++ implementation it checks.

Conventions
-----------
BVH
  * Angles are degrees.
  * Rotation channels compose in the order listed: ``Zrotation Xrotation
    Yrotation`` gives R = Rz . Rx . Ry acting on column vectors.
  * Position channels (on any joint) REPLACE the matching component of the
    joint's OFFSET; components without a position channel keep the OFFSET
    value.
  * World transform: T_world = T_parent_world . Translate(offset/positions) . R
  * End Sites are not joints (not reported).

ASF/AMC (Acclaim / CMU)
  * Joint "root" sits at the AMC root translation (file units, unscaled), with
    world rotation W_root = C_root . M_root . C_root^-1, C_root from the ASF
    ``:root`` ``orientation`` values in the ``axis`` order, M_root from the AMC
    root rotation values in ``:root order`` order.  The ASF root ``position``
    is not added (it is 0 0 0 in CMU files).
  * Each ASF bone is a joint of the same name located at the bone's START,
    i.e. at its parent bone's END (bones whose parent is root start at the
    root position).
  * C = rotation from ``axis a b c ORDER``: ORDER lists the axes in the order
    the rotations are applied (first letter first) and the values go with
    the letters positionally; ``XYZ`` gives C = Rz(c) . Ry(b) . Rx(a).
  * M = rotation from the AMC values for the bone's ``dof`` list, first listed
    applied first: ``rx ry rz`` gives M = Rz . Ry . Rx.  Bones without dofs
    (or absent from a frame) have M = I.  Translation dofs are ignored.
  * L = C . M . C^-1;  W_bone = W_parent . L;
    bone end = bone start + W_bone . (direction * length), with direction the
    ASF (global, rest-pose) direction.
  * Angle unit from ASF ``:units angle`` (deg default; an AMC ``:RADIANS``
    line also switches the AMC values to radians).  Lengths/positions are in
    file units (``:units length`` is ignored).
  * Frame index i (0-based) is the AMC frame numbered i+1.

Command line (for manual inspection):
  fk_reference.py FILE.bvh [--frame N]
  fk_reference.py FILE.amc --asf FILE.asf [--frame N]
prints JSON {"frames":..,"joints":[{"name","parent","position"}...]}.
"""

import json
import math
import os
import sys

# ---------------------------------------------------------------------------
# Small 3x3 matrix helpers (row-major lists of lists, column-vector convention)
# ---------------------------------------------------------------------------

IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def mat_mul(a, b):
    return tuple(
        tuple(a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] for j in range(3))
        for i in range(3)
    )


def mat_vec(a, v):
    return (
        a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2],
        a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2],
        a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2],
    )


def mat_transpose(a):
    return tuple(tuple(a[j][i] for j in range(3)) for i in range(3))


def vec_add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def vec_sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def vec_len(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def axis_rotation(axis, radians):
    """Right-handed rotation about a principal axis ('x', 'y' or 'z')."""
    c = math.cos(radians)
    s = math.sin(radians)
    if axis == "x":
        return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))
    if axis == "y":
        return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))
    if axis == "z":
        return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))
    raise ValueError("bad rotation axis %r" % axis)


def euler_applied_first_first(axes_and_radians):
    """Rotation that applies the listed rotations in order, first one first.

    [(x, a), (y, b), (z, c)] -> Rz(c) . Ry(b) . Rx(a)
    """
    m = IDENTITY
    for axis, ang in axes_and_radians:
        m = mat_mul(axis_rotation(axis, ang), m)
    return m


def euler_listed_order(axes_and_radians):
    """BVH composition: matrices multiplied in listed order.

    [(z, a), (x, b), (y, c)] -> Rz(a) . Rx(b) . Ry(c)
    """
    m = IDENTITY
    for axis, ang in axes_and_radians:
        m = mat_mul(m, axis_rotation(axis, ang))
    return m


def _read_lines(path, text=None):
    """Lines of a text file (or of `text`), tolerant of CRLF/LF/CR mixes."""
    if text is None:
        with open(path, "r", encoding="utf-8", errors="replace", newline="") as f:
            text = f.read()
    return text.splitlines()


# ---------------------------------------------------------------------------
# BVH
# ---------------------------------------------------------------------------


class BvhJoint:
    __slots__ = ("name", "parent", "offset", "channels", "channel_start", "children")

    def __init__(self, name, parent):
        self.name = name
        self.parent = parent  # index or None
        self.offset = (0.0, 0.0, 0.0)
        self.channels = []
        self.channel_start = 0
        self.children = []


class BvhClip:
    """Parsed BVH. joints: list of BvhJoint (End Sites excluded), file order."""

    kind = "bvh"

    def __init__(self, path, text=None):
        self.path = path
        self.joints = []
        self.end_sites = []  # (parent joint index, offset)
        self.num_channels = 0
        self.frame_time = None
        self.frames = []  # list of tuples of floats
        self._parse(path, text)

    # -- parsing ----------------------------------------------------------
    def _parse(self, path, text):
        lines = _read_lines(path, text)  # handles CRLF / LF / CR mixes
        i = 0
        n = len(lines)
        while i < n and lines[i].strip() == "":
            i += 1
        if i >= n or lines[i].split()[0] != "HIERARCHY":
            raise ValueError("%s: expected HIERARCHY" % path)
        i += 1
        # Hierarchy: token stream up to MOTION.
        tokens = []
        while i < n:
            s = lines[i].strip()
            if s.split()[:1] == ["MOTION"]:
                break
            tokens.extend(s.split())
            i += 1
        if i >= n:
            raise ValueError("%s: no MOTION section" % path)
        motion_line = i
        self._parse_hierarchy(tokens)
        # MOTION header.
        i = motion_line + 1
        frames = None
        while i < n:
            s = lines[i].strip()
            i += 1
            if not s:
                continue
            if s.startswith("Frames:"):
                frames = int(s[len("Frames:"):].strip())
            elif s.startswith("Frame Time:"):
                self.frame_time = float(s[len("Frame Time:"):].strip())
                break
            else:
                raise ValueError("%s: unexpected line in MOTION header: %r" % (path, s))
        if frames is None or self.frame_time is None:
            raise ValueError("%s: missing Frames / Frame Time" % path)
        values = []
        for line in lines[i:]:
            values.extend(line.split())
        nc = self.num_channels
        if len(values) < frames * nc:
            raise ValueError(
                "%s: %d values for %d frames x %d channels" % (path, len(values), frames, nc)
            )
        self.frames = [
            tuple(float(v) for v in values[k * nc:(k + 1) * nc]) for k in range(frames)
        ]

    def _parse_hierarchy(self, tokens):
        pos = 0
        stack = []  # joint index or -1 for End Site

        def expect(tok):
            nonlocal pos
            if pos >= len(tokens) or tokens[pos] != tok:
                got = tokens[pos] if pos < len(tokens) else "<eof>"
                raise ValueError("%s: expected %r, got %r" % (self.path, tok, got))
            pos += 1

        channel_count = 0
        while pos < len(tokens):
            t = tokens[pos]
            if t in ("ROOT", "JOINT"):
                name = tokens[pos + 1]
                pos += 2
                parent = stack[-1] if stack else None
                if parent == -1:
                    raise ValueError("%s: joint inside End Site" % self.path)
                if t == "ROOT" and stack:
                    raise ValueError("%s: nested ROOT" % self.path)
                j = BvhJoint(name, parent)
                idx = len(self.joints)
                self.joints.append(j)
                if parent is not None:
                    self.joints[parent].children.append(idx)
                expect("{")
                stack.append(idx)
            elif t == "End":
                expect("End")
                expect("Site")
                expect("{")
                stack.append(-1)
                self.end_sites.append([stack[-2], (0.0, 0.0, 0.0)])
            elif t == "OFFSET":
                off = tuple(float(x) for x in tokens[pos + 1:pos + 4])
                pos += 4
                if stack[-1] == -1:
                    self.end_sites[-1][1] = off
                else:
                    self.joints[stack[-1]].offset = off
            elif t == "CHANNELS":
                cnt = int(tokens[pos + 1])
                chans = tokens[pos + 2:pos + 2 + cnt]
                pos += 2 + cnt
                j = self.joints[stack[-1]]
                j.channels = [c.lower() for c in chans]
                j.channel_start = channel_count
                channel_count += cnt
                for c in j.channels:
                    if c not in ("xposition", "yposition", "zposition",
                                 "xrotation", "yrotation", "zrotation"):
                        raise ValueError("%s: unknown channel %r" % (self.path, c))
            elif t == "}":
                pos += 1
                stack.pop()
            else:
                raise ValueError("%s: unexpected token %r in HIERARCHY" % (self.path, t))
        if stack:
            raise ValueError("%s: unbalanced braces" % self.path)
        self.num_channels = channel_count

    # -- queries ----------------------------------------------------------
    @property
    def frame_count(self):
        return len(self.frames)

    def joint_names(self):
        return [j.name for j in self.joints]

    def parents(self):
        return {j.name: (self.joints[j.parent].name if j.parent is not None else None)
                for j in self.joints}

    def local_translation(self, j, values):
        t = list(j.offset)
        for k, c in enumerate(j.channels):
            if c.endswith("position"):
                t["xyz".index(c[0])] = values[j.channel_start + k]
        return tuple(t)

    def local_rotation(self, j, values):
        rots = []
        for k, c in enumerate(j.channels):
            if c.endswith("rotation"):
                rots.append((c[0], math.radians(values[j.channel_start + k])))
        return euler_listed_order(rots)

    def world(self, frame):
        """Return list of (rotation, position) per joint for a 0-based frame."""
        if not 0 <= frame < len(self.frames):
            raise IndexError("frame %d out of range (0..%d)" % (frame, len(self.frames) - 1))
        values = self.frames[frame]
        out = []
        for j in self.joints:  # parents always precede children in file order
            t = self.local_translation(j, values)
            r = self.local_rotation(j, values)
            if j.parent is None:
                out.append((r, t))
            else:
                pr, pp = out[j.parent]
                out.append((mat_mul(pr, r), vec_add(pp, mat_vec(pr, t))))
        return out

    def positions(self, frame):
        w = self.world(frame)
        return {j.name: list(w[k][1]) for k, j in enumerate(self.joints)}


# ---------------------------------------------------------------------------
# ASF / AMC
# ---------------------------------------------------------------------------


class AsfBone:
    __slots__ = ("name", "direction", "length", "axis_values", "axis_order",
                 "dof", "parent", "children", "C", "Cinv")

    def __init__(self, name):
        self.name = name
        self.direction = (0.0, 0.0, 0.0)
        self.length = 0.0
        self.axis_values = (0.0, 0.0, 0.0)
        self.axis_order = "XYZ"
        self.dof = []
        self.parent = None  # bone name or "root"
        self.children = []
        self.C = IDENTITY
        self.Cinv = IDENTITY


def _axis_matrix(values, order, to_rad):
    order = order.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise ValueError("bad axis order %r" % order)
    return euler_applied_first_first(
        [(order[k].lower(), values[k] * to_rad) for k in range(3)])


class AsfSkeleton:
    def __init__(self, path, text=None):
        self.path = path
        self.angle_unit = "deg"
        self.length_unit = 1.0
        self.root_order = ["tx", "ty", "tz", "rx", "ry", "rz"]
        self.root_axis_order = "XYZ"
        self.root_position = (0.0, 0.0, 0.0)
        self.root_orientation = (0.0, 0.0, 0.0)
        self.bones = {}  # name -> AsfBone (insertion = file order)
        self.root_children = []
        self._parse(path, text)

    def _parse(self, path, text):
        lines = _read_lines(path, text)
        section = None
        bone = None
        in_hier = False
        for raw in lines:
            s = raw.strip()
            if not s or s.startswith("#"):
                continue
            tok = s.split()
            if tok[0].startswith(":"):
                section = tok[0].lower()
                if section in (":name", ":version"):
                    section = None
                continue
            if section == ":units":
                if tok[0] == "angle":
                    self.angle_unit = tok[1].lower()
                elif tok[0] == "length":
                    self.length_unit = float(tok[1])
            elif section == ":root":
                key = tok[0].lower()
                if key == "order":
                    self.root_order = [t.lower() for t in tok[1:]]
                elif key == "axis":
                    self.root_axis_order = tok[1].upper()
                elif key == "position":
                    self.root_position = tuple(float(x) for x in tok[1:4])
                elif key == "orientation":
                    self.root_orientation = tuple(float(x) for x in tok[1:4])
            elif section == ":bonedata":
                key = tok[0].lower()
                if key == "begin":
                    bone = AsfBone(None)
                elif key == "end":
                    if bone is None or bone.name is None:
                        raise ValueError("%s: bone without name" % path)
                    self.bones[bone.name] = bone
                    bone = None
                elif bone is None:
                    raise ValueError("%s: %r outside begin/end" % (path, s))
                elif key == "name":
                    bone.name = tok[1]
                elif key == "direction":
                    bone.direction = tuple(float(x) for x in tok[1:4])
                elif key == "length":
                    bone.length = float(tok[1])
                elif key == "axis":
                    bone.axis_values = tuple(float(x) for x in tok[1:4])
                    bone.axis_order = tok[4].upper() if len(tok) > 4 else "XYZ"
                elif key == "dof":
                    bone.dof = [t.lower() for t in tok[1:]]
                # id, limits, "(..)" continuation lines, bodymass, cofmass: ignored
            elif section == ":hierarchy":
                key = tok[0].lower()
                if key == "begin":
                    in_hier = True
                    continue
                if key == "end":
                    in_hier = False
                    continue
                if not in_hier:
                    continue
                parent = tok[0]
                for child in tok[1:]:
                    if child not in self.bones:
                        raise ValueError("%s: hierarchy names unknown bone %r" % (path, child))
                    if parent != "root" and parent not in self.bones:
                        raise ValueError("%s: hierarchy names unknown bone %r" % (path, parent))
                    self.bones[child].parent = parent
                    if parent == "root":
                        self.root_children.append(child)
                    else:
                        self.bones[parent].children.append(child)
        to_rad = self.to_rad
        for b in self.bones.values():
            if b.parent is None:
                raise ValueError("%s: bone %r not in hierarchy" % (self.path, b.name))
            b.C = _axis_matrix(b.axis_values, b.axis_order, to_rad)
            b.Cinv = mat_transpose(b.C)
        self.root_C = _axis_matrix(self.root_orientation, self.root_axis_order, to_rad)
        self.root_Cinv = mat_transpose(self.root_C)

    @property
    def to_rad(self):
        return math.pi / 180.0 if self.angle_unit.startswith("deg") else 1.0

    def order_dfs(self):
        """Bone names in depth-first hierarchy order."""
        out = []

        def visit(name):
            out.append(name)
            for c in self.bones[name].children:
                visit(c)

        for c in self.root_children:
            visit(c)
        return out


class AmcClip:
    """ASF skeleton + AMC motion."""

    kind = "amc"

    def __init__(self, amc_path, asf, text=None):
        if not isinstance(asf, AsfSkeleton):
            asf = AsfSkeleton(asf)
        self.path = amc_path
        self.asf = asf
        self.frame_time = None  # AMC has no rate field
        self.amc_radians = False
        self.frames = []  # list of dict bone -> tuple of floats
        self._parse(amc_path, text)

    def _parse(self, path, text):
        lines = _read_lines(path, text)
        numbers = []
        cur = None
        for raw in lines:
            s = raw.strip()
            if not s or s.startswith("#"):
                continue
            if s.startswith(":"):
                if s.upper().startswith(":RADIANS"):
                    self.amc_radians = True
                continue
            tok = s.split()
            if len(tok) == 1 and tok[0].isdigit():
                cur = {}
                self.frames.append(cur)
                numbers.append(int(tok[0]))
                continue
            if cur is None:
                raise ValueError("%s: data before first frame number: %r" % (path, s))
            cur[tok[0]] = tuple(float(x) for x in tok[1:])
        if numbers != list(range(1, len(numbers) + 1)):
            raise ValueError("%s: frame numbers are not 1..N" % path)

    @property
    def frame_count(self):
        return len(self.frames)

    def joint_names(self):
        return ["root"] + self.asf.order_dfs()

    def parents(self):
        p = {"root": None}
        for name in self.asf.order_dfs():
            p[name] = self.asf.bones[name].parent
        return p

    def _to_rad(self):
        if self.amc_radians:
            return 1.0
        return self.asf.to_rad

    def root_transform(self, frame):
        asf = self.asf
        vals = self.frames[frame].get("root")
        if vals is None:
            raise ValueError("%s: frame %d has no root line" % (self.path, frame + 1))
        to_rad = self._to_rad()
        pos = [0.0, 0.0, 0.0]
        rots = []
        for k, ch in enumerate(asf.root_order):
            if k >= len(vals):
                break
            if ch in ("tx", "ty", "tz"):
                pos["xyz".index(ch[1])] = vals[k]
            elif ch in ("rx", "ry", "rz"):
                rots.append((ch[1], vals[k] * to_rad))
        m = euler_applied_first_first(rots)
        w = mat_mul(mat_mul(asf.root_C, m), asf.root_Cinv)
        return w, tuple(pos)

    def bone_motion(self, bone, frame):
        vals = self.frames[frame].get(bone.name)
        if vals is None or not bone.dof:
            return IDENTITY
        to_rad = self._to_rad()
        rots = []
        for k, d in enumerate(bone.dof):
            if k >= len(vals):
                break
            if d in ("rx", "ry", "rz"):
                rots.append((d[1], vals[k] * to_rad))
        return euler_applied_first_first(rots)

    def world(self, frame):
        """dict name -> (start, end, world_rotation); root has start == end."""
        if not 0 <= frame < len(self.frames):
            raise IndexError("frame %d out of range (0..%d)" % (frame, len(self.frames) - 1))
        asf = self.asf
        w_root, p_root = self.root_transform(frame)
        out = {"root": (p_root, p_root, w_root)}

        def visit(name, parent_w, start):
            b = asf.bones[name]
            local = mat_mul(mat_mul(b.C, self.bone_motion(b, frame)), b.Cinv)
            w = mat_mul(parent_w, local)
            d = b.direction
            end = vec_add(start, mat_vec(w, (d[0] * b.length, d[1] * b.length, d[2] * b.length)))
            out[name] = (start, end, w)
            for c in b.children:
                visit(c, w, end)

        for c in asf.root_children:
            visit(c, w_root, p_root)
        return out

    def positions(self, frame):
        w = self.world(frame)
        return {name: list(w[name][0]) for name in self.joint_names()}


# ---------------------------------------------------------------------------
# Convenience
# ---------------------------------------------------------------------------


def load_clip(path, asf=None):
    """Load a .bvh, or a .amc with its ASF (path or AsfSkeleton)."""
    low = path.lower()
    if low.endswith(".bvh"):
        return BvhClip(path)
    if low.endswith(".amc"):
        if asf is None:
            raise ValueError("%s: an ASF skeleton is required for AMC" % path)
        return AmcClip(path, asf)
    raise ValueError("%s: unknown clip format" % path)


def reference_positions(path, frame, asf=None):
    """dict joint name -> [x, y, z] world position at 0-based frame."""
    return load_clip(path, asf).positions(frame)


# ---------------------------------------------------------------------------
# Self-test
# ---------------------------------------------------------------------------

# Expected facts about the shared data (from its README).
EXPECTED_BVH = {
    "cmu_bvh_131/131_01.bvh": (31, 994, 1.0 / 120.0),
    "cmu_bvh_131/131_02.bvh": (31, 1247, 1.0 / 120.0),
    "cmu_bvh_131/131_03.bvh": (31, 1102, 1.0 / 120.0),
    "edge/mixamo_55_joints.bvh": (55, 69, 1.0 / 30.0),
}
EXPECTED_AMC = {  # 16.asf: root + 30 bones
    "16_11": 534, "16_15": 471, "16_17": 518, "16_19": 410, "16_33": 285,
    "16_35": 162, "16_41": 160, "16_43": 210, "16_57": 268,
}
WALKS_BVH = ["cmu_bvh_131/131_01.bvh", "cmu_bvh_131/131_02.bvh"]
WALKS_AMC = ["16_11", "16_15", "16_17", "16_19", "16_33"]


def default_mocap_dir():
    env = os.environ.get("MARIONETTE_MOCAP_DIR")
    if env:
        return env
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    return os.path.join(os.path.dirname(repo), "shared", "data", "mocap")


def sample_frames(n):
    """First, second, a third of the way, middle, last (0-based, unique)."""
    return sorted({0, min(1, n - 1), n // 3, n // 2, n - 1})


def _close(a, b, tol):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def _det(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def _rodrigues(axis_letter, degrees):
    """Rotation by Rodrigues' formula (independent of axis_rotation)."""
    u = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}[axis_letter]
    t = math.radians(degrees)
    c, s_, k = math.cos(t), math.sin(t), 1.0 - math.cos(t)
    x, y, z = u
    return ((c + k * x * x, k * x * y - s_ * z, k * x * z + s_ * y),
            (k * y * x + s_ * z, c + k * y * y, k * y * z - s_ * x),
            (k * z * x - s_ * y, k * z * y + s_ * x, c + k * z * z))


def _mat4_bvh_positions(clip, frame):
    """Second formulation of BVH FK: 4x4 homogeneous matrices, one per channel
    (Translate for a position channel, Rodrigues rotation for a rotation
    channel) multiplied in listed order."""
    values = clip.frames[frame]
    world = []
    for j in clip.joints:
        t = list(j.offset)
        for k, c in enumerate(j.channels):
            if c.endswith("position"):
                t["xyz".index(c[0])] = values[j.channel_start + k]
        local = [[1.0, 0.0, 0.0, t[0]], [0.0, 1.0, 0.0, t[1]],
                 [0.0, 0.0, 1.0, t[2]], [0.0, 0.0, 0.0, 1.0]]
        for k, c in enumerate(j.channels):
            if c.endswith("rotation"):
                r = _rodrigues(c[0], values[j.channel_start + k])
                m = [list(r[0]) + [0.0], list(r[1]) + [0.0], list(r[2]) + [0.0],
                     [0.0, 0.0, 0.0, 1.0]]
                local = [[sum(local[i][q] * m[q][cc] for q in range(4)) for cc in range(4)]
                         for i in range(4)]
        if j.parent is None:
            world.append(local)
        else:
            p = world[j.parent]
            world.append([[sum(p[i][q] * local[q][cc] for q in range(4)) for cc in range(4)]
                          for i in range(4)])
    return {j.name: [world[k][0][3], world[k][1][3], world[k][2][3]]
            for k, j in enumerate(clip.joints)}


def _zyx_closed_form(ax, ay, az):
    """Rz(az) . Ry(ay) . Rx(ax) written out in closed form (degrees)."""
    a, b, c = math.radians(ax), math.radians(ay), math.radians(az)
    sa, ca, sb, cb, sc, cc = math.sin(a), math.cos(a), math.sin(b), math.cos(b), math.sin(c), math.cos(c)
    return ((cb * cc, sa * sb * cc - ca * sc, ca * sb * cc + sa * sc),
            (cb * sc, sa * sb * sc + ca * cc, ca * sb * sc - sa * cc),
            (-sb, sa * cb, ca * cb))


def _local_frame_amc_positions(clip, frame):
    """Second formulation of ASF/AMC FK in the style of the CMU/Barbic viewer:
    bone-local frames, F_root = C_root M_root, F_b = F_parent (C_parent^-1 C_b) M_b,
    end_b = start_b + F_b (C_b^-1 direction) length, with every C and M built
    as the closed-form Rz.Ry.Rx from values picked by axis name (only valid
    for XYZ axis orders and degrees, which is what CMU files use)."""
    asf = clip.asf
    vals = clip.frames[frame]["root"]
    named = dict(zip(asf.root_order, vals))
    p_root = (named.get("tx", 0.0), named.get("ty", 0.0), named.get("tz", 0.0))
    c_root = _zyx_closed_form(*asf.root_orientation)
    f_root = mat_mul(c_root, _zyx_closed_form(named.get("rx", 0.0), named.get("ry", 0.0),
                                               named.get("rz", 0.0)))
    out = {"root": list(p_root)}

    def visit(name, parent_f, parent_cinv, start):
        b = asf.bones[name]
        c = _zyx_closed_form(*b.axis_values)
        cinv = mat_transpose(c)
        dv = dict(zip(b.dof, clip.frames[frame].get(name, ())))
        m = _zyx_closed_form(dv.get("rx", 0.0), dv.get("ry", 0.0), dv.get("rz", 0.0))
        f = mat_mul(mat_mul(parent_f, mat_mul(parent_cinv, c)), m)
        step = mat_vec(f, mat_vec(cinv, b.direction))
        end = vec_add(start, (step[0] * b.length, step[1] * b.length, step[2] * b.length))
        out[name] = list(start)
        for ch in b.children:
            visit(ch, f, cinv, end)

    for ch in asf.root_children:
        visit(ch, f_root, mat_transpose(c_root), p_root)
    return out


_SYNTH_BVH = """HIERARCHY
ROOT A
{
\tOFFSET 5 5 5
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT B
\t{
\t\tOFFSET 0 1 0
\t\tCHANNELS 3 Xrotation Zrotation Yrotation
\t\tJOINT C
\t\t{
\t\t\tOFFSET 0 1 0
\t\t\tCHANNELS 4 Yposition Zrotation Xrotation Yrotation
\t\t\tEnd Site
\t\t\t{
\t\t\t\tOFFSET 0 0 1
\t\t\t}
\t\t}
\t}
}
MOTION
Frames: 1
Frame Time: .5
1 2 3 90 90 0 90 90 0 7 0 0 0
"""

_SYNTH_ASF = """:version 1.10
:name T
:units
  length 0.45
  angle deg
:documentation
  anything here
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name a
     direction 1 0 0
     length 2
     axis 0 0 90 XYZ
    dof rx
    limits (-180 180)
  end
  begin
     id 2
     name b
     direction 0 1 0
     length 1
     axis 0 0 0 XYZ
    dof rx rz
    limits (-180 180)
           (-180 180)
  end
  begin
     id 3
     name c
     direction 0 1 0
     length 1
     axis 0 0 0 XYZ
    dof rz rx
    limits (-180 180)
           (-180 180)
  end
:hierarchy
  begin
    root a
    a b
    b c
  end
"""

_SYNTH_AMC = """:FULLY-SPECIFIED
:DEGREES
1
root 10 20 30 0 0 0
a 90
b 90 90
c 90 90
"""


def _synthetic_checks(report):
    ok = True
    # BVH: listed-order composition, position channels replace OFFSET.
    clip = BvhClip("<synthetic.bvh>", _SYNTH_BVH)
    pos = clip.positions(0)
    # A: position channels (1,2,3) replace OFFSET (5,5,5).
    # A rot = Rz(90) Rx(90); B offset (0,1,0) -> Rz90 Rx90 (0,1,0) = (0,0,1).
    # B rot (local) = Rx(90) Rz(90); world = Rz90 Rx90 Rx90 Rz90.
    # C: Yposition 7 replaces offset y -> local t = (0,7,0);
    #    Rx90 Rz90 (0,7,0) = Rx90 (-7,0,0) = (-7,0,0); Rz90 Rx90 (-7,0,0) = (0,-7,0).
    expect = {"A": [1, 2, 3], "B": [1, 2, 4], "C": [1, -5, 4]}
    for name, e in expect.items():
        if not _close(pos[name], e, 1e-9):
            ok = False
            report("FAIL synthetic BVH %s: got %s expected %s" % (name, pos[name], e))
    # ASF/AMC: L = C M C^-1 and dof order.
    asf = AsfSkeleton("<synthetic.asf>", _SYNTH_ASF)
    amc = AmcClip("<synthetic.amc>", asf, _SYNTH_AMC)
    pos = amc.positions(0)
    # a: C = Rz90, M = Rx90 -> L = rotation of 90 deg about C x = +y  (Ry90).
    #    end_a = root + Ry90 (2,0,0) = root + (0,0,-2).
    # b: starts at end_a; W_b = Ry90 . Rz90 Rx90; Rz90 Rx90 (0,1,0) = (0,0,1);
    #    Ry90 (0,0,1) = (1,0,0) -> end_b = end_a + (1,0,0).
    expect = {"root": [10, 20, 30], "a": [10, 20, 30], "b": [10, 20, 28], "c": [11, 20, 28]}
    for name, e in expect.items():
        if not _close(pos[name], e, 1e-9):
            ok = False
            report("FAIL synthetic ASF/AMC %s: got %s expected %s" % (name, pos[name], e))
    # c: W_c = W_b . Rx90 Rz90; Rx90 Rz90 (0,1,0) = Rx90 (-1,0,0) = (-1,0,0);
    #    W_b (-1,0,0): Rz90 Rx90 (-1,0,0) = (0,-1,0); Ry90 (0,-1,0) = (0,-1,0).
    end_c = amc.world(0)["c"][1]
    if not _close(end_c, [11, 19, 28], 1e-9):
        ok = False
        report("FAIL synthetic ASF/AMC end of c: got %s expected [11, 19, 28]" % (list(end_c),))
    report("synthetic BVH/ASF/AMC convention checks: %s" % ("ok" if ok else "FAILED"))
    return ok


def self_test(mocap_dir=None, report=print):
    """Internal consistency checks on the shared data; returns True if all pass."""
    mocap_dir = mocap_dir or default_mocap_dir()
    ok = _synthetic_checks(report)
    if not os.path.isdir(mocap_dir):
        report("FAIL mocap dir not found: %s" % mocap_dir)
        return False
    report("mocap dir: %s" % mocap_dir)

    def fail(msg):
        nonlocal ok
        ok = False
        report("FAIL " + msg)

    # ---- BVH ----
    for rel, (nj, nf, ft) in EXPECTED_BVH.items():
        path = os.path.join(mocap_dir, rel)
        clip = BvhClip(path)
        report("%s: %d joints, %d frames, frame time %r, %d end sites"
               % (rel, len(clip.joints), clip.frame_count, clip.frame_time, len(clip.end_sites)))
        if len(clip.joints) != nj:
            fail("%s: %d joints, expected %d" % (rel, len(clip.joints), nj))
        if clip.frame_count != nf:
            fail("%s: %d frames, expected %d" % (rel, clip.frame_count, nf))
        if abs(clip.frame_time - ft) > 1e-6:
            fail("%s: frame time %r, expected %r" % (rel, clip.frame_time, ft))
        if len(set(clip.joint_names())) != len(clip.joints):
            fail("%s: duplicate joint names" % rel)
        worst_len = 0.0
        worst_alt = 0.0
        worst_det = 0.0
        for fr in sample_frames(clip.frame_count):
            world = clip.world(fr)
            pos = {j.name: world[k][1] for k, j in enumerate(clip.joints)}
            for k, j in enumerate(clip.joints):
                worst_det = max(worst_det, abs(_det(world[k][0]) - 1.0))
                if j.parent is None or any(c.endswith("position") for c in j.channels):
                    continue
                d = vec_len(vec_sub(pos[j.name], pos[clip.joints[j.parent].name]))
                worst_len = max(worst_len, abs(d - vec_len(j.offset)))
            alt = _mat4_bvh_positions(clip, fr)
            for name, p in alt.items():
                worst_alt = max(worst_alt, max(abs(a - b) for a, b in zip(p, pos[name])))
        report("  bone lengths preserved on frames %s: max |error| %.3g; "
               "4x4 formulation agrees to %.3g; max |det R - 1| %.3g"
               % (sample_frames(clip.frame_count), worst_len, worst_alt, worst_det))
        if worst_len > 1e-6 or worst_alt > 1e-9 or worst_det > 1e-9:
            fail("%s: internal consistency" % rel)
    for rel in WALKS_BVH:
        clip = BvhClip(os.path.join(mocap_dir, rel))
        pos = clip.positions(0)
        feet = {n: p for n, p in pos.items() if any(s in n for s in ("Ankle", "Toe", "Foot"))}
        # End sites of the toes are lower still; include them.
        w = clip.world(0)
        for parent, off in clip.end_sites:
            name = clip.joints[parent].name
            if "Toe" in name:
                r, p = w[parent]
                feet[name + "/End"] = list(vec_add(p, mat_vec(r, off)))
        lowest = min(feet.items(), key=lambda kv: kv[1][1])
        hips = pos[clip.joints[0].name][1]
        report("  %s frame 0: hips y %.3f, lowest foot point %s y %.3f"
               % (rel, hips, lowest[0], lowest[1][1]))
        if not abs(lowest[1][1]) < 0.1 * hips:
            fail("%s: feet not near the floor at frame 0" % rel)

    # ---- ASF/AMC ----
    amc_dir = os.path.join(mocap_dir, "cmu_amc_16")
    asf = AsfSkeleton(os.path.join(amc_dir, "16.asf"))
    report("16.asf: %d bones, angle unit %s, length unit %g (ignored), root order %s"
           % (len(asf.bones), asf.angle_unit, asf.length_unit, " ".join(asf.root_order)))
    worst_unit = max(abs(vec_len(b.direction) - 1.0) for b in asf.bones.values())
    report("  max | |direction| - 1 | over bones: %.3g (directions are used as given)" % worst_unit)
    if len(asf.bones) != 30:
        fail("16.asf: %d bones, expected 30" % len(asf.bones))
    for stem, nf in EXPECTED_AMC.items():
        clip = AmcClip(os.path.join(amc_dir, stem + ".amc"), asf)
        names = clip.joint_names()
        worst_len = 0.0
        worst_alt = 0.0
        worst_det = 0.0
        for fr in sample_frames(clip.frame_count):
            world = clip.world(fr)
            for name in asf.bones:
                start, end, rot = world[name]
                b = asf.bones[name]
                # direction is used as given (not renormalised), like the CMU
                # readers do; CMU directions are unit to ~1e-7.
                expect_len = b.length * vec_len(b.direction)
                worst_det = max(worst_det, abs(_det(rot) - 1.0))
                worst_len = max(worst_len, abs(vec_len(vec_sub(end, start)) - expect_len))
                for c in b.children:
                    d = vec_len(vec_sub(world[c][0], start))
                    worst_len = max(worst_len, abs(d - expect_len))
            for c in asf.root_children:
                worst_len = max(worst_len, vec_len(vec_sub(world[c][0], world["root"][0])))
            alt = _local_frame_amc_positions(clip, fr)
            for name in names:
                worst_alt = max(worst_alt, max(abs(a - b) for a, b in zip(alt[name], world[name][0])))
        report("%s.amc: %d joints, %d frames; bone lengths on frames %s: max |error| %.3g; "
               "local-frame formulation agrees to %.3g; max |det W - 1| %.3g"
               % (stem, len(names), clip.frame_count, sample_frames(clip.frame_count),
                  worst_len, worst_alt, worst_det))
        if len(names) != 31:
            fail("%s: %d joints, expected 31" % (stem, len(names)))
        if clip.frame_count != nf:
            fail("%s: %d frames, expected %d" % (stem, clip.frame_count, nf))
        if worst_len > 1e-6 or worst_alt > 1e-9 or worst_det > 1e-9:
            fail("%s: internal consistency" % stem)
        if stem in WALKS_AMC:
            world = clip.world(0)
            feet = {n: world[n][0] for n in ("lfoot", "ltoes", "rfoot", "rtoes")}
            feet["ltoes/end"] = world["ltoes"][1]
            feet["rtoes/end"] = world["rtoes"][1]
            lowest = min(feet.items(), key=lambda kv: kv[1][1])
            rooty = world["root"][0][1]
            report("  frame 0: root y %.3f, lowest foot point %s y %.3f"
                   % (rooty, lowest[0], lowest[1][1]))
            if not abs(lowest[1][1]) < 0.1 * rooty:
                fail("%s: feet not near the floor at frame 0" % stem)
    report("self-test: %s" % ("PASSED" if ok else "FAILED"))
    return ok


def _main(argv):
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file", nargs="?")
    ap.add_argument("--asf")
    ap.add_argument("--frame", type=int, default=0)
    ap.add_argument("--self-test", action="store_true",
                    help="run internal consistency checks on the shared mocap data")
    ap.add_argument("--mocap-dir", help="for --self-test (default: $MARIONETTE_MOCAP_DIR "
                    "or <repo>/../shared/data/mocap)")
    a = ap.parse_args(argv)
    if a.self_test:
        return 0 if self_test(a.mocap_dir) else 1
    if not a.file:
        ap.error("FILE is required")
    clip = load_clip(a.file, a.asf)
    pos = clip.positions(a.frame)
    par = clip.parents()
    doc = {
        "frames": clip.frame_count,
        "frame_time": clip.frame_time,
        "joints": [{"name": n, "parent": par[n], "position": pos[n]} for n in clip.joint_names()],
    }
    json.dump(doc, sys.stdout, indent=1)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
