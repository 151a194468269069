#!/usr/bin/python3
"""A hammer test of a lightly damped structure whose resonances are narrower than one line,
simulated independently of vibid (numpy/scipy only).

Two modes as a wing on an analyzer shows them (records of 3.2 s at 1280 Hz: lines 0.3125 Hz
apart): 13.44 Hz with zeta 0.002 and 167.8 Hz with zeta 0.0003 (half-power bands 0.054 and
0.10 Hz, under a third of a line), unit modal mass, the force and the accelerometer at one point.
Each mode is integrated exactly as a second-order system (scipy.signal.lsim, first-order hold)
at 8 times the output rate under 1 ms half-sine hits of 40 N every 3.2 s, then low-pass filtered
and decimated as a DAQ samples (scipy.signal.decimate, FIR, zero phase), with Gaussian noise of
1 % of each channel's largest value.

Writes a recording as vibid reads it (t_s, force1_n, acc1_m_s2):
    sub_line_record.py -o host/cli/ident/testdata/sub_line_wing.csv
"""
import argparse

import numpy as np
import scipy.signal

MODES_HZ = [13.44, 167.8]
ZETAS = [0.002, 0.0003]
FS_HZ = 1280.0
OVERSAMPLE = 8


def record(hits=3, spacing_s=3.2, seed=11):
    fine = FS_HZ * OVERSAMPLE
    seconds = 0.2 + hits * spacing_s
    t = np.arange(int(round(seconds * FS_HZ)) * OVERSAMPLE) / fine
    f = np.zeros_like(t)
    rng = np.random.default_rng(seed)
    for h in range(hits):
        t0 = 0.1 + h * spacing_s
        inside = (t >= t0) & (t < t0 + 0.001)
        f[inside] += 40.0 * (0.9 + 0.2 * rng.random()) * np.sin(np.pi * (t[inside] - t0) / 0.001)
    acc = np.zeros_like(t)
    for fn, z in zip(MODES_HZ, ZETAS):
        w = 2 * np.pi * fn
        # Acceleration over force of a unit-modal-mass mode: s^2 / (s^2 + 2 z w s + w^2).
        sys = scipy.signal.lti([1.0, 0.0, 0.0], [1.0, 2 * z * w, w * w])
        _, y, _ = scipy.signal.lsim(sys, f, t, interp=True)
        acc += y
    force = scipy.signal.decimate(f, OVERSAMPLE, ftype="fir", zero_phase=True)
    acc = scipy.signal.decimate(acc, OVERSAMPLE, ftype="fir", zero_phase=True)
    force = force + 0.01 * np.abs(force).max() * rng.standard_normal(force.size)
    acc = acc + 0.01 * np.abs(acc).max() * rng.standard_normal(acc.size)
    return np.arange(force.size) / FS_HZ, force, acc


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", required=True)
    a = p.parse_args()
    t, force, acc = record()
    with open(a.output, "w") as out:
        out.write("t_s,force1_n,acc1_m_s2\n")
        for row in zip(t, force, acc):
            out.write(f"{row[0]:.6f},{row[1]:.6g},{row[2]:.6g}\n")


if __name__ == "__main__":
    main()
