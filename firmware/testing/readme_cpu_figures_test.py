#!/usr/bin/python3
"""The README's CPU figures are the build's: the Cortex-M4 instructions per sample of the DOB
kernel and per second-order section, as README.md states them ("the DOB kernel 135 instructions
per sample (19.3 per second-order section" and the speed table's "19.3 instructions per section",
its target "<= 20"), against the count benchmarks/dob/m4_instructions.py makes on this build's
dob_kernel_m4_bench image in QEMU (deterministic: the same image executes the same instructions).
A kernel change that moves the count fails here until the README says the new figure.

Usage: readme_cpu_figures_test.py --build FIRMWARE_BUILD_DIR --readme README.md
"""
import argparse
import os
import re
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def number(text):
    """A figure as README types it: digits with thin or plain spaces between thousands."""
    return float(re.sub(r"[\s\u202f\u2009]", "", text))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", required=True)
    parser.add_argument("--readme", required=True)
    args = parser.parse_args()
    with open(args.readme, encoding="utf-8") as f:
        readme = f.read()
    stated = re.search(r"the DOB kernel ([\d\s\u202f\u2009]+) instructions per sample "
                       r"\(([\d.]+) per second-order section", readme)
    table = re.search(r"\| DOB kernel on the Cortex-M4 \(QEMU\) \| ([\d.]+) instructions per "
                      r"section \|[^|]*\|[^|]*\| <= ([\d.]+) \(met\) \|", readme)
    if not stated or not table:
        print("FAIL README.md does not state the DOB kernel's instructions per sample and per "
              "section where this test reads them (the CPU bullet and the speed table)")
        return 1
    out = subprocess.run([sys.executable, os.path.join(ROOT, "benchmarks", "dob", "m4_instructions.py"),
                          "--no-build", "--build", os.path.abspath(args.build)],
                         check=True, capture_output=True, text=True).stdout
    print(out.rstrip())
    per_sample = re.search(r"= ([\d.]+) instructions/sample", out)
    per_section = re.search(r"per section \(\d+ sections\): ([\d.]+) instructions", out)
    if not per_sample or not per_section:
        print("FAIL m4_instructions.py printed no per-sample or per-section count")
        return 1
    failures = 0

    def check(ok, what):
        nonlocal failures
        print(("ok   " if ok else "FAIL ") + what)
        failures += not ok

    measured_sample = float(per_sample.group(1))
    measured_section = float(per_section.group(1))
    check(round(measured_sample) == number(stated.group(1)),
          f"README's {stated.group(1).strip()} instructions per sample: measured "
          f"{measured_sample:.1f}")
    for where, typed in (("CPU bullet", stated.group(2)), ("speed table", table.group(1))):
        check(f"{measured_section:.1f}" == typed,
              f"README's {typed} instructions per section ({where}): measured "
              f"{measured_section:.1f}")
    check(measured_section <= float(table.group(2)),
          f"README's target <= {table.group(2)} per section (met): measured {measured_section:.1f}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
