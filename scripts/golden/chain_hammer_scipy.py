#!/usr/bin/python3
"""Hammer tests of a mass-spring chain simulated with scipy, independent of vibid's simulator.

The chain ground -k1- m1 -k2- m2 ... with a dashpot beside each spring is integrated exactly
(scipy.signal.lsim of its state space, first-order hold between samples) at 16 times the DAQ's
rate, and then sampled as a DAQ samples it: an anti-alias FIR low-pass (scipy.signal.decimate,
zero phase) and every 16th sample kept. The hammer is a half-sine force pulse on one mass, hit
`hits` times at a fixed spacing; each response is the acceleration of its mass. Gaussian noise of
`noise` times each channel's rms is added after sampling (seeded).

As a module: write_hammer_test(path, masses_kg, springs_n_per_m, dampers_ns_per_m, ...) writes the
CSV `vibid acquire` writes (t_s, force1_n, acc1_m_s2, ...; the responses named by `responses`).
From the command line: chain_hammer_scipy.py OUT.csv --masses 1.2,0.8 --springs 3000,2000
  --dampers 0.9,0.8 [--hammer 2] [--fs-hz 500] [--hits 5] [--spacing-s 8] [--seed 1]
"""
import argparse

import numpy as np
import scipy.signal

OVERSAMPLE = 16


def chain_matrices(masses, springs, dampers):
    """M, C, K of the chain (spring i between mass i-1, or ground, and mass i)."""
    n = len(masses)
    m = np.diag(masses)
    k = np.zeros((n, n))
    c = np.zeros((n, n))
    for i in range(n):
        for mat, v in ((k, springs[i]), (c, dampers[i])):
            mat[i, i] += v
            if i > 0:
                mat[i - 1, i - 1] += v
                mat[i, i - 1] -= v
                mat[i - 1, i] -= v
    return m, c, k


def simulate(masses, springs, dampers, hammer, fs_hz, hits, spacing_s, pulse_s=0.004,
             peak_n=50.0, noise=0.01, seed=1, lead_s=0.5):
    """(t_s, force_n, accelerations [samples x masses]) sampled at fs_hz; `hammer` from 1."""
    m, c, k = chain_matrices(np.asarray(masses, float), np.asarray(springs, float),
                             np.asarray(dampers, float))
    n = len(masses)
    minv = np.linalg.inv(m)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ c]])
    b = np.zeros((2 * n, 1))
    b[n:, 0] = minv[:, hammer - 1]
    # Output: accelerations = -M^-1 K x - M^-1 C v + M^-1 e_h f.
    cmat = np.hstack([-minv @ k, -minv @ c])
    dmat = minv[:, [hammer - 1]]
    fine_hz = fs_hz * OVERSAMPLE
    seconds = lead_s + hits * spacing_s
    samples = int(round(seconds * fs_hz)) * OVERSAMPLE
    t = np.arange(samples) / fine_hz
    f = np.zeros(samples)
    for h in range(hits):
        t0 = lead_s + h * spacing_s
        inside = (t >= t0) & (t < t0 + pulse_s)
        f[inside] = peak_n * np.sin(np.pi * (t[inside] - t0) / pulse_s)
    _, y, _ = scipy.signal.lsim((a, b, cmat, dmat), f, t, interp=True)
    y = y.reshape(samples, n)
    # The DAQ: anti-alias filter, then every OVERSAMPLE-th sample (FIR, zero phase).
    fs = scipy.signal.decimate(f, OVERSAMPLE, ftype="fir", zero_phase=True)
    ys = np.column_stack([scipy.signal.decimate(y[:, j], OVERSAMPLE, ftype="fir", zero_phase=True)
                          for j in range(n)])
    rng = np.random.default_rng(seed)
    fs = fs + noise * np.sqrt(np.mean(fs ** 2)) * rng.standard_normal(fs.size)
    for j in range(n):
        ys[:, j] += noise * np.sqrt(np.mean(ys[:, j] ** 2)) * rng.standard_normal(ys.shape[0])
    return np.arange(fs.size) / fs_hz, fs, ys


def write_hammer_test(path, masses, springs, dampers, hammer=None, responses=None, fs_hz=500.0,
                      hits=5, spacing_s=8.0, noise=0.01, seed=1):
    """Writes the CSV; `responses` names each mass's column (default acc1_m_s2, ...)."""
    n = len(masses)
    hammer = hammer or n
    names = responses or ["acc%d_m_s2" % (i + 1) for i in range(n)]
    t, f, y = simulate(masses, springs, dampers, hammer, fs_hz, hits, spacing_s, noise=noise,
                       seed=seed)
    with open(path, "w") as out:
        out.write(",".join(["t_s", "force1_n"] + names) + "\n")
        for i in range(t.size):
            out.write("%.9g,%.9g," % (t[i], f[i]) + ",".join("%.9g" % v for v in y[i]) + "\n")
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--masses", required=True)
    ap.add_argument("--springs", required=True)
    ap.add_argument("--dampers", required=True)
    ap.add_argument("--hammer", type=int, default=0)
    ap.add_argument("--responses", default="")
    ap.add_argument("--fs-hz", type=float, default=500.0)
    ap.add_argument("--hits", type=int, default=5)
    ap.add_argument("--spacing-s", type=float, default=8.0)
    ap.add_argument("--noise", type=float, default=0.01)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    vals = lambda s: [float(x) for x in s.split(",")]
    write_hammer_test(a.out, vals(a.masses), vals(a.springs), vals(a.dampers), a.hammer or None,
                      a.responses.split(",") if a.responses else None, a.fs_hz, a.hits,
                      a.spacing_s, a.noise, a.seed)


if __name__ == "__main__":
    main()
