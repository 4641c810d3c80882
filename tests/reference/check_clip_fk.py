#!/usr/bin/env python3
"""Check `marionette clip fk` / `clip info` against the independent reference FK.

Usage:
  check_clip_fk.py --marionette PATH [--mocap-dir DIR] [--tolerance 1e-3]
  check_clip_fk.py --self-test [--mocap-dir DIR]

For every shared clip (cmu_bvh_131/*.bvh, edge/*.bvh, cmu_amc_16/*.amc with the
.asf of its folder) and a handful of frames (first, second, a third, middle,
last) it runs

  marionette clip fk FILE [--asf ASF] --frame N --json
  marionette clip info FILE [--asf ASF] --json

and compares, per joint, the world position with fk_reference.py to an absolute
tolerance (default 1e-3 file units, per component), the joint name set, the
parent of every joint (a name string or null; an integer index into the
"joints" array, with null or -1 for the root, is accepted and reported), the
joint count and the frame count.

Exit status: 0 all checks passed; 1 some check failed (a per-joint report is
printed); 2 bad usage (no executable, no data).
Python 3 standard library only.
"""

import argparse
import glob
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fk_reference as ref  # noqa: E402

MAX_REPORTED_JOINTS = 12  # mismatching joints listed per file and frame


def find_clips(mocap_dir):
    """[(label, clip path, asf path or None)] for every clip under mocap_dir."""
    clips = []
    for path in sorted(glob.glob(os.path.join(mocap_dir, "**", "*.bvh"), recursive=True)):
        clips.append((os.path.relpath(path, mocap_dir), path, None))
    for path in sorted(glob.glob(os.path.join(mocap_dir, "**", "*.amc"), recursive=True)):
        folder = os.path.dirname(path)
        asfs = sorted(glob.glob(os.path.join(folder, "*.asf")))
        stem = os.path.basename(path).split("_")[0]
        match = [a for a in asfs if os.path.splitext(os.path.basename(a))[0] == stem]
        asf = match[0] if match else (asfs[0] if len(asfs) == 1 else None)
        if asf is None:
            raise SystemExit("no ASF found for %s" % path)
        clips.append((os.path.relpath(path, mocap_dir), path, asf))
    return clips


def run_cli(marionette, args, timeout=60):
    """Run marionette; returns (parsed json or None, error text or None)."""
    cmd = [marionette] + args
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, "timed out after %ds: %s" % (timeout, " ".join(cmd))
    except OSError as e:
        return None, "cannot run %s: %s" % (marionette, e)
    out = p.stdout.decode("utf-8", "replace")
    err = p.stderr.decode("utf-8", "replace").strip()
    if p.returncode != 0:
        return None, "exit %d: %s\n      stderr: %s" % (p.returncode, " ".join(cmd), err[:2000])
    try:
        return json.loads(out), None
    except ValueError as e:
        return None, "stdout is not JSON (%s): %s\n      stdout starts: %r" % (
            e, " ".join(cmd), out[:300])


def _fmt(v):
    return "[" + ", ".join("%.6f" % x for x in v) + "]"


def _count(v):
    if isinstance(v, bool):
        return None
    if isinstance(v, int):
        return v
    if isinstance(v, list):
        return len(v)
    return None


class Checker:
    def __init__(self, marionette, tol):
        self.marionette = marionette
        self.tol = tol
        self.failures = 0
        self.checks = 0
        self.parent_forms = {}  # label -> set of forms seen
        self.worst = 0.0

    def fail(self, msg):
        self.failures += 1
        print("FAIL " + msg)

    def check_info(self, label, path, asf, clip):
        self.checks += 1
        args = ["clip", "info", path] + (["--asf", asf] if asf else []) + ["--json"]
        doc, err = run_cli(self.marionette, args)
        if err:
            self.fail("%s: clip info: %s" % (label, err))
            return
        if not isinstance(doc, dict):
            self.fail("%s: clip info: JSON is not an object" % label)
            return
        nj = _count(doc.get("joints"))
        nf = _count(doc.get("frames"))
        exp_j = len(clip.joint_names())
        exp_f = clip.frame_count
        if nj != exp_j:
            self.fail("%s: clip info joints = %r, reference %d" % (label, doc.get("joints"), exp_j))
        if nf != exp_f:
            self.fail("%s: clip info frames = %r, reference %d" % (label, doc.get("frames"), exp_f))
        ft = doc.get("frame_time")
        if isinstance(ft, (int, float)) and clip.frame_time is not None \
                and abs(ft - clip.frame_time) > 1e-6:
            self.fail("%s: clip info frame_time = %r, reference %r" % (label, ft, clip.frame_time))

    def check_fk(self, label, path, asf, clip, frame):
        self.checks += 1
        args = ["clip", "fk", path] + (["--asf", asf] if asf else []) + \
               ["--frame", str(frame), "--json"]
        doc, err = run_cli(self.marionette, args)
        where = "%s frame %d" % (label, frame)
        if err:
            self.fail("%s: clip fk: %s" % (where, err))
            return
        joints = doc.get("joints") if isinstance(doc, dict) else None
        if not isinstance(joints, list):
            self.fail("%s: clip fk JSON has no \"joints\" array" % where)
            return
        expect_pos = clip.positions(frame)
        expect_par = clip.parents()
        problems = []
        names = []
        for k, j in enumerate(joints):
            if not isinstance(j, dict) or not isinstance(j.get("name"), str):
                problems.append("joints[%d] has no string \"name\": %r" % (k, j))
                continue
            names.append(j["name"])
        if problems:
            for p in problems[:MAX_REPORTED_JOINTS]:
                self.fail("%s: %s" % (where, p))
            return
        # Joint set.
        dup = sorted({n for n in names if names.count(n) > 1})
        missing = [n for n in expect_pos if n not in names]
        extra = [n for n in names if n not in expect_pos]
        if dup:
            self.fail("%s: duplicate joint names: %s" % (where, ", ".join(dup)))
        if missing:
            self.fail("%s: %d joints missing from marionette output: %s"
                      % (where, len(missing), ", ".join(missing)))
        if extra:
            self.fail("%s: %d unexpected joints in marionette output: %s"
                      % (where, len(extra), ", ".join(extra)))
        # Parents and positions.
        forms = self.parent_forms.setdefault(label, set())
        bad_parent = []
        bad_pos = []
        for k, j in enumerate(joints):
            name = j["name"]
            if name not in expect_pos:
                continue
            par = j.get("parent", "<absent>")
            if par is None:
                forms.add("null")
                got_par = None
            elif isinstance(par, bool):
                got_par = "<bool %r>" % par
            elif isinstance(par, int):
                forms.add("index")
                if par == -1:
                    got_par = None
                elif 0 <= par < len(joints):
                    got_par = joints[par].get("name")
                else:
                    got_par = "<index %d out of range>" % par
            elif isinstance(par, str):
                forms.add("name")
                got_par = par
            else:
                got_par = "<%r>" % (par,)
            if got_par != expect_par[name]:
                bad_parent.append("%s: parent %r (as given: %r), reference %r"
                                  % (name, got_par, par, expect_par[name]))
            pos = j.get("position")
            if (not isinstance(pos, list) or len(pos) != 3
                    or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                               for x in pos)):
                bad_pos.append("%s: position is not [x,y,z]: %r" % (name, pos))
                continue
            e = expect_pos[name]
            d = max(abs(float(a) - b) for a, b in zip(pos, e))
            if d != d:  # NaN
                d = float("inf")
            self.worst = max(self.worst, d)
            if d > self.tol:
                diff = [float(a) - b for a, b in zip(pos, e)]
                bad_pos.append("%s: got %s reference %s diff %s (max %.3g)"
                               % (name, _fmt(pos), _fmt(e), _fmt(diff), d))
        if bad_parent:
            self.fail("%s: %d joints with a wrong parent:" % (where, len(bad_parent)))
            for line in bad_parent[:MAX_REPORTED_JOINTS]:
                print("      " + line)
            if len(bad_parent) > MAX_REPORTED_JOINTS:
                print("      ... and %d more" % (len(bad_parent) - MAX_REPORTED_JOINTS))
        if bad_pos:
            self.fail("%s: %d of %d joints off by more than %g:"
                      % (where, len(bad_pos), len(joints), self.tol))
            for line in bad_pos[:MAX_REPORTED_JOINTS]:
                print("      " + line)
            if len(bad_pos) > MAX_REPORTED_JOINTS:
                print("      ... and %d more" % (len(bad_pos) - MAX_REPORTED_JOINTS))


def main(argv=None):
    ap = argparse.ArgumentParser(description="Check marionette clip fk/info against "
                                 "the independent Python reference.")
    ap.add_argument("--marionette", help="path of the marionette executable")
    ap.add_argument("--mocap-dir", help="shared mocap folder (default: "
                    "$MARIONETTE_MOCAP_DIR, else <repo>/../shared/data/mocap)")
    ap.add_argument("--tolerance", type=float, default=1e-3,
                    help="absolute per-component position tolerance (default 1e-3)")
    ap.add_argument("--self-test", action="store_true",
                    help="check the reference itself (no marionette needed)")
    a = ap.parse_args(argv)
    mocap_dir = a.mocap_dir or ref.default_mocap_dir()

    if a.self_test:
        return 0 if ref.self_test(mocap_dir) else 1

    if not a.marionette:
        ap.error("--marionette PATH is required (or --self-test)")
    marionette = a.marionette
    if os.sep not in marionette and not os.path.exists(marionette):
        pass  # let PATH lookup happen in subprocess
    elif not (os.path.isfile(marionette) and os.access(marionette, os.X_OK)):
        print("error: %s is not an executable file" % marionette, file=sys.stderr)
        return 2
    if not os.path.isdir(mocap_dir):
        print("error: mocap dir not found: %s" % mocap_dir, file=sys.stderr)
        return 2

    t0 = time.time()
    clips = find_clips(mocap_dir)
    if not clips:
        print("error: no .bvh/.amc clips under %s" % mocap_dir, file=sys.stderr)
        return 2
    checker = Checker(marionette, a.tolerance)
    asf_cache = {}
    for label, path, asf in clips:
        if asf:
            if asf not in asf_cache:
                asf_cache[asf] = ref.AsfSkeleton(asf)
            clip = ref.AmcClip(path, asf_cache[asf])
        else:
            clip = ref.BvhClip(path)
        frames = ref.sample_frames(clip.frame_count)
        before = checker.failures
        checker.check_info(label, path, asf, clip)
        for fr in frames:
            checker.check_fk(label, path, asf, clip, fr)
        forms = ",".join(sorted(checker.parent_forms.get(label, ()))) or "-"
        print("%-4s %s: %d joints, %d frames, checked frames %s; parent given as: %s"
              % ("ok" if checker.failures == before else "BAD", label,
                 len(clip.joint_names()), clip.frame_count, frames, forms))
    all_forms = set()
    for f in checker.parent_forms.values():
        all_forms |= f
    print("%d clips, %d checks, %d failures; worst position difference %.3g "
          "(tolerance %g); parents given as %s; %.1fs"
          % (len(clips), checker.checks, checker.failures, checker.worst, a.tolerance,
             "/".join(sorted(all_forms)) or "-", time.time() - t0))
    return 0 if checker.failures == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
