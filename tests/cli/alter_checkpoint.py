#!/usr/bin/env python3
"""Flips one bit of the Nth state-hash checkpoint of a version 2 input log and
fixes that chunk's CRC, so the log still decodes and only replay's verification
can notice (docs/input-log.md). Usage: alter_checkpoint.py IN OUT N
Prints the number of ticks after which the altered checkpoint stands."""
import struct
import sys
import zlib


def read_varint(data, pos):
    value, shift = 0, 0
    while True:
        byte = data[pos]
        pos += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if not byte & 0x80:
            return value, pos


def main():
    data = bytearray(open(sys.argv[1], "rb").read())
    wanted = int(sys.argv[3])
    version = struct.unpack_from("<I", data, 8)[0]
    if version < 2:
        sys.exit("version 1 logs have no checkpoints")
    pos = 28 + struct.unpack_from("<I", data, 24)[0]
    for _ in range(2):  # provenance, motion data
        pos += 4 + struct.unpack_from("<I", data, pos)[0]
    pos += 4  # header CRC
    seen, ticks_before = 0, 0
    while pos < len(data):
        if data[pos:pos + 4] != b"CHNK":
            sys.exit(f"no chunk at byte {pos}")
        size = struct.unpack_from("<I", data, pos + 16)[0]
        p, end = pos + 24, pos + 24 + size
        while p < end:
            tag = data[p]
            p += 1
            if tag < 0x80:
                for field in range(7):
                    if tag & (1 << field):
                        _, p = read_varint(data, p)
                repeat, p = read_varint(data, p)
                ticks_before += repeat
            elif tag == 0x80:
                length, p = read_varint(data, p)
                p += length
            elif tag == 0x82:
                if seen == wanted:
                    data[p] ^= 1
                    crc = zlib.crc32(bytes(data[pos + 4:pos + 20]))
                    crc = zlib.crc32(bytes(data[pos + 24:end]), crc)
                    struct.pack_into("<I", data, pos + 20, crc)
                    open(sys.argv[2], "wb").write(data)
                    print(ticks_before)
                    return
                seen += 1
                p += 8
        pos = end
    sys.exit(f"the log has only {seen} checkpoints")


if __name__ == "__main__":
    main()
