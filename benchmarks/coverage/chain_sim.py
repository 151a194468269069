"""Hammer tests of a mass-spring chain, simulated independently of vibid (numpy and scipy only).

The chain ground -k1- m1 -k2- m2 - ... with a dashpot beside each spring is integrated exactly on
a fine grid (each mode of the state matrix as a first-order complex system, the force linear
between the fine samples: the first-order-hold discretisation, exact for such a force), then
sampled as a DAQ samples: a linear-phase anti-aliasing FIR (scipy.signal.resample_poly's Kaiser
window, its delay removed as a sigma-delta converter's time stamps remove it) and decimation to
the record's rate, then white noise on every channel. Coulomb friction per mass, when asked for,
makes the chain nonlinear: then the classical Runge-Kutta method integrates it at the fine rate.

The hits are half-sine pulses at continuous times (not on samples), heights and spacings drawn
from the seed.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
from scipy import signal

G_M_S2 = 9.80665


@dataclasses.dataclass
class Chain:
    masses_kg: list[float]
    springs_n_per_m: list[float]
    dampers_ns_per_m: list[float]

    @property
    def n(self) -> int:
        return len(self.masses_kg)

    def matrices(self):
        n = self.n
        m = np.diag(self.masses_kg)
        k = np.zeros((n, n))
        c = np.zeros((n, n))
        for i in range(n):
            for mat, v in ((k, self.springs_n_per_m[i]), (c, self.dampers_ns_per_m[i])):
                mat[i, i] += v
                if i > 0:
                    mat[i - 1, i - 1] += v
                    mat[i - 1, i] -= v
                    mat[i, i - 1] -= v
        return m, k, c

    def model_json(self) -> dict:
        return {"topology": "chain", "masses": list(self.masses_kg),
                "springs": list(self.springs_n_per_m), "dampers": list(self.dampers_ns_per_m)}

    def truth(self) -> dict:
        """Parameter name (m1, k1, c1, ...) -> value."""
        out = {}
        for q, vals in (("m", self.masses_kg), ("k", self.springs_n_per_m),
                        ("c", self.dampers_ns_per_m)):
            for i, v in enumerate(vals):
                out[f"{q}{i + 1}"] = v
        return out

    def natural_hz(self) -> np.ndarray:
        m, k, _ = self.matrices()
        w2 = np.linalg.eigvals(np.linalg.solve(m, k)).real
        return np.sqrt(np.sort(w2)) / (2 * math.pi)


@dataclasses.dataclass
class HammerSpec:
    hammer_mass: int  # 1-based
    fs_hz: float = 500.0
    hits: int = 5
    spacing_min_s: float = 8.0
    spacing_max_s: float = 9.0
    pulse_width_s: float = 0.004
    peak_n: float = 50.0
    peak_spread: float = 0.2
    lead_s: float = 0.2
    noise: float = 0.01  # white noise, as a fraction of each channel's largest value
    friction_n: float = 0.0  # Coulomb friction per mass
    oversample: int = 20
    seed: int = 1


def _hits(spec: HammerSpec, rng: np.random.Generator):
    times, peaks = [], []
    t = spec.lead_s
    for _ in range(spec.hits):
        times.append(t)
        peaks.append(spec.peak_n * (1 + spec.peak_spread * (2 * rng.random() - 1)))
        t += spec.spacing_min_s + (spec.spacing_max_s - spec.spacing_min_s) * rng.random()
    return np.array(times), np.array(peaks), t


def _force(t_fine, times, peaks, width_s):
    f = np.zeros_like(t_fine)
    for t0, p in zip(times, peaks):
        i0 = np.searchsorted(t_fine, t0)
        i1 = np.searchsorted(t_fine, t0 + width_s)
        tau = t_fine[i0:i1] - t0
        f[i0:i1] = p * np.sin(math.pi * tau / width_s)
    return f


def _linear_response(chain: Chain, dof: int, f, dt):
    """Accelerations (samples x n) of the linear chain to force f on `dof` (0-based), exact for a
    force linear between the samples."""
    m, k, c = chain.matrices()
    n = chain.n
    minv = np.linalg.inv(m)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ c]])
    b = np.concatenate([np.zeros(n), minv[:, dof]])
    lam, v = np.linalg.eig(a)
    bz = np.linalg.solve(v, b.astype(complex))
    # Accelerations from the state: -M^-1 [K C] (the force's direct term added below).
    out = -minv @ np.hstack([k, c]) @ v
    acc = np.zeros((f.size, n))
    for i, l in enumerate(lam):
        if l.imag < 0:
            continue  # its conjugate's twice the real part
        e = np.exp(l * dt)
        g1 = (e - 1 - l * dt) / (l * l * dt)  # weight of u[k+1]
        g0 = (e - 1) / l - g1  # weight of u[k]
        z = signal.lfilter([g1 * bz[i], g0 * bz[i]], [1.0, -e], f.astype(complex))
        acc += 2.0 * np.outer(z, out[:, i]).real
    return acc + np.outer(f, minv[:, dof])


def _friction_response(chain: Chain, dof: int, f, dt, friction_n):
    """The same with Coulomb friction of `friction_n` on every mass, as a smooth sign (tanh of
    the velocity over 0.1 mm/s), by the classical Runge-Kutta method at the fine rate (the force
    taken linear between the fine samples, as above)."""
    m, k, c = chain.matrices()
    n = chain.n
    minv = np.linalg.inv(m)
    v_eps = 1e-4
    e_dof = np.zeros(n)
    e_dof[dof] = 1.0

    def accel(x, xd, fr):
        return minv @ (-k @ x - c @ xd - friction_n * np.tanh(xd / v_eps) + e_dof * fr)

    x = np.zeros(n)
    xd = np.zeros(n)
    acc = np.zeros((f.size, n))
    acc[0] = accel(x, xd, f[0])
    for i in range(f.size - 1):
        f0, f1 = f[i], f[i + 1]
        fm = 0.5 * (f0 + f1)
        a1 = accel(x, xd, f0)
        x2, v2 = x + 0.5 * dt * xd, xd + 0.5 * dt * a1
        a2 = accel(x2, v2, fm)
        x3, v3 = x + 0.5 * dt * v2, xd + 0.5 * dt * a2
        a3 = accel(x3, v3, fm)
        x4, v4 = x + dt * v3, xd + dt * a3
        a4 = accel(x4, v4, f1)
        x = x + dt / 6 * (xd + 2 * v2 + 2 * v3 + v4)
        xd = xd + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        acc[i + 1] = accel(x, xd, f1)
    return acc


def _friction_response_batch(chain: Chain, dof: int, forces, dt, friction_n):
    """_friction_response for several forces at once (rows of `forces`, seeds x samples): the
    same Runge-Kutta steps on a state of seeds x 2n, so that one Python loop integrates every
    seed (40 seeds of a 60 s test at 10 kHz: about a minute, where one seed alone takes 40 s)."""
    m, k, c = chain.matrices()
    n = chain.n
    minv = np.linalg.inv(m)
    v_eps = 1e-4
    # Accelerations from the state (x, xd) and the applied forces (friction and hammer).
    ak = (-minv @ k).T
    ac = (-minv @ c).T
    fric_t = -friction_n * minv.T
    f_dof = minv.T[dof]  # the hammer force's row of M^-1 transposed
    inv_eps = 1.0 / v_eps

    def accel(x, xd, fr):
        return x @ ak + xd @ ac + np.tanh(xd * inv_eps) @ fric_t + fr[:, None] * f_dof

    seeds, samples = forces.shape
    x = np.zeros((seeds, n))
    xd = np.zeros((seeds, n))
    acc = np.zeros((samples, seeds, n))
    acc[0] = accel(x, xd, forces[:, 0])
    h2 = 0.5 * dt
    h6 = dt / 6
    ft = np.ascontiguousarray(forces.T)
    for i in range(samples - 1):
        f0, f1 = ft[i], ft[i + 1]
        fm = 0.5 * (f0 + f1)
        a1 = accel(x, xd, f0)
        v2 = xd + h2 * a1
        a2 = accel(x + h2 * xd, v2, fm)
        v3 = xd + h2 * a2
        a3 = accel(x + h2 * v2, v3, fm)
        v4 = xd + dt * a3
        a4 = accel(x + dt * v3, v4, f1)
        x = x + h6 * (xd + 2 * v2 + 2 * v3 + v4)
        xd = xd + h6 * (a1 + 2 * a2 + 2 * a3 + a4)
        acc[i + 1] = accel(x, xd, f1)
    return [acc[:, s, :] for s in range(seeds)]


def _sample(spec: HammerSpec, rng, f, acc, samples):
    """The DAQ: anti-aliasing FIR, linear phase, its delay removed; then the rate and the noise."""
    r = spec.oversample
    force = signal.resample_poly(f, 1, r)[:samples]
    resp = signal.resample_poly(acc, 1, r, axis=0)[:samples]
    force = force + spec.noise * np.abs(force).max() * rng.standard_normal(samples)
    for j in range(resp.shape[1]):
        resp[:, j] += spec.noise * np.abs(resp[:, j]).max() * rng.standard_normal(samples)
    t = np.arange(samples) / spec.fs_hz
    return t, force, resp


def hammer_test(chain: Chain, spec: HammerSpec):
    """(t_s, force_n, acc (samples x n)) as the DAQ records them."""
    rng = np.random.default_rng(spec.seed)
    times, peaks, end_s = _hits(spec, rng)
    r = spec.oversample
    fine_hz = spec.fs_hz * r
    samples = int(end_s * spec.fs_hz)
    t_fine = np.arange(samples * r) / fine_hz
    f = _force(t_fine, times, peaks, spec.pulse_width_s)
    dof = spec.hammer_mass - 1
    if spec.friction_n > 0:
        acc = _friction_response(chain, dof, f, 1 / fine_hz, spec.friction_n)
    else:
        acc = _linear_response(chain, dof, f, 1 / fine_hz)
    return _sample(spec, rng, f, acc, samples)


def hammer_tests(chain: Chain, specs: list[HammerSpec]):
    """hammer_test for each spec (one friction level, seeds apart), the friction cases
    integrated together: [(t_s, force_n, acc)] in the specs' order."""
    if not specs:
        return []
    if specs[0].friction_n <= 0:
        return [hammer_test(chain, s) for s in specs]
    assert all(s.friction_n == specs[0].friction_n and s.oversample == specs[0].oversample
               and s.fs_hz == specs[0].fs_hz and s.hammer_mass == specs[0].hammer_mass
               for s in specs)
    r = specs[0].oversample
    fine_hz = specs[0].fs_hz * r
    rngs, forces, lengths = [], [], []
    for s in specs:
        rng = np.random.default_rng(s.seed)
        times, peaks, end_s = _hits(s, rng)
        samples = int(end_s * s.fs_hz)
        t_fine = np.arange(samples * r) / fine_hz
        rngs.append(rng)
        forces.append(_force(t_fine, times, peaks, s.pulse_width_s))
        lengths.append(samples)
    longest = max(f.size for f in forces)
    batch = np.zeros((len(specs), longest))
    for i, f in enumerate(forces):
        batch[i, :f.size] = f
    accs = _friction_response_batch(chain, specs[0].hammer_mass - 1, batch, 1 / fine_hz,
                                    specs[0].friction_n)
    return [_sample(s, rng, f, acc[:f.size], samples)
            for s, rng, f, acc, samples in zip(specs, rngs, forces, accs, lengths)]


def write_recording(path: str, t, force, responses, names):
    """A recording as vibid reads it: t_s, force1_n, then the named responses."""
    cols = [t, force] + [responses[:, j] for j in range(responses.shape[1])]
    data = np.column_stack(cols)
    header = ",".join(["t_s", "force1_n"] + list(names))
    np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.9g")


def write_model(path: str, chain: Chain):
    with open(path, "w") as fh:
        json.dump(chain.model_json(), fh)
