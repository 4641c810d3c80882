#!/usr/bin/env python3
"""Checks `marionette input monitor --json --raw` output against an evemu event
stream, independently of marionette's code: replays the stream's events frame by
frame (one expected sample per SYN_REPORT; SYN_DROPPED discards events up to the
next SYN_REPORT and resynchronises to the device's rest state, as umockdev's
ioctl records give it), normalises each axis from the stream's A: lines, and
compares every sample.

Usage: check_monitor.py EVENTS_FILE MONITOR_JSON_LINES
       check_monitor.py --expected-count EVENTS_FILE
"""
import json
import sys

ABS = {0x00: "lx", 0x01: "ly", 0x03: "rx", 0x04: "ry", 0x02: "lt", 0x05: "rt", 0x10: "hatx", 0x11: "haty"}
KEYS = {0x130: "south", 0x131: "east", 0x134: "west", 0x133: "north", 0x136: "left_shoulder",
        0x137: "right_shoulder", 0x13a: "back", 0x13b: "start", 0x13c: "guide", 0x13d: "left_stick",
        0x13e: "right_stick"}
ORDER = ["south", "east", "west", "north", "left_shoulder", "right_shoulder", "back", "start", "guide",
         "left_stick", "right_stick", "dpad_up", "dpad_down", "dpad_left", "dpad_right"]


def centred(v, lo, hi):
    c = lo + (hi - lo + 1) // 2
    v = min(max(v, lo), hi)
    span = hi - c if v >= c else c - lo
    return (v - c) / span


def expected(events_path):
    info, state, frames, rest = {}, {}, [], {}
    dropping = False
    for line in open(events_path):
        if line.startswith("A:"):
            code, lo, hi = (int(x, 16) if i == 0 else int(x) for i, x in enumerate(line.split()[1:4]))
            info[code] = (lo, hi)
            rest[code] = 0 if code in (0x02, 0x05, 0x10, 0x11) or lo < 0 else lo + (hi - lo + 1) // 2
            state[code] = rest[code]
        if not line.startswith("E:"):
            continue
        _, _, typ, code, value = line.split()[:5]
        typ, code, value = int(typ, 16), int(code, 16), int(value)
        if typ == 0 and code == 3:  # SYN_DROPPED
            dropping = True
            state = {c: v for c, v in rest.items()}
            state.update({k: 0 for k in KEYS})
            frames.append(dict(state))  # libevdev's resync frame
            continue
        if typ == 0 and code == 0:
            if dropping:
                dropping = False
                continue
            frames.append(dict(state))
            continue
        if dropping:
            continue
        state[code] = value
    out = []
    for st in frames:
        s = {}
        for code, name in ABS.items():
            lo, hi = info[code]
            v = st.get(code, rest[code])
            if name in ("lt", "rt"):
                s[name] = (min(max(v, lo), hi) - lo) / (hi - lo)
            elif name in ("lx", "rx"):
                s[name] = centred(v, lo, hi)
            elif name in ("ly", "ry"):
                s[name] = -centred(v, lo, hi)
            else:
                s[name] = v
        buttons = {KEYS[k] for k in KEYS if st.get(k)}
        if s["hatx"] < 0: buttons.add("dpad_left")
        if s["hatx"] > 0: buttons.add("dpad_right")
        if s["haty"] < 0: buttons.add("dpad_up")
        if s["haty"] > 0: buttons.add("dpad_down")
        s["buttons"] = [b for b in ORDER if b in buttons]
        out.append(s)
    return out


def main():
    if sys.argv[1] == "--expected-count":
        print(len(expected(sys.argv[2])))
        return 0
    events, monitor = sys.argv[1], sys.argv[2]
    want = expected(events)
    got = [json.loads(l) for l in open(monitor) if l.strip()]
    failures = []
    if len(got) != len(want):
        failures.append(f"{len(got)} samples, expected {len(want)} (one per SYN_REPORT frame, plus the resync)")
    for i, (g, w) in enumerate(zip(got, want)):
        for k in ("lx", "ly", "rx", "ry", "lt", "rt"):
            if abs(g[k] - w[k]) > 1e-6:
                failures.append(f"sample {i}: {k} = {g[k]}, expected {w[k]:.7f}")
        if g["buttons"] != w["buttons"]:
            failures.append(f"sample {i}: buttons {g['buttons']}, expected {w['buttons']}")
        if i > 0 and g["t_ns"] < got[i - 1]["t_ns"]:
            failures.append(f"sample {i}: t_ns goes backwards")
    for f in failures[:20]:
        print("FAILED:", f)
    print(f"{len(got)} samples checked against {len(want)} expected frames")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
