#!/usr/bin/python3
"""Cortex-M4 instructions of the anti-aliasing decimator, counted in QEMU (no plugins).

Builds the firmware preset's decimator_m4_bench image (benchmarks/decimator/m4_kernel_image.cpp: 7
channels, PERIODS whole output periods at each factor in FACTORS), runs it in qemu-system-arm -M
mps2-an386 with one instruction per translation block (-singlestep) and the execution log
(-d exec,nochain), and counts, for every call of Decimator::Push, the instructions from its entry
until control is back in the image's driver loop (so inlined and called helpers are included, the
input generation is not). Prints per factor the average per input frame (7 channels), per channel
sample, the worst single call (the output tick, where every stage computes), the cheapest call
(a tick where only the first stage stores its input) and the share of a 168 MHz core at a 10 kHz
input rate.

QEMU executes instructions, not cycles, so the cycles are an estimate (benchmarks/m4_trace.py
prices each executed instruction with the Cortex-M4 TRM timings).

Usage: /usr/bin/python3 benchmarks/decimator/m4_instructions.py [--no-build] [--build DIR]
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
import m4_trace  # noqa: E402

FACTORS = (2, 5, 10, 50, 625, 1000)  # kFactors in m4_kernel_image.cpp; 625 has the worst tick
PERIODS = 2  # kPeriods
CHANNELS = 7
CORE_HZ = 168e6
INPUT_HZ = 10e3
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
IMAGE = os.path.join(m4_trace.BUILD_DIR, "shared", "fixed", "decimator_m4_bench")
PUSH = "vibid::fixed::Decimator::Push("
DRIVER = "vibid::fixed::(anonymous namespace)::Drive("


def main():
    m4_trace.build("decimator_m4_bench")
    found = m4_trace.symbols(IMAGE, (PUSH, DRIVER))
    push, driver = found[PUSH], found[DRIVER]
    insns = m4_trace.disassembly(IMAGE)
    with m4_trace.executed_pcs(IMAGE) as executed:
        calls = m4_trace.per_call_counts(executed, push, driver, insns)
    expected = sum(PERIODS * d for d in FACTORS)
    if len(calls) != expected:
        sys.exit("counted %d Push calls, expected %d" % (len(calls), expected))
    print("image: %s (Decimator::Push at 0x%x, %d bytes)" % (os.path.relpath(IMAGE, ROOT), push[0], push[1] - push[0]))
    print("%d channels, one Push = one input frame; instructions counted, cycles estimated; core share of %.0f MHz"
          " at %.0f kHz from the estimated cycles (from the instructions in brackets)"
          % (CHANNELS, CORE_HZ / 1e6, INPUT_HZ / 1e3))
    print("  %5s %10s %9s %8s %11s %11s %9s %16s" % ("D", "instr/frm", "instr/ch", "cyc/frm", "worst instr",
                                                    "worst cyc", "min instr", "core share"))
    i = 0
    for d in FACTORS:
        mine = calls[i:i + PERIODS * d]
        i += PERIODS * d
        # Whole periods from phase 0, so every stage computes its exact share.
        instr = sum(c[0] for c in mine) / len(mine)
        cyc = sum(c[1] for c in mine) / len(mine)
        worst = max(range(len(mine)), key=lambda k: mine[k][0])
        assert worst % d == 0, "the worst call is not an output tick"
        print("  %5d %10.1f %9.1f %8.1f %11d %11d %9d %7.2f%% (%.2f%%)" % (
            d, instr, instr / CHANNELS, cyc, mine[worst][0], mine[worst][1], min(c[0] for c in mine),
            100.0 * cyc * INPUT_HZ / CORE_HZ, 100.0 * instr * INPUT_HZ / CORE_HZ))


if __name__ == "__main__":
    main()
