#!/usr/bin/env python3
"""Turns what `marionette sim-pad` writes into a umockdev script (the format of
umockdev-record --script: one "r DELAY_MS DATA" line per read the device
answers), so that umockdev plays it through an emulated device node:

  hid:   a file of concatenated fixed-size HID reports (--report-size, --rate),
         one read per report, as a hidraw node returns them;
  evemu: an evemu-record event stream, one struct input_event (64-bit
         timeval, type, code, value) per read, delays from the event times.

Unlike umockdev's own evemu loading, the first read waits --lead ms, so the
program under test has opened the node before anything arrives (a hidraw
reader that finds several reports queued would read them as one).

Data bytes below 33 are written as '^' + chr(b + 64) and '^' as "^`"
(umockdev's docs/script-format.txt); all other bytes verbatim.

Usage: umockdev_script.py hid|evemu INPUT OUTPUT [--lead MS] [--rate HZ] [--report-size N]
"""
import argparse
import re
import struct


def encode(data):
    out = bytearray()
    for b in data:
        if b == ord("^"):
            out += b"^`"
        elif b <= 32:
            out += bytes([ord("^"), b + 64])
        else:
            out.append(b)
    return bytes(out)


def hid_reads(path, size, rate):
    data = open(path, "rb").read()
    if len(data) % size:
        raise SystemExit(f"{path}: {len(data)} bytes is not a whole number of {size}-byte reports")
    step = 1000 // rate
    return [(step, data[i:i + size]) for i in range(0, len(data), size)]


def evemu_reads(path):
    reads, previous_ms = [], None
    for line in open(path):
        m = re.match(r"E: (\d+)\.(\d+) +([0-9a-fA-F]+) +([0-9a-fA-F]+) +(-?\d+)", line)
        if not m:
            continue
        sec, usec = int(m.group(1)), int(m.group(2))
        at_ms = sec * 1000 + usec // 1000
        delay = 0 if previous_ms is None else max(0, at_ms - previous_ms)
        previous_ms = at_ms
        event = struct.pack("<qqHHi", sec, usec, int(m.group(3), 16), int(m.group(4), 16), int(m.group(5)))
        reads.append((delay, event))
    return reads


def main():
    p = argparse.ArgumentParser()
    p.add_argument("format", choices=["hid", "evemu"])
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--lead", type=int, default=0, help="ms before the first read")
    p.add_argument("--rate", type=int, default=250, help="hid: reports per second (a divisor of 1000)")
    p.add_argument("--report-size", type=int, default=64, help="hid: bytes per report")
    a = p.parse_args()
    reads = hid_reads(a.input, a.report_size, a.rate) if a.format == "hid" else evemu_reads(a.input)
    with open(a.output, "wb") as out:
        for i, (delay, data) in enumerate(reads):
            out.write(b"r %d " % (a.lead if i == 0 else delay) + encode(data) + b"\n")


if __name__ == "__main__":
    main()
