#!/usr/bin/env python3
"""The board's model test (its "model stale" flag) on a rig simulated with scipy, independent of
vibid's emulator: its trips per hour on the unchanged rig against the band its calibration day
states (two-sided), and its delay after a 3 % mass step.

The rig is not the emulator's (host/emulator/rigs/*): 2 masses of 2.4 and 1.1 kg, springs of 4100
and 2300 N/m, dampers of 6 and 2.5 N·s/m from the ground out (modes near 4.6 and 11.7 Hz), linear,
no friction. It is simulated here in the modal coordinates of its exact discrete model (the force
held over each step) at 10 kHz, so that a mass can change while it runs, the state carried over.
It is driven as the emulator's `operate` scenario drives a rig, in kind: a Gaussian force of 2 N
RMS through a 4th-order Butterworth low-pass at 50 Hz (twice the highest mode, at least 50 Hz) on
mass 2, measured by load cell 1 (force1, on mass 2 in examples/sensors.json), the observer's other
input the position of mass 2 (x2). The DAQ: both channels through one 4th-order Butterworth
anti-alias filter at 400 Hz (simultaneous sampling), every 10th sample kept (1 kHz, the observer's
rate), converter noise (0.05 N on the load cell, 1 µm on the position), the 12-bit load cell's
and the encoder's codes with the sensors file's counts per unit and offsets, and the board's own
integer calibration of those codes to Q31 (gain and shift of the record), written as `vibid
acquire` writes a calibrated recording: t_s, force1_n, x2_m (the Q31 values in SI, exactly) and
the sidecar REC.csv.json with the channels' scaling, full scales, code ranges and rails.

The observer is designed from the rig's model (`vibid dob design --fs-hz 1000 --sensors
examples/sensors.json`) and replayed bit for bit on each recording (`vibid dob run --fixed`: the
d_hat_q31 the board's kernel consumes). Per seed: a calibration day of --day-s seconds, the
board's test built from it without a board (`vibid cal build --watch-day` on the day with its
replayed d_hat_q31, which the build checks against its own replay, at each rate asked; the design
line gives the band; `-o cal.json`'s `model_test` the kernel's parameters), then:

- rate (the default): --hours of the rig unchanged, continuing from the day; the board's integer
  kernel (board_kernel.py, checked bit for bit against the board on the emulator) counts the
  trips on the replayed d_hat, restarted from rest after each, the first --settle-s seconds (the
  observer's start) left out. A day's count is inside its band when it lies between the 2.5 %
  Poisson point of the band's low end and the 97.5 % point of its high end over the hours counted,
  as board_flag_rate_study.py judges the emulator's.
- delay (--delay): the test at the default rate (0.001 per hour); --run-s seconds of the rig with
  mass 2 up 3 % at 600 s; the time from the step to the first trip (a trip before the step is a
  false alarm, said so).

    /usr/bin/python3 benchmarks/watch/board_flag_scipy_study.py --build build/host --seeds 10 --hours 0.5
    /usr/bin/python3 benchmarks/watch/board_flag_scipy_study.py --build build/host --delay --seeds 40

The figures in docs/dob.md come from those runs. With VIBID_BENCH_SMOKE=1 (benchmarks/smoke.py)
one seed, a day of 120 s and 120 s counted at 60 per hour: the same path end to end, its figures
not meaningful. --ci --check is the ctest (label coverage): one seed's day of 500 s, 0.25 h
counted at 60 per hour, failing when the count lies outside the band's 0.1 % to 99.9 % Poisson
points (a count the band cannot give at 0.2 % odds: a test that never trips, or trips several times
too often) or when `cal build` refuses the day's replayed d_hat as not its own.
"""
import argparse
import json
import os
import re
import statistics
import sys
import tempfile

import numpy as np
import pandas as pd
from scipy import linalg, signal

from board_kernel import Kernel, poisson_band, run

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SENSORS = os.path.join(ROOT, "examples/sensors.json")
MASSES_KG = (2.4, 1.1)
SPRINGS_N_PER_M = (4100.0, 2300.0)
DAMPERS_NS_PER_M = (6.0, 2.5)
SIM_HZ = 10000.0
FS_HZ = 1000.0
DECIMATION = int(SIM_HZ / FS_HZ)
FORCE_RMS_N = 2.0
FORCE_BAND_HZ = 50.0
ANTI_ALIAS_HZ = 400.0
FORCE_NOISE_N = 0.05
POSITION_NOISE_M = 1e-6
STEP_AT_S = 600.0
STEP_FRACTION = 0.03
DEFAULT_RATE = 0.001
BAND = re.compile(r"gives between (\S+) and (\S+) false alarms per hour")
CHUNK_S = 100.0


def modal(masses):
    """The rig's exact discrete model at SIM_HZ in modal coordinates: z[k+1] = mu z[k] + beta u[k],
    x = V z (x: positions then velocities), force on mass 2."""
    m = np.asarray(masses, float)
    k, c = SPRINGS_N_PER_M, DAMPERS_NS_PER_M
    stiff = np.array([[k[0] + k[1], -k[1]], [-k[1], k[1]]])
    damp = np.array([[c[0] + c[1], -c[1]], [-c[1], c[1]]])
    minv = np.diag(1.0 / m)
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-minv @ stiff, -minv @ damp]])
    b = np.concatenate([np.zeros(2), minv @ np.array([0.0, 1.0])])
    lam, v = linalg.eig(a)  # two underdamped modes: conjugate pairs, the first of each kept below
    vinv = linalg.inv(v)
    dt = 1.0 / SIM_HZ
    mu = np.exp(lam * dt)
    beta = (mu - 1.0) / lam * (vinv @ b)  # ZOH: integral of e^{lam s} over a step
    return mu, beta, v, vinv


class Rig:
    """The rig in operation, sampled by the DAQ at FS_HZ; every filter's state carried over."""

    def __init__(self, seed):
        self.rng = np.random.default_rng(seed)
        self.masses = list(MASSES_KG)
        self.mu, self.beta, self.v, self.vinv = modal(self.masses)
        self.z = np.zeros(4, complex)
        self.pair()
        self.force_sos = signal.butter(4, FORCE_BAND_HZ, fs=SIM_HZ, output="sos")
        impulse = signal.sosfilt(self.force_sos, np.r_[1.0, np.zeros(200000)])
        self.force_gain = FORCE_RMS_N / np.sqrt(np.sum(impulse ** 2))
        self.force_zi = np.zeros((self.force_sos.shape[0], 2))
        self.aa_sos = signal.butter(4, ANTI_ALIAS_HZ, fs=SIM_HZ, output="sos")
        self.aa_zi = np.zeros((2, self.aa_sos.shape[0], 2))
        self.t_s = 0.0

    def rest(self):
        """The rig stopped and started again from rest (the force's filter too), as the
        emulator starts its rig at each acquisition."""
        self.z[:] = 0.0
        self.force_zi[:] = 0.0
        self.aa_zi[:] = 0.0

    def change_mass(self, index, factor):
        """The mass changes at this instant; positions and velocities carry over."""
        x = (self.v @ self.z).real
        self.masses[index] *= factor
        self.mu, self.beta, self.v, self.vinv = modal(self.masses)
        self.z = self.vinv @ x
        self.pair()

    def pair(self):
        """Each mode's conjugate (the rig is real: its modal states come in conjugate pairs)."""
        self.partner = [int(np.argmin(abs(self.mu - np.conj(m)))) for m in self.mu]
        assert all(self.mu[i].imag != 0.0 for i in range(4)), "an overdamped mode"

    def next(self, seconds):
        """(force_n, x2_m) at FS_HZ over `seconds`, as they reach the converters."""
        n = int(round(seconds * SIM_HZ))
        assert n % DECIMATION == 0
        white = self.rng.standard_normal(n)
        force, self.force_zi = signal.sosfilt(self.force_sos, white, zi=self.force_zi)
        force *= self.force_gain
        x2 = np.zeros(n)
        row = self.v[1]  # x2 from the modal states
        for i in range(4):
            if self.mu[i].imag < 0.0:  # the conjugate of a mode run below: its part is the same
                continue
            zi = signal.lfilter([0.0, self.beta[i]], [1.0, -self.mu[i]], force,
                                zi=[self.z[i]])
            x2 += 2.0 * (row[i] * zi[0]).real
            self.z[i] = zi[1][0]
            self.z[self.partner[i]] = np.conj(self.z[i])
        out = []
        for ch, sig in enumerate((force, x2)):
            y, self.aa_zi[ch] = signal.sosfilt(self.aa_sos, sig, zi=self.aa_zi[ch])
            out.append(y[DECIMATION - 1::DECIMATION])
        self.t_s += seconds
        m = len(out[0])
        return (out[0] + FORCE_NOISE_N * self.rng.standard_normal(m),
                out[1] + POSITION_NOISE_M * self.rng.standard_normal(m))


def calibrate(raw, ch):
    """The board's calibration of converter codes (calibration_record.hpp: calibrated =
    sat32(round(((raw - offset) gain) / 2^gain_shift)), the shift arithmetic, rounding half up)
    and the SI value the log writes for it (Q31 of the full scale)."""
    acc = (raw.astype(np.int64) - ch["offset_counts"]) * ch["gain"]
    if ch["gain_shift"] > 0:
        acc = (acc + (1 << (ch["gain_shift"] - 1))) >> ch["gain_shift"]
    q31 = np.clip(acc, -(1 << 31), (1 << 31) - 1)
    return q31 * (ch["full_scale"] / 2147483648.0)


def codes(values, ch, adc_bits):
    """The converter's codes of a value: an analog input's 12 bits, an encoder's 32-bit counter."""
    raw = np.rint(values * ch["counts_per_unit"]) + ch["offset_counts"]
    lo, hi = (0, (1 << adc_bits) - 1) if adc_bits else (-(1 << 31), (1 << 31) - 1)
    return np.clip(raw, lo, hi).astype(np.int64), (lo, hi)


def column_text(raw, ch):
    """The column's values as text, each code's calibrated value formatted once (the shortest
    decimal that reads back to the same double, so the Q31 integers survive the file)."""
    values, where = np.unique(raw, return_inverse=True)
    text = np.array([repr(float(v)) for v in calibrate(values, ch)], dtype=object)
    return text[where.ravel()]


def write_recording(path, t0_s, force_n, x2_m, record):
    """A calibrated recording as `vibid acquire` writes it, with its sidecar."""
    columns = ["t_s", "force1_n", "x2_m"]
    start_ms = int(round(t0_s * 1000.0))
    text = [[f"{(start_ms + i) / 1000.0:.3f}" for i in range(len(force_n))]]
    channels = []
    for name, stem, values, bits in (("force1_n", "force1", force_n, 12),
                                     ("x2_m", "x2", x2_m, 0)):
        ch = record["channels"][stem]
        raw, code_range = codes(values, ch, bits)
        text.append(column_text(raw, ch))
        rails = [float(v) for v in calibrate(np.array(code_range), ch)]
        channels.append({"name": name, "unit_str": ch["unit"], "fs": FS_HZ,
                         "counts_per_unit": ch["counts_per_unit"],
                         "offset_counts": float(ch["offset_counts"]),
                         "full_scale": ch["full_scale"],
                         "code_range": [float(code_range[0]), float(code_range[1])],
                         "rails": rails})
    with open(path, "w") as f:
        f.write(",".join(columns) + "\n")
        f.write("\n".join(map(",".join, zip(*text))))
        f.write("\n")
    facts = {"format": "vibid-recording", "version": 2, "columns": columns, "fs": FS_HZ,
             "calibration": {"label": record["label"], "crc32": record["crc32"],
                             "created_unix_s": record["created_unix_s"]},
             "channels": channels}
    with open(path + ".json", "w") as f:
        json.dump(facts, f, indent=1)


def replay(vibid, design, rec, out):
    """The observer's d_hat_q31 on a recording, bit for bit as the board runs it."""
    run([vibid, "dob", "run", rec, "--design", design, "--force", "force1_n", "--response",
         "x2_m", "--fixed", "-o", out])
    return pd.read_csv(out, usecols=["d_hat_q31"])["d_hat_q31"].to_numpy(np.int64)


def build_test(vibid, files, day, rate, out):
    """The board's test built from the day without a board: its band and kernel parameters."""
    said = run([vibid, "cal", "build", files["model"], "--design", files["design"], "--sensors",
                SENSORS, "--watch-day", day, "--watch-false-alarms-per-hour", f"{rate:g}",
                "-o", out])
    band = BAND.search(said)
    if not band:
        sys.exit(f"no band of rates in the design's words: {said}")
    with open(out) as f:
        kernel = Kernel(json.load(f)["model_test"])
    kernel.band = (float(band.group(1)), float(band.group(2)))
    return kernel


def setup(vibid, work):
    """The rig's model, the observer designed from it, the record without a test."""
    files = {"model": os.path.join(work, "scipy_rig.json"),
             "design": os.path.join(work, "design.json")}
    with open(files["model"], "w") as f:
        json.dump({"topology": "chain", "masses": list(MASSES_KG),
                   "springs": list(SPRINGS_N_PER_M), "dampers": list(DAMPERS_NS_PER_M)}, f)
    run([vibid, "dob", "design", files["model"], "--fs-hz", f"{FS_HZ:g}", "--sensors", SENSORS,
         "-o", files["design"]])
    plain = os.path.join(work, "plain.json")
    run([vibid, "cal", "build", files["model"], "--design", files["design"], "--sensors",
         SENSORS, "-o", plain])
    with open(plain) as f:
        files["record"] = json.load(f)
    return files


def calibration_day(vibid, files, rig, day_s, work):
    """The day recorded, the observer replayed on it; the replay's file is the --watch-day."""
    rec = os.path.join(work, "day.csv")
    write_recording(rec, 0.0, *rig.next(day_s), files["record"])
    day = os.path.join(work, "day_dhat.csv")
    replay(vibid, files["design"], rec, day)
    return day


def recorded_d_hat(vibid, files, rig, seconds, work, step_at_s=None):
    """`seconds` more of the rig (mass 2 up 3 % at step_at_s into them), recorded and replayed."""
    parts, done = [], 0.0
    t0 = rig.t_s
    while done < seconds - 1e-9:
        s = min(CHUNK_S, seconds - done)
        if step_at_s is not None and done < step_at_s < done + s:
            s = step_at_s - done
        if step_at_s is not None and abs(done - step_at_s) < 1e-9:
            rig.change_mass(1, 1.0 + STEP_FRACTION)
        parts.append(rig.next(s))
        done += s
    rec = os.path.join(work, "run.csv")
    write_recording(rec, t0, np.concatenate([p[0] for p in parts]),
                    np.concatenate([p[1] for p in parts]), files["record"])
    return replay(vibid, files["design"], rec, os.path.join(work, "run_dhat.csv"))


def rate_study(a, vibid, rates, work, level=0.95):
    files = setup(vibid, work)
    settle = int(round(a.settle_s * FS_HZ))
    totals = {r: [0, 0.0] for r in rates}
    inside = {r: 0 for r in rates}
    rows = {r: [] for r in rates}
    for seed in range(a.first_seed, a.first_seed + a.seeds):
        rig = Rig(seed)
        day = calibration_day(vibid, files, rig, a.day_s, work)
        kernels = {r: build_test(vibid, files, day, r, os.path.join(work, "cal.json"))
                   for r in rates}
        d_hat = recorded_d_hat(vibid, files, rig, a.hours * 3600.0 + a.settle_s, work)
        for rate, k in kernels.items():
            k.feed(d_hat[settle:])
            p = k.p
            hours = k.judged_windows * p["window_samples"] / FS_HZ / 3600.0
            low, high = k.band
            lo, hi = poisson_band(low * hours, level)[0], poisson_band(high * hours, level)[1]
            ok = lo <= k.trips <= hi
            inside[rate] += ok
            totals[rate][0] += k.trips
            totals[rate][1] += hours
            rows[rate].append((k.trips, lo, hi, ok, p["h_q16"] / 65536.0, low, high))
            print(f"seed {seed:3d} rate {rate:g}/h: {k.trips} trips in {hours:.3f} h"
                  f" ({k.trips / hours:.1f} per hour); this calibration's band {low:.3g} to"
                  f" {high:.3g} per hour, {lo} to {hi} trips with the count's own scatter:"
                  f" {'inside' if ok else 'OUTSIDE'}; W {p['window_samples']},"
                  f" h {p['h_q16'] / 65536:.2f}", flush=True)
    print(f"\n{a.seeds} days of {a.day_s:g} s (seeds {a.first_seed} to"
          f" {a.first_seed + a.seeds - 1}), {a.hours:g} h counted after each\n")
    print("| rate asked | trips per day (band in trips with the count's scatter) | `h` |"
          " days inside | pooled: trips per hour (band's ends, mean over days) |")
    print("|---|---|---|---|---|")
    for rate in rates:
        r = rows[rate]
        trips, hours = totals[rate]
        cells = ", ".join(f"{t} ({lo}–{hi})" + ("" if ok else " **out**")
                          for t, lo, hi, ok, *_ in r)
        hs = [x[4] for x in r]
        print(f"| {rate:g} per hour | {cells} | {min(hs):.1f} to {max(hs):.1f} |"
              f" {inside[rate]} of {len(r)} | {trips / hours:.1f}"
              f" ({statistics.mean(x[5] for x in r):.1f} to {statistics.mean(x[6] for x in r):.1f}) |")
    n_in = sum(inside.values())
    n_all = sum(len(r) for r in rows.values())
    print(f"\n{n_in} of {n_all} day counts inside their bands ({100.0 * n_in / n_all:.0f} %)")
    return n_in, n_all


def delay_study(a, vibid, work):
    files = setup(vibid, work)
    delays, early, hs = [], 0, []
    for seed in range(a.first_seed, a.first_seed + a.seeds):
        rig = Rig(seed)
        day = calibration_day(vibid, files, rig, a.day_s, work)
        k = build_test(vibid, files, day, DEFAULT_RATE, os.path.join(work, "cal.json"))
        hs.append(k.p["h_q16"] / 65536.0)
        # The observer starts with the run (from rest), as after `vibid dob start`, and the
        # board's test with it; the rig starts from rest too (as the emulator's does at each
        # acquisition) unless --moving-start: then the observer starts on a rig in motion.
        if not a.moving_start:
            rig.rest()
        d_hat = recorded_d_hat(vibid, files, rig, a.run_s, work, step_at_s=STEP_AT_S)
        k.feed(d_hat)
        if k.first_trip_window is None:
            t, delay = None, None
        else:
            t = k.first_trip_window * k.p["window_samples"] / FS_HZ
            delay = t - STEP_AT_S
        if delay is not None and delay < 0:
            early += 1
        delays.append(delay)
        print(f"seed {seed:3d}: first trip at {'-' if t is None else f'{t:.2f}'} s"
              f" ({'no trip' if delay is None else f'{delay:.1f} s after the step'});"
              f" W {k.p['window_samples']}, h {k.p['h_q16'] / 65536:.2f},"
              f" hold-off {k.p.get('holdoff_windows', 0)} windows", flush=True)
    after = sorted(d for d in delays if d is not None and d >= 0)
    missed = sum(1 for d in delays if d is None)
    print(f"\n{len(delays)} seeds, a day of {a.day_s:g} s each, then {a.run_s:g} s with mass 2 up"
          f" {100 * STEP_FRACTION:g} % at {STEP_AT_S:g} s; the default rate ({DEFAULT_RATE:g} per"
          f" hour), h {min(hs):.1f} to {max(hs):.1f}")
    print(f"flagged after the step: {len(after)} of {len(delays)}; before it: {early};"
          f" not within the run: {missed}")
    if after:
        q = np.percentile(after, [25, 50, 75, 90])
        print(f"| figure | measured |\n|---|---|\n| time from the step to the flag | median"
              f" {q[1]:.0f} s, quartiles {q[0]:.0f} and {q[2]:.0f} s, 90 % within {q[3]:.0f} s,"
              f" the longest {after[-1]:.0f} s ({', '.join(f'{d:.0f}' for d in after)} s) |")
    return len(after), len(delays)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build/host")
    ap.add_argument("--vibid", help="the vibid program (default: BUILD/host/cli/vibid)")
    ap.add_argument("--ci", action="store_true",
                    help="one seed, 0.25 h at 60 per hour, judged at 99.8 %% (the ctest)")
    ap.add_argument("--check", action="store_true", help="exit 1 when a count is outside")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--rates", default="10,30,60", help="stated false alarms per hour")
    ap.add_argument("--day-s", type=float, default=500.0)
    ap.add_argument("--hours", type=float, default=0.5, help="in-control hours counted per seed")
    ap.add_argument("--settle-s", type=float, default=2.0,
                    help="seconds left out at the run's start (the observer's start)")
    ap.add_argument("--delay", action="store_true", help="the 3 %% mass step's delay instead")
    ap.add_argument("--run-s", type=float, default=1800.0, help="the step's run (--delay)")
    ap.add_argument("--moving-start", action="store_true",
                    help="--delay: the run goes on from the day, the observer starting on a "
                         "moving rig (default: the rig starts from rest)")
    a = ap.parse_args()
    if os.environ.get("VIBID_BENCH_SMOKE") == "1":
        a.seeds, a.day_s, a.hours, a.run_s, a.rates = 1, 120.0, 120.0 / 3600.0, 700.0, "60"
    level = 0.95
    if a.ci:
        a.seeds, a.hours, a.rates, a.delay, level = 1, 0.25, "60", False, 0.998
    vibid = a.vibid or os.path.join(ROOT, a.build, "host/cli/vibid")
    with tempfile.TemporaryDirectory() as work:
        if a.delay:
            flagged, seeds = delay_study(a, vibid, work)
            return 1 if a.check and flagged < seeds else 0
        inside, days = rate_study(a, vibid, [float(r) for r in a.rates.split(",")], work, level)
    return 1 if a.check and inside < days else 0


if __name__ == "__main__":
    sys.exit(main())
