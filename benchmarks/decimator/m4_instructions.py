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

QEMU executes instructions, not cycles, so the cycles are an estimate: each executed instruction
is priced with the Cortex-M4 TRM timings (zero wait states; single loads and stores 2 cycles, 1
when they follow another load or store; LDRD/STRD 3; LDM/STM/PUSH/POP 1 + registers; multiplies
and SMLAL 1; divides 7; taken branches 3, i.e. a two-cycle refill), the taken branches found from
the logged program counters. On the board, flash wait states the ART accelerator does not hide
come on top.

Usage: /usr/bin/python3 benchmarks/decimator/m4_instructions.py [--no-build] [--build DIR]
"""
import os
import re
import subprocess
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


def disassembly():
    """pc -> (size in bytes, mnemonic, operands) for every instruction of the image."""
    out = subprocess.run(["arm-none-eabi-objdump", "-d", IMAGE], check=True, capture_output=True, text=True).stdout
    table = {}
    line_re = re.compile(r"^\s*([0-9a-f]+):\t([0-9a-f]{4}(?: [0-9a-f]{4})?)\s*\t(\S+)\s*(.*)$")
    for line in out.splitlines():
        m = line_re.match(line)
        if m:
            table[int(m.group(1), 16)] = (2 * len(m.group(2).split()), m.group(3), m.group(4))
    return table


SINGLE_LS = re.compile(r"^(ldr|str)(b|h|sb|sh)?(\.w|\.n)?$")
MULTI_LS = re.compile(r"^(ldm|stm|push|pop)")
BRANCH = re.compile(r"^(b|bl|bx|blx|cbz|cbnz)(eq|ne|cs|hs|cc|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le)?(\.w|\.n)?$")


def cycles(insn, taken, after_ls):
    """Estimated Cortex-M4 cycles of one executed instruction (see the module comment)."""
    _, mnemonic, operands = insn
    if SINGLE_LS.match(mnemonic):
        return 1 if after_ls else 2
    if mnemonic.startswith(("ldrd", "strd")):
        return 3
    if MULTI_LS.match(mnemonic):
        regs = operands[operands.find("{") + 1:operands.find("}")]
        n = sum(int(r.split("-")[1][1:]) - int(r.split("-")[0][1:]) + 1 if "-" in r else 1
                for r in regs.replace(" ", "").split(",") if r)
        return 1 + n + (2 if taken else 0)
    if mnemonic.startswith(("udiv", "sdiv")):
        return 7
    if BRANCH.match(mnemonic):
        return 3 if taken else 1
    return 3 if taken else 1  # anything else that writes pc, or 1


def per_call_counts(executed, push, driver, insns):
    """(instructions, estimated cycles) of each Push call, in call order."""
    calls, pcs, inside = [], [], False

    def close():
        total, after_ls = 0, False
        for i, pc in enumerate(pcs):
            insn = insns[pc]
            nxt = pcs[i + 1] if i + 1 < len(pcs) else None
            total += cycles(insn, nxt is not None and nxt != pc + insn[0] or nxt is None, after_ls)
            after_ls = bool(SINGLE_LS.match(insn[1]))
        calls.append((len(pcs), total))

    for pc in executed:
        if pc == push[0]:
            inside, pcs = True, []
        elif inside and driver[0] <= pc < driver[1]:
            close()
            inside = False
        if inside:
            pcs.append(pc)
    return calls


def main():
    m4_trace.build("decimator_m4_bench")
    push, driver = symbols()
    insns = disassembly()
    with m4_trace.executed_pcs(IMAGE) as executed:
        calls = per_call_counts(executed, push, driver, insns)
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
