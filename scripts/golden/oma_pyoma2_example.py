#!/usr/bin/python3
"""Writes pyOMA2's published 5-DOF example record (pyoma2.functions.gen.example_data) for the
output-only tests: host/lib/oma/testdata/pyoma2_example.f32, little-endian float32, 30 001 rows
of 5 accelerations (m/s^2), row after row, at 100 Hz.

The example, as pyOMA2 states it: a 5-storey shear frame, m = 25.91 kg and k = 10 000 N/m per
storey (ground spring at the last one), modal damping 0.02 in every mode, one white-noise force
per storey (numpy RandomState(12345), unit variance plus 10 % process noise drawn next), the
accelerations of the zero-order-hold discretised model (dt = 0.01 s, scipy's dlsim), then 10 %
measurement noise relative to each channel's standard deviation, drawn last from the same
generator. Natural frequencies 0.89, 2.598, 4.095, 5.261, 6.0 Hz. With the same generator and
the same order of draws, this is the record pyOMA2's example analyses.

Run: /usr/bin/python3 scripts/golden/oma_pyoma2_example.py"""
import pathlib

import numpy as np
from scipy import linalg, signal

DOF, MASS_KG, K_N_PER_M, ZETA = 5, 25.91, 10000.0, 0.02
N, DT_S, NOISE = 30001, 0.01, 0.1

m = np.eye(DOF) * MASS_KG
k = np.zeros((DOF, DOF))
for i in range(DOF - 1):
    k[i:i + 2, i:i + 2] += K_N_PER_M * np.array([[1.0, -1.0], [-1.0, 1.0]])
k[DOF - 1, DOF - 1] += K_N_PER_M
lam, phi = linalg.eigh(k, m)
omega = np.sqrt(lam)
phi = phi / np.sqrt(np.diag(phi.T @ m @ phi))
c = m @ phi @ np.diag(2.0 * ZETA * omega) @ phi.T @ m

minv = linalg.inv(m)
a = np.block([[np.zeros((DOF, DOF)), np.eye(DOF)], [-minv @ k, -minv @ c]])
b = np.vstack([np.zeros((DOF, DOF)), minv])
c_out = np.hstack([-minv @ k, -minv @ c])
d_out = minv
discrete = signal.StateSpace(a, b, c_out, d_out).to_discrete(DT_S)

rng = np.random.RandomState(12345)
u = rng.randn(N, DOF) + NOISE * rng.randn(N, DOF)
_, y, _ = signal.dlsim(discrete, u, np.arange(N) * DT_S)
y = y + rng.randn(*y.shape) * (NOISE * np.std(y, axis=0))

out = pathlib.Path(__file__).resolve().parents[2] / "host/lib/oma/testdata/pyoma2_example.f32"
y.astype("<f4").tofile(out)
print(f"{out}: {y.shape}, frequencies {omega / (2 * np.pi)} Hz")
