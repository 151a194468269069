#!/usr/bin/env python3
"""The firmware image's CRC trailer (sections.ld, ".image_crc"): written after the link, checked
in a flat image.

The trailer is the last 24 bytes of the image in flash, six little-endian u32:
  magic "vCRC", head_start, head_end, body_start, body_end, crc
and crc is CRC-32/ISO-HDLC (zlib.crc32: polynomial 0x04C11DB7 reflected, initial value and final
XOR 0xFFFFFFFF) of [head_start, head_end) followed by [body_start, body_end). body_end is the
CRC word's own address, so the CRC covers every image byte before it (the calibration sectors
between head and body are not the image's). The board computes the same CRC at run time
(image_crc.cpp) and compares.

  image_crc.py stamp IMAGE.elf --objcopy OBJCOPY   write the CRC into the ELF's .image_crc
  image_crc.py check IMAGE.bin                     0: the stored CRC matches, 1: it does not,
                                                   2: no trailer (not an image with one)

A flat image (.bin, objcopy -O binary --gap-fill 0xff) starts at head_start and ends with the
trailer.
"""

import argparse
import os
import struct
import subprocess
import sys
import tempfile
import zlib

MAGIC = 0x43524376  # "vCRC"
TRAILER = struct.Struct("<6I")


class NoTrailer(Exception):
    pass


def parse(image):
    """The trailer's fields and the CRC over its ranges of a flat image."""
    if len(image) < TRAILER.size:
        raise NoTrailer(f"{len(image)} bytes, shorter than the {TRAILER.size}-byte trailer")
    magic, head_start, head_end, body_start, body_end, stored = TRAILER.unpack_from(
        image, len(image) - TRAILER.size)
    if magic != MAGIC:
        raise NoTrailer(f"the last {TRAILER.size} bytes are not a CRC trailer "
                        f"(magic 0x{magic:08X}, expected 0x{MAGIC:08X})")
    if not head_start <= head_end <= body_start <= body_end:
        raise NoTrailer(f"ranges out of order: head 0x{head_start:08X}..0x{head_end:08X}, "
                        f"body 0x{body_start:08X}..0x{body_end:08X}")
    if body_end != head_start + len(image) - 4:
        raise NoTrailer(f"the trailer's CRC word is at 0x{body_end:08X}, but the image ends at "
                        f"0x{head_start + len(image):08X}: a section follows the trailer")
    head = image[head_start - head_start:head_end - head_start]
    body = image[body_start - head_start:body_end - head_start]
    computed = zlib.crc32(body, zlib.crc32(head)) & 0xFFFFFFFF
    return {"head": (head_start, head_end), "body": (body_start, body_end),
            "stored": stored, "computed": computed}


def flat(elf, objcopy):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "image.bin")
        subprocess.run([objcopy, "-O", "binary", "--gap-fill", "0xff", elf, out], check=True)
        with open(out, "rb") as f:
            return f.read()


def stamp(elf, objcopy):
    image = flat(elf, objcopy)
    t = parse(image)
    trailer = bytearray(image[-TRAILER.size:])
    struct.pack_into("<I", trailer, TRAILER.size - 4, t["computed"])
    with tempfile.TemporaryDirectory() as tmp:
        section = os.path.join(tmp, "image_crc.bin")
        with open(section, "wb") as f:
            f.write(trailer)
        subprocess.run([objcopy, "--update-section", f".image_crc={section}", elf], check=True)
    again = parse(flat(elf, objcopy))
    if again["stored"] != again["computed"]:
        sys.exit(f"{elf}: the CRC written (0x{again['stored']:08X}) does not read back as "
                 f"0x{again['computed']:08X}")
    print(f"{os.path.basename(elf)}: CRC-32 0x{t['computed']:08X} of "
          f"{t['head'][1] - t['head'][0] + t['body'][1] - t['body'][0]} bytes written "
          f"at 0x{t['body'][1]:08X}")


def check(path):
    with open(path, "rb") as f:
        image = f.read()
    try:
        t = parse(image)
    except NoTrailer as e:
        print(f"{path}: {e}", file=sys.stderr)
        return 2
    covered = t["head"][1] - t["head"][0] + t["body"][1] - t["body"][0]
    if t["stored"] == t["computed"]:
        print(f"{path}: CRC-32 0x{t['computed']:08X} of {covered} bytes matches the stored one")
        return 0
    print(f"{path}: CRC-32 0x{t['computed']:08X} of {covered} bytes does not match the stored "
          f"0x{t['stored']:08X}")
    return 1


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("stamp", help="write the CRC into an ELF image's .image_crc section")
    s.add_argument("elf")
    s.add_argument("--objcopy", required=True)
    c = sub.add_parser("check", help="check a flat image's CRC against its trailer")
    c.add_argument("image")
    a = p.parse_args()
    if a.command == "stamp":
        try:
            stamp(a.elf, a.objcopy)
        except NoTrailer as e:
            sys.exit(f"{a.elf}: {e}")
        return 0
    return check(a.image)


if __name__ == "__main__":
    sys.exit(main())
