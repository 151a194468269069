#!/usr/bin/python3
"""Cortex-M4 instructions of the anti-aliasing decimator, counted in QEMU (no plugins).

Builds the firmware preset's decimator_m4_bench image (bench/decimator/m4_kernel_image.cpp: 7
channels, PERIODS whole output periods at each factor in FACTORS), runs it in qemu-system-arm -M
mps2-an386 with one instruction per translation block (-singlestep) and the execution log
(-d exec,nochain), and counts, for every call of Decimator::Push, the instructions from its entry
until control is back in the image's driver loop (so inlined and called helpers are included, the
input generation is not). Prints per factor the average per input frame (7 channels), per channel
sample, the worst single call (the output tick, where every stage computes) and the share of a
168 MHz core at a 10 kHz input rate, counting one cycle per instruction (a lower bound: loads
after loads and taken branches cost more on the M4, typically 1.2-1.5 cycles per instruction in
such loops).

Usage: /usr/bin/python3 bench/decimator/m4_instructions.py [--no-build]
"""
import os
import re
import subprocess
import sys
import tempfile

FACTORS = (2, 5, 10, 50, 625, 1000)  # kFactors in m4_kernel_image.cpp; 625 has the worst tick
PERIODS = 2  # kPeriods
CHANNELS = 7
CORE_HZ = 168e6
INPUT_HZ = 10e3
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
IMAGE = os.path.join(ROOT, "build", "firmware", "shared", "fixed", "decimator_m4_bench")
PUSH = "vibid::fixed::Decimator::Push("
DRIVER = "vibid::fixed::(anonymous namespace)::Drive("


def symbols():
    out = subprocess.run(["arm-none-eabi-nm", "-C", "-S", IMAGE], check=True, capture_output=True, text=True).stdout
    found = {}
    for line in out.splitlines():
        parts = line.split(maxsplit=3)
        if len(parts) == 4 and parts[2] in "tTW":
            for key in (PUSH, DRIVER):
                if parts[3].startswith(key):
                    start = int(parts[0], 16) & ~1
                    found[key] = (start, start + int(parts[1], 16))
    if len(found) != 2:
        sys.exit("symbols not found in " + IMAGE + ": " + repr(found))
    return found[PUSH], found[DRIVER]


def per_call_counts(log, push, driver):
    """Instructions of each Push call, in call order."""
    pc_re = re.compile(r"\[[0-9a-f]+/([0-9a-f]+)/")
    calls, count, inside = [], 0, False
    with open(log) as f:
        for line in f:
            m = pc_re.search(line)
            if not m:
                continue
            pc = int(m.group(1), 16)
            if pc == push[0]:
                inside, count = True, 0
            elif inside and driver[0] <= pc < driver[1]:
                calls.append(count)
                inside = False
            if inside:
                count += 1
    return calls


def main():
    if "--no-build" not in sys.argv:
        subprocess.run(["cmake", "--preset", "firmware"], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", "--preset", "firmware", "--target", "decimator_m4_bench"], cwd=ROOT,
                       check=True, stdout=subprocess.DEVNULL)
    push, driver = symbols()
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "exec.log")
        run = subprocess.run(["qemu-system-arm", "-M", "mps2-an386", "-cpu", "cortex-m4", "-nographic", "-monitor",
                              "none", "-serial", "none", "-semihosting-config", "enable=on,target=native",
                              "-singlestep", "-d", "exec,nochain", "-D", log, "-kernel", IMAGE],
                             capture_output=True, text=True, timeout=600)
        if run.returncode != 0:
            sys.exit("the image failed under QEMU:\n" + run.stdout + run.stderr)
        calls = per_call_counts(log, push, driver)
    expected = sum(PERIODS * d for d in FACTORS)
    if len(calls) != expected:
        sys.exit("counted %d Push calls, expected %d" % (len(calls), expected))
    print("image: %s (Decimator::Push at 0x%x, %d bytes)" % (os.path.relpath(IMAGE, ROOT), push[0], push[1] - push[0]))
    print("%d channels; instructions per Push (one input frame); core share at %.0f kHz on %.0f MHz, 1 instr = 1 cycle"
          % (CHANNELS, INPUT_HZ / 1e3, CORE_HZ / 1e6))
    print("  %4s %10s %14s %11s %12s %10s %11s" % ("D", "avg/frame", "avg/ch sample", "worst tick", "worst/ch",
                                                   "min tick", "core share"))
    i = 0
    for d in FACTORS:
        mine = calls[i:i + PERIODS * d]
        i += PERIODS * d
        # Whole periods from phase 0, so every stage computes its exact share.
        avg = sum(mine) / len(mine)
        worst = max(mine)
        assert mine.index(worst) % d == 0, "the worst call is not an output tick"
        print("  %4d %10.1f %14.1f %11d %12.1f %10d %10.2f%%" % (d, avg, avg / CHANNELS, worst, worst / CHANNELS,
                                                                 min(mine), 100.0 * avg * INPUT_HZ / CORE_HZ))


if __name__ == "__main__":
    main()
