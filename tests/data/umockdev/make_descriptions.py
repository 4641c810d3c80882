#!/usr/bin/env python3
"""Writes the umockdev device (.umockdev) and ioctl (.ioctl) descriptions of the
two simulated evdev gamepads, as the kernel exposes them: an Xbox 360 pad
(xpad) and a DualSense (hid-playstation). The capabilities match
firmware_sim/sim_pad.cpp's evdev_pad_description(). umockdev answers an ioctl
only from a record of exactly the requested size, so each variable-size query
is written at the sizes libevdev (EVIOCGNAME/PHYS/UNIQ at 255 bytes, bitmaps at
its array sizes) and SDL2 (EVIOCGNAME at 128) ask for.

Usage: python3 make_descriptions.py [OUTPUT_DIR]   (default: this folder)
"""
import os
import struct
import sys

EV_SYN, EV_KEY, EV_ABS = 0x00, 0x01, 0x03
KEYS = [0x130, 0x131, 0x133, 0x134, 0x136, 0x137, 0x13a, 0x13b, 0x13c, 0x13d, 0x13e]
PADS = {
    "xbox": dict(
        name="Microsoft X-Box 360 pad", bus=0x0003, vendor=0x045e, product=0x028e, version=0x0114,
        event=7, keys=KEYS,
        # code: (value at rest, min, max, fuzz, flat)
        abs={0x00: (0, -32768, 32767, 16, 128), 0x01: (0, -32768, 32767, 16, 128),
             0x02: (0, 0, 255, 0, 0), 0x03: (0, -32768, 32767, 16, 128),
             0x04: (0, -32768, 32767, 16, 128), 0x05: (0, 0, 255, 0, 0),
             0x10: (0, -1, 1, 0, 0), 0x11: (0, -1, 1, 0, 0)},
        phys="usb-0000:00:14.0-1/input0", syspath="/devices/pci0000:00/0000:00:14.0/usb1/1-1/1-1:1.0/input/input7"),
    "dualsense": dict(
        name="Sony Interactive Entertainment DualSense Wireless Controller", bus=0x0003, vendor=0x054c,
        product=0x0ce6, version=0x8111, event=9, keys=KEYS + [0x138, 0x139],
        abs={0x00: (128, 0, 255, 0, 0), 0x01: (128, 0, 255, 0, 0), 0x02: (0, 0, 255, 0, 0),
             0x03: (128, 0, 255, 0, 0), 0x04: (128, 0, 255, 0, 0), 0x05: (0, 0, 255, 0, 0),
             0x10: (0, -1, 1, 0, 0), 0x11: (0, -1, 1, 0, 0)},
        phys="usb-0000:00:14.0-2/input3",
        syspath="/devices/pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.3/0003:054C:0CE6.0005/input/input9"),
}


def bits(n_bytes, codes):
    b = bytearray(n_bytes)
    for c in codes:
        b[c // 8] |= 1 << (c % 8)
    return bytes(b)


def hexs(b):
    return b.hex().upper()


def kernel_bitmap(codes):
    """sysfs capabilities/* text: 64-bit words, most significant first."""
    if not codes:
        return "0"
    words = [0] * (max(codes) // 64 + 1)
    for c in codes:
        words[c // 64] |= 1 << (c % 64)
    return " ".join(f"{w:x}" for w in reversed(words))


def ioctl_text(p):
    out = []
    out.append("# marionette: %s (tests/data/umockdev/make_descriptions.py)" % p["name"])
    out.append("EVIOCGVERSION 0 " + hexs(struct.pack("<i", 0x010001)))
    out.append("EVIOCGID 0 " + hexs(struct.pack("<HHHH", p["bus"], p["vendor"], p["product"], p["version"])))
    name = p["name"].encode()
    for size in (255, 256, 128, 64):
        out.append("EVIOCGNAME(0) %d %s" % (min(len(name) + 1, size), hexs(name[: size - 1].ljust(size, b"\0"))))
    phys = p["phys"].encode()
    for size in (255, 256, 128, 64):
        out.append("EVIOCGPHYS(0) %d %s" % (len(phys) + 1, hexs(phys.ljust(size, b"\0"))))
        out.append("EVIOCGUNIQ(0) 1 " + hexs(bytes(size)))
    out.append("EVIOCGPROP(0) 0 " + hexs(bits(8, [])))
    out.append("EVIOCGBIT(0) 0 " + hexs(bits(8, [EV_SYN, EV_KEY, EV_ABS])))
    out.append("EVIOCGBIT(1) 0 " + hexs(bits(96, p["keys"])))
    out.append("EVIOCGBIT(3) 0 " + hexs(bits(8, list(p["abs"]))))
    for ev in (2, 4, 5, 0x11, 0x12):
        out.append("EVIOCGBIT(%d) 0 %s" % (ev, hexs(bits(8, []))))
    out.append("EVIOCGBIT(21) 0 " + hexs(bits(16, [])))
    out.append("EVIOCGKEY(0) 0 " + hexs(bits(96, [])))
    out.append("EVIOCGLED(0) 0 " + hexs(bits(8, [])))
    out.append("EVIOCGSW(0) 0 " + hexs(bits(8, [])))
    for code, (value, mn, mx, fuzz, flat) in sorted(p["abs"].items()):
        out.append("EVIOCGABS(%d) 0 %s" % (code, hexs(struct.pack("<6i", value, mn, mx, fuzz, flat, 0))))
    return "\n".join(out) + "\n"


def device_text(p):
    ev = p["event"]
    node = p["syspath"] + "/event%d" % ev
    props = ["ID_INPUT=1", "ID_INPUT_JOYSTICK=1", "ID_BUS=usb",
             "ID_VENDOR_ID=%04x" % p["vendor"], "ID_MODEL_ID=%04x" % p["product"]]
    lines = ["P: " + node, "N: input/event%d" % ev, "E: DEVNAME=/dev/input/event%d" % ev, "E: SUBSYSTEM=input",
             "E: MAJOR=13", "E: MINOR=%d" % (64 + ev)] + ["E: " + x for x in props] + \
            ["A: dev=13:%d" % (64 + ev), "L: device=../../input%d" % ev, ""]
    lines += ["P: " + p["syspath"], "E: SUBSYSTEM=input",
              'E: NAME="%s"' % p["name"],
              "E: PRODUCT=%x/%x/%x/%x" % (p["bus"], p["vendor"], p["product"], p["version"])] + \
             ["E: " + x for x in props] + [
              "A: name=" + p["name"], "A: phys=" + p["phys"], "A: uniq=",
              "A: id/bustype=%04x" % p["bus"], "A: id/vendor=%04x" % p["vendor"],
              "A: id/product=%04x" % p["product"], "A: id/version=%04x" % p["version"],
              "A: capabilities/ev=" + kernel_bitmap([EV_SYN, EV_KEY, EV_ABS]),
              "A: capabilities/key=" + kernel_bitmap(p["keys"]),
              "A: capabilities/abs=" + kernel_bitmap(list(p["abs"])),
              "A: capabilities/rel=0", "A: capabilities/msc=0", "A: capabilities/ff=0",
              "A: capabilities/led=0", "A: capabilities/snd=0", "A: capabilities/sw=0", "A: properties=0", ""]
    return "\n".join(lines)


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    for key, p in PADS.items():
        with open(os.path.join(out_dir, key + ".umockdev"), "w") as f:
            f.write(device_text(p))
        with open(os.path.join(out_dir, key + ".ioctl"), "w") as f:
            f.write(ioctl_text(p))


if __name__ == "__main__":
    main()
