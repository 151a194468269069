#!/usr/bin/python3
"""Hammer tests that are not clean, and a record with no hammer, on lightly damped structures,
simulated independently of vibid (numpy/scipy only).

Structures as an analyzer records them (3.2 s per hit at 1280 Hz: lines 0.3125 Hz apart), unit
modal masses, the force and the accelerometer at one point:
  wing: 13.44 Hz (zeta 0.002) and 167.8 Hz (zeta 0.0003), as scripts/golden/sub_line_record.py;
  beam: 34.0 Hz (zeta 0.0004), 212.5 Hz (zeta 0.0008) and 596.0 Hz (zeta 0.001).
Each mode is integrated exactly as a second-order system (scipy.signal.lsim, first-order hold)
at 8 times the output rate, then low-pass filtered and decimated as a DAQ samples
(scipy.signal.decimate, FIR, zero phase), with Gaussian noise of 1 % of each channel's largest
value (`--noise`).

Excitations (`--kind`):
  hammer:    1 ms half-sine hits of 40 N (+-10 %) every `--spacing-s`, the first at `--first-s`
             (0: the hit starts on the record's first sample, as an analyzer without a
             pretrigger records it); `--rebound F --rebound-delay-s D` adds to each hit a second
             half-sine of F times its peak D seconds after it (a hammer that bounces).
  unbalance: a rotating unbalance: a sinusoidal force of 20 N at the motor speed `--motor-hz`
             (no hammer), for `--hits` times `--spacing-s` seconds.

Writes a recording as vibid reads it (t_s, force1_n, acc1_m_s2). The records in
host/cli/ident/testdata/ (hammer_records_cli_test.cpp), from the repository's root:
    G=scripts/golden/hammer_records.py D=host/cli/ident/testdata
    $G --rebound 0.12 --rebound-delay-s 0.015 --noise 0.02 -o $D/wing_rebound_noisy_force.csv
    $G --noise 0.02 --hits 2 -o $D/wing_noisy_force.csv
    $G --first-s 0 --hits 2 -o $D/wing_no_pretrigger.csv
    $G --kind unbalance --hits 2 -o $D/unbalance_no_hammer.csv
    $G --structure beam -o $D/beam_light.csv
    $G --structure beam --spacing-s 11 --hits 2 -o $D/beam_light_11s.csv
    $G --seed 12 -o $D/wing_repeat_seed12.csv   (a repeat of sub_line_wing.csv, which is --seed 11)
"""
import argparse

import numpy as np
import scipy.signal

STRUCTURES = {
    "wing": ([13.44, 167.8], [0.002, 0.0003]),
    "beam": ([34.0, 212.5, 596.0], [0.0004, 0.0008, 0.001]),
}
FS_HZ = 1280.0
OVERSAMPLE = 8
PULSE_S = 0.001


def half_sine(t, t0, peak):
    inside = (t >= t0) & (t < t0 + PULSE_S)
    out = np.zeros_like(t)
    out[inside] = peak * np.sin(np.pi * (t[inside] - t0) / PULSE_S)
    return out


def record(a):
    modes_hz, zetas = STRUCTURES[a.structure]
    fine = FS_HZ * OVERSAMPLE
    seconds = a.first_s + a.hits * a.spacing_s + (0.1 if a.first_s > 0 else 0.0)
    n = int(round(seconds * FS_HZ)) * OVERSAMPLE
    t = np.arange(n) / fine
    rng = np.random.default_rng(a.seed)
    f = np.zeros_like(t)
    if a.kind == "hammer":
        for h in range(a.hits):
            t0 = a.first_s + h * a.spacing_s
            peak = 40.0 * (0.9 + 0.2 * rng.random())
            f += half_sine(t, t0, peak)
            if a.rebound > 0.0:
                f += half_sine(t, t0 + a.rebound_delay_s, a.rebound * peak)
    else:
        phase = 2 * np.pi * rng.random()
        f = 20.0 * np.sin(2 * np.pi * a.motor_hz * t + phase)
    acc = np.zeros_like(t)
    for fn, z in zip(modes_hz, zetas):
        w = 2 * np.pi * fn
        # Acceleration over force of a unit-modal-mass mode: s^2 / (s^2 + 2 z w s + w^2).
        sys = scipy.signal.lti([1.0, 0.0, 0.0], [1.0, 2 * z * w, w * w])
        _, y, _ = scipy.signal.lsim(sys, f, t, interp=True)
        acc += y
    force = scipy.signal.decimate(f, OVERSAMPLE, ftype="fir", zero_phase=True)
    acc = scipy.signal.decimate(acc, OVERSAMPLE, ftype="fir", zero_phase=True)
    force = force + a.noise * np.abs(force).max() * rng.standard_normal(force.size)
    acc = acc + a.noise * np.abs(acc).max() * rng.standard_normal(acc.size)
    return np.arange(force.size) / FS_HZ, force, acc


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", required=True)
    p.add_argument("--structure", choices=sorted(STRUCTURES), default="wing")
    p.add_argument("--kind", choices=["hammer", "unbalance"], default="hammer")
    p.add_argument("--hits", type=int, default=3)
    p.add_argument("--spacing-s", type=float, default=3.2)
    p.add_argument("--first-s", type=float, default=0.1)
    p.add_argument("--rebound", type=float, default=0.0)
    p.add_argument("--rebound-delay-s", type=float, default=0.015)
    p.add_argument("--motor-hz", type=float, default=24.7)
    p.add_argument("--noise", type=float, default=0.01)
    p.add_argument("--seed", type=int, default=11)
    a = p.parse_args()
    t, force, acc = record(a)
    with open(a.output, "w") as out:
        out.write("t_s,force1_n,acc1_m_s2\n")
        for row in zip(t, force, acc):
            out.write(f"{row[0]:.6f},{row[1]:.6g},{row[2]:.6g}\n")


if __name__ == "__main__":
    main()
