#!/usr/bin/python3
"""Writes recording_v1_hammer.csv: a hammer test in the form vibid wrote recordings before the JSON
sidecar (the board's sampling instants on an opening comment line, then the CSV with numbers in
shortest round-trip form), kept so that the tests check vibid still reads that form.

The rig: one mass m = 2 kg on k = 8 kN/m with 2 % damping (10.1 Hz), two 100 N half-sine hits
of 4 ms at 0.1 s and 1.1 s, sampled at 1 kHz for 3 s; the acceleration by scipy.signal.lsim of
x'' = (F - c x' - k x) / m. Run: /usr/bin/python3 make_recording_v1.py
"""
import os

import numpy as np
import scipy.signal

M, K, ZETA, FS, SECONDS = 2.0, 8000.0, 0.02, 1000.0, 3.0
C = 2 * ZETA * np.sqrt(K * M)

t = np.arange(int(FS * SECONDS)) / FS
force = np.zeros_like(t)
for t0 in (0.1, 1.1):
    inside = (t >= t0) & (t < t0 + 0.004)
    force[inside] = 100.0 * np.sin(np.pi * (t[inside] - t0) / 0.004)
# Acceleration output of the mass: a = (F - c v - k x) / m, state (x, v).
system = scipy.signal.StateSpace([[0, 1], [-K / M, -C / M]], [[0], [1 / M]], [[-K / M, -C / M]],
                                 [[1 / M]])
_, acc, _ = scipy.signal.lsim(system, force, t)
lines = ["# vibid-recording sample_instants_us=force1_n:2.667,acc1_m_s2:5.905",
         "t_s,force1_n,acc1_m_s2"]
lines += [f"{i / FS!r},{f!r},{a!r}" for i, (f, a) in enumerate(zip(force.tolist(), acc.tolist()))]
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "recording_v1_hammer.csv"),
          "w") as out:
    out.write("\n".join(lines) + "\n")
