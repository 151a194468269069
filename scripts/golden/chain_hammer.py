#!/usr/bin/python3
"""Hammer tests of a mass-spring chain, simulated independently of vibid (numpy/scipy only).

A chain of n masses from ground (spring k_i and damper c_i between mass i-1 and mass i, mass 0 the
ground), hit on one mass by half-sine pulses. The state space x' = A x + B F is diagonalised
(scipy.linalg.eig) and each complex mode stepped exactly under a zero-order hold of the force
(z[k+1] = e^{lambda T} z[k] + (e^{lambda T} - 1)/lambda b F[k], scipy.signal.lfilter) at eight
times the output rate; force and accelerations are then low-pass filtered and decimated
(scipy.signal.decimate, FIR, zero phase) as a DAQ's anti-alias filter and sampler would, and
Gaussian noise is added to every channel.

As a script: writes one recording CSV (t_s, force1_n, acc1_m_s2..accN_m_s2):
    chain_hammer.py --masses 1.52,1.2,0.9 --springs 3200,2600,2100 --dampers 3,2,1.5 \
        --hammer-mass 2 -o rec.csv
"""
import argparse
import csv

import numpy as np
import scipy.linalg
import scipy.signal

OVERSAMPLE = 8


def chain_matrices(masses, springs, dampers):
    """M, C, K of the chain (diagonal M; k_i, c_i tie mass i to mass i-1, mass 1 to ground)."""
    n = len(masses)
    m = np.diag(masses)
    k = np.zeros((n, n))
    c = np.zeros((n, n))
    for i in range(n):
        k[i, i] += springs[i]
        c[i, i] += dampers[i]
        if i > 0:
            k[i - 1, i - 1] += springs[i]
            k[i, i - 1] = k[i - 1, i] = -springs[i]
            c[i - 1, i - 1] += dampers[i]
            c[i, i - 1] = c[i - 1, i] = -dampers[i]
    return m, c, k


def hammer_force(fs_hz, seconds, spacing_s, width_s, peak_n, seed):
    """Half-sine pulses every spacing_s (jittered by up to 10 %), the first after 0.5 s, on a grid
    of OVERSAMPLE * fs_hz."""
    rng = np.random.default_rng(seed)
    fs = fs_hz * OVERSAMPLE
    t = np.arange(int(round(seconds * fs))) / fs
    f = np.zeros_like(t)
    start = 0.5
    while start + width_s < seconds - 0.5:
        inside = (t >= start) & (t < start + width_s)
        f[inside] += peak_n * (0.8 + 0.4 * rng.random()) * np.sin(np.pi * (t[inside] - start) /
                                                                   width_s)
        start += spacing_s * (1.0 + 0.1 * (rng.random() - 0.5))
    return f


def simulate(masses, springs, dampers, hammer_mass, fs_hz=1000.0, seconds=40.0, spacing_s=8.0,
             width_s=0.003, peak_n=50.0, noise=0.002, seed=1, displacements=False):
    """(t_s, force_n, accelerations n x samples) at fs_hz; hammer_mass counted from 1. noise: the
    standard deviation of each channel's Gaussian noise as a fraction of its largest value.
    displacements: also the masses' displacements (n x samples, sampled alike, no noise) last."""
    n = len(masses)
    m, c, k = chain_matrices(masses, springs, dampers)
    minv = np.linalg.inv(m)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ c]])
    b = np.zeros(2 * n)
    b[n + hammer_mass - 1] = 1.0 / masses[hammer_mass - 1]
    # Accelerations: the lower half of A x + B F.
    c_out = a[n:, :]
    d_out = b[n:]
    lam, v = scipy.linalg.eig(a)
    bm = np.linalg.solve(v, b)
    f = hammer_force(fs_hz, seconds, spacing_s, width_s, peak_n, seed)
    ts = 1.0 / (fs_hz * OVERSAMPLE)
    z = np.empty((2 * n, f.size), dtype=complex)
    for i in range(2 * n):
        e = np.exp(lam[i] * ts)
        gain = (e - 1.0) / lam[i] * bm[i]
        # z[k+1] = e z[k] + gain F[k]: the state at sample k is the filter's output at k-1.
        zi = scipy.signal.lfilter([0.0, gain], [1.0, -e], f.astype(complex))
        z[i] = zi
    x = (v @ z).real
    acc = c_out @ x + np.outer(d_out, f)
    force = scipy.signal.decimate(f, OVERSAMPLE, ftype="fir", zero_phase=True)
    acc = np.vstack([scipy.signal.decimate(row, OVERSAMPLE, ftype="fir", zero_phase=True)
                     for row in acc])
    rng = np.random.default_rng(seed + 1000)
    force = force + noise * np.abs(force).max() * rng.standard_normal(force.size)
    acc = acc + noise * np.abs(acc).max(axis=1, keepdims=True) * rng.standard_normal(acc.shape)
    t = np.arange(force.size) / fs_hz
    if displacements:
        disp = np.vstack([scipy.signal.decimate(row, OVERSAMPLE, ftype="fir", zero_phase=True)
                          for row in x[:n]])
        return t, force, acc, disp
    return t, force, acc


def write_recording(path, t, force, acc):
    n = acc.shape[0]
    with open(path, "w", newline="") as out:
        w = csv.writer(out)
        w.writerow(["t_s", "force1_n"] + [f"acc{i + 1}_m_s2" for i in range(n)])
        for s in range(t.size):
            w.writerow([f"{t[s]:.6f}", f"{force[s]:.7g}"] + [f"{acc[i, s]:.7g}" for i in range(n)])


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--masses", required=True)
    p.add_argument("--springs", required=True)
    p.add_argument("--dampers", required=True)
    p.add_argument("--hammer-mass", type=int, required=True, help="from 1")
    p.add_argument("--fs-hz", type=float, default=1000.0)
    p.add_argument("--seconds", type=float, default=40.0)
    p.add_argument("--spacing-s", type=float, default=8.0)
    p.add_argument("--noise", type=float, default=0.002)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("-o", "--output", required=True)
    a = p.parse_args()
    vals = [[float(x) for x in s.split(",")] for s in (a.masses, a.springs, a.dampers)]
    t, force, acc = simulate(*vals, a.hammer_mass, fs_hz=a.fs_hz, seconds=a.seconds,
                             spacing_s=a.spacing_s, noise=a.noise, seed=a.seed)
    write_recording(a.output, t, force, acc)


if __name__ == "__main__":
    main()
