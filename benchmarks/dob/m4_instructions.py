#!/usr/bin/python3
"""Cortex-M4 instructions per sample of the DOB kernel, counted in QEMU (no plugins).

Builds the firmware preset's dob_kernel_m4_bench image (default design: 2 inputs, 4 + 3 sections),
runs it in qemu-system-arm -M mps2-an386 with one instruction per translation block
(-singlestep) and the execution log (-d exec,nochain), and counts the logged program counters that
fall inside DobFilter::Step, StepBlock, the backend's DobKernel::Run and the program it runs, vibid_fixed_dob_run (ranges
from arm-none-eabi-nm). The image runs StepBlock once over FRAMES frames. Prints
the count per sample and per section beside CMSIS-DSP's q31 DF1 biquad (about 17 per section).

Usage: /usr/bin/python3 benchmarks/dob/m4_instructions.py [--no-build] [--build DIR]
"""
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
import m4_trace  # noqa: E402

FRAMES = 1000  # kFrames in m4_kernel_image.cpp
SECTIONS = 7  # the vector's design: 4 + 3 sections
# The peer: CMSIS-DSP's q31 Direct Form I biquad (no rounding, saturation or error feedback), about 17
# instructions per section per sample in its inner loop. The target leaves the sampling interrupt
# room beside the observer (docs/performance.md).
CMSIS_PER_SECTION = 17
TARGET_PER_SECTION = 20
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
IMAGE = os.path.join(m4_trace.BUILD_DIR, "firmware", "testing", "dob_kernel_m4_bench")
KERNEL = ("vibid::fixed::DobFilter::Step(", "vibid::fixed::DobFilter::StepBlock(",
          "vibid::fixed::DobKernel::Run(", "vibid_fixed_dob_run")


def kernel_ranges():
    out = subprocess.run(["arm-none-eabi-nm", "-C", "-S", IMAGE], check=True, capture_output=True, text=True).stdout
    ranges = []
    for line in out.splitlines():
        parts = line.split(maxsplit=3)
        if len(parts) == 4 and parts[2] in "tT" and parts[3].startswith(KERNEL):
            start = int(parts[0], 16) & ~1
            ranges.append((start, start + int(parts[1], 16), parts[3].split("(")[0]))
    # The image calls StepBlock only, so Step may be dropped by the linker, and Run may be inlined into
    # StepBlock; the program and StepBlock must be there.
    found = {name for _, _, name in ranges}
    if not {"vibid_fixed_dob_run", "vibid::fixed::DobFilter::StepBlock"} <= found:
        sys.exit("kernel symbols not found in " + IMAGE + " (inlined?): " + repr(ranges))
    return ranges


def main():
    m4_trace.build("dob_kernel_m4_bench")
    ranges = kernel_ranges()
    total = 0
    per = {name: 0 for _, _, name in ranges}
    with m4_trace.executed_pcs(IMAGE) as executed:
        for pc in executed:
            total += 1
            for lo, hi, name in ranges:
                if lo <= pc < hi:
                    per[name] += 1
                    break
    kernel = sum(per.values())
    print("image: %s" % os.path.relpath(IMAGE, ROOT))
    for name, n in per.items():
        print("  %-40s %9d instructions" % (name, n))
    print("kernel: %d instructions over %d frames = %.1f instructions/sample (whole run %d)"
          % (kernel, FRAMES, kernel / FRAMES, total))
    per_section = kernel / FRAMES / SECTIONS
    print("per section (%d sections): %.1f instructions, all per-sample work included; "
          "CMSIS-DSP arm_biquad_cascade_df1_q31 about %d; target <= %d (%s)"
          % (SECTIONS, per_section, CMSIS_PER_SECTION, TARGET_PER_SECTION,
             "met" if per_section <= TARGET_PER_SECTION else "NOT met"))


if __name__ == "__main__":
    main()
