#!/usr/bin/env python3
"""Did the puppet move as the stick program says? Compares the root's travel
in a run's trace (tick,hash,root_x,root_y,root_z) with a reference trace of the
same program played by the simulated controller (`run --fast --input sim:`).

Travel is cut into legs at the given seconds (e.g. where a pad was unplugged):
leg i runs from cut i-1 (or the first tick) to cut i (or the last tick). For
each leg with a reference travel of at least 0.5 m the run's travel must point
the same way (within --max-angle degrees on the ground plane) and be between
--min-ratio (0.6) and --max-ratio (3) of the reference's length. A device run
travels further on a loaded machine: umockdev sleeps before each report it
plays, every sleep overshoots, so the program runs slower than real time and a
held stick is held longer (hidapi legs at 250 Hz measured 1.16-2.16x under a
load average of 16-20). Less was
seen twice in about a dozen runs under that load, both 0.70x (1.07 m of 1.53,
once evdev, once SDL2), not reproduced in three reruns and not explained.

Usage: check_walk.py RUN.csv REF.csv [--cuts S,S...] [--ref-cuts S,S...] [--ref-legs N] [--rate HZ]
"""
import argparse
import csv
import math
import sys


def positions(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [(float(r["root_x"]), float(r["root_z"])) for r in rows]


def legs(pos, cuts, rate):
    ends = [min(len(pos) - 1, max(0, int(round(c * rate)) - 1)) for c in cuts] + [len(pos) - 1]
    out, start = [], 0
    for end in ends:
        out.append((pos[end][0] - pos[start][0], pos[end][1] - pos[start][1]))
        start = end
    return out


def seconds_list(text):
    return [float(s) for s in text.split(",") if s] if text else []


def main():
    p = argparse.ArgumentParser()
    p.add_argument("run")
    p.add_argument("ref")
    p.add_argument("--cuts", default="")
    p.add_argument("--ref-cuts", default="")
    p.add_argument("--rate", type=int, default=240)
    p.add_argument("--max-angle", type=float, default=10.0)
    p.add_argument("--min-ratio", type=float, default=0.6)
    p.add_argument("--max-ratio", type=float, default=3.0)
    p.add_argument("--ref-legs", type=int, default=0, help="compare with only the reference's first N legs")
    a = p.parse_args()
    run = legs(positions(a.run), seconds_list(a.cuts), a.rate)
    ref = legs(positions(a.ref), seconds_list(a.ref_cuts), a.rate)
    if a.ref_legs:
        ref = ref[:a.ref_legs]
    if len(run) != len(ref):
        print(f"{len(run)} legs in the run, {len(ref)} in the reference")
        return 1
    ok = True
    for i, ((x, z), (rx, rz)) in enumerate(zip(run, ref)):
        length, ref_length = math.hypot(x, z), math.hypot(rx, rz)
        if ref_length < 0.5:
            print(f"leg {i + 1}: reference travels {ref_length:.2f} m; run {length:.2f} m (not compared)")
            continue
        angle = abs(math.degrees(math.atan2(x * rz - z * rx, x * rx + z * rz))) if length > 0 else 180.0
        ratio = length / ref_length
        good = angle <= a.max_angle and a.min_ratio <= ratio <= a.max_ratio
        ok = ok and good
        print(f"leg {i + 1}: run ({x:+.2f}, {z:+.2f}) m, reference ({rx:+.2f}, {rz:+.2f}) m: "
              f"{angle:.1f}° apart, {ratio:.2f}× as far: {'ok' if good else 'WRONG'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
