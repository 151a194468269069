#!/usr/bin/env python3
"""The build's images carry the CRC their trailer states, and a changed byte is caught.

  image_crc_test.py --objcopy OBJCOPY IMAGE.elf...

For each image: its .bin and its .hex (as objcopy reads it back) check as a match; a copy with
one byte flipped in the head (vector table), in the body (code) or in the stored CRC word checks
as a mismatch (exit 1); a copy with the magic changed has no trailer (exit 2); a byte changed in
the calibration sectors between head and body is not the image's and still matches.
"""

import argparse
import os
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CHECKER = os.path.join(HERE, "image_crc.py")


def check(path):
    r = subprocess.run([sys.executable, CHECKER, "check", path], capture_output=True, text=True)
    return r.returncode, (r.stdout + r.stderr).strip()


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--objcopy", required=True)
    p.add_argument("elf", nargs="+")
    a = p.parse_args()
    failures = 0

    def expect(what, path, code):
        nonlocal failures
        got, text = check(path)
        ok = got == code
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} {what}: exit {got} (expected {code}): {text}")

    with tempfile.TemporaryDirectory() as tmp:
        for elf in a.elf:
            name = os.path.splitext(os.path.basename(elf))[0]
            base = os.path.splitext(elf)[0]
            expect(f"{name}.bin", base + ".bin", 0)
            from_hex = os.path.join(tmp, name + ".hex.bin")
            subprocess.run([a.objcopy, "-I", "ihex", "-O", "binary", "--gap-fill", "0xff",
                            base + ".hex", from_hex], check=True)
            expect(f"{name}.hex", from_hex, 0)
            with open(base + ".bin", "rb") as f:
                image = f.read()
            _magic, head_start, head_end, body_start, body_end, _crc = struct.unpack_from(
                "<6I", image, len(image) - 24)
            cases = [("head byte", head_end - 1 - head_start, 0x01, 1),
                     ("body byte", body_start + 0x100 - head_start, 0x80, 1),
                     ("stored CRC", len(image) - 1, 0x01, 1),
                     ("magic", len(image) - 24, 0x01, 2),
                     ("calibration sector", head_end - head_start + 0x8000, 0x5A, 0)]
            for what, at, mask, code in cases:
                corrupt = bytearray(image)
                corrupt[at] ^= mask
                path = os.path.join(tmp, f"{name}.{what.replace(' ', '_')}.bin")
                with open(path, "wb") as f:
                    f.write(corrupt)
                expect(f"{name} with its {what} changed", path, code)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
