#!/usr/bin/env python3
"""How soon `vibid watch` alarms on a change of the rig, and how often on none.

The rig, force and noise of reference_rate_study.py (2 masses of 2.4 and 1.1 kg, springs of 4100
and 2300 N/m, dampers of 6 and 2.5 N·s/m, a white force on mass 2 only, both accelerations at
200 Hz with 1 % noise), none of which the watch's own tests use. Its model is simulated here in
modal coordinates (each mode of the exact discrete model, force held over each sample, run by
scipy.signal.lfilter), so that the masses, springs and dampers can change while it runs: the
state is carried across each change. For each seed a 30-minute reference, then 40 minutes
watched with the change at a time drawn uniformly in 300 … 900 s (anywhere in a window of 60
blocks), the same force and noise for every case:

- mass 2 3 % heavier (a step),
- spring 2 3 % softer (a step),
- both dampers drifting to twice their values over 10 minutes,
- both springs 2 % softer: every frequency 1 % lower (a step),
- none: the rig unchanged (false alarms).

`vibid watch REC.csv --reference REF.csv --modes-s 0 --json` at its defaults (windows of 60
blocks, 0.01 false alarms per hour asked of each test, the sequential test's onsets up to 60
blocks back). The delay is the first alarm's time after the change, for the sequential test and
the window test apart. The per-block noncentrality δ² of each change is read from the full
windows after it (a window's T² is p + K/(1 + K/m) δ² on average), for Lorden's bound.

The figures in docs/watch.md come from

    /usr/bin/python3 benchmarks/watch/sequential_delay_study.py --build build/host --seeds 40

(about an hour of CPU on the shared build machine; it ran as two halves, `--seeds 20` and
`--seeds 20 --first-seed 2020`, each with `-o`, and `--summarise` of both). With VIBID_BENCH_SMOKE=1 (benchmarks/smoke.py)
two seeds of a shorter watch: the same path end to end, its figures not meaningful.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
from scipy import linalg, signal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reference_rate_study as rr  # noqa: E402  (the rig, its constants and the recording writer)

WATCH_S = 2400.0
CHUNK_S = 1.0  # a drift is held constant over each second
M, K, C = rr.MASSES_KG, rr.SPRINGS_N_PER_M, rr.DAMPERS_NS_PER_M


def constant(m=M, k=K, c=C):
    return lambda t_s: (m, k, c)


CASES = {
    "mass 2 +3 %": lambda at: lambda t: (M, K, C) if t < at else ((M[0], 1.03 * M[1]), K, C),
    "spring 2 -3 %": lambda at: lambda t: (M, K, C) if t < at else (M, (K[0], 0.97 * K[1]), C),
    "dampers x2 over 10 min": lambda at: lambda t: (
        M, K, tuple(c * (1.0 + min(max((t - at) / 600.0, 0.0), 1.0)) for c in C)),
    "frequencies -1 %": lambda at: lambda t: (
        M, K, C) if t < at else (M, tuple(0.9801 * k for k in K), C),
    "none": lambda at: constant(),
}


class ModalSimulator:
    """The rig in modal coordinates of its exact discrete model: x[n+1] = Ad x[n] + Bd u[n],
    y = Cd x + Dd u, run per mode by lfilter; parameters(t_s) gives (m, k, c) at each chunk and
    the physical state x is carried across a change."""

    def __init__(self, seed):
        self.rng = np.random.default_rng(seed)
        self.x = np.zeros(4)
        self.t_s = 0.0
        self.noise_rms = None
        self.key = None

    def _model(self, params):
        if params != self.key:
            a, b, c, d = rr.rig(*params)
            ad = linalg.expm(a / rr.FS_HZ)
            bd = np.linalg.solve(a, (ad - np.eye(4)) @ b)  # force held over the sample
            lam, v = np.linalg.eig(ad)
            self.model = (lam, v, np.linalg.inv(v), (np.linalg.inv(v) @ bd)[:, 0], c, d)
            self.key = params
        return self.model

    def next(self, n, parameters):
        force = self.rng.standard_normal(n) * 5.0
        y = np.empty((n, 2))
        step = int(round(CHUNK_S * rr.FS_HZ))
        for i in range(0, n, step):
            u = force[i:i + step]
            lam, v, vinv, bm, c, d = self._model(parameters(self.t_s))
            z0 = vinv @ self.x
            # z[j+1] = λ z[j] + bm u[j] from z[0] = z0: lfilter gives z[0 … n−1] and z[n] last.
            z = np.empty((len(u), 4), complex)
            z_next = np.empty(4, complex)
            for mode in range(4):
                z[:, mode], zf = signal.lfilter([0.0, bm[mode]], [1.0, -lam[mode]], u,
                                                zi=[z0[mode]])
                z_next[mode] = zf[0]
            y[i:i + len(u)] = (z @ v.T).real @ c.T + np.outer(u, d[:, 0])
            self.x = (z_next @ v.T).real
            self.t_s += len(u) / rr.FS_HZ
        if self.noise_rms is None:  # 1 % of each channel's RMS, fixed by the first chunk
            self.noise_rms = 0.01 * np.sqrt(np.mean(y ** 2, axis=0))
        return y + self.rng.standard_normal(y.shape) * self.noise_rms


def watch(vibid, rec, ref):
    r = subprocess.run([vibid, "watch", rec, "--reference", ref, "--modes-s", "0", "--json"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"vibid watch: exit {r.returncode}\n{r.stderr}")
    lines = [json.loads(line) for line in r.stdout.splitlines() if line.startswith("{")]
    return lines[0], [b for b in lines if "header" not in b]


def first(blocks, key, after_t_s):
    ts = [b["t_s"] for b in blocks if b[key]["alarm"] and b["t_s"] > after_t_s]
    return ts[0] if ts else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build/host")
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--first-seed", type=int, default=2000)
    ap.add_argument("-o", "--output", help="every run as JSON")
    ap.add_argument("--summarise", nargs="+", metavar="JSON",
                    help="print the tables of earlier runs' -o files instead of running")
    args = ap.parse_args()
    if args.summarise:
        summarise([r for path in args.summarise for r in json.load(open(path))])
        return 0
    watch_s = WATCH_S
    if os.environ.get("VIBID_BENCH_SMOKE") == "1":
        args.seeds, watch_s = 2, 1200.0
    vibid = os.path.join(rr.ROOT, args.build, "host", "cli", "vibid")
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        ref_path, rec_path = os.path.join(tmp, "ref.csv"), os.path.join(tmp, "rec.csv")
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            at_s = rr.REFERENCE_S + np.random.default_rng(seed + 10**6).uniform(300.0, 900.0)
            sim = ModalSimulator(seed)
            rr.write_recording(ref_path, sim.next(int(rr.REFERENCE_S * rr.FS_HZ), constant()),
                               0.0)
            state = (sim.rng.bit_generator.state, sim.x.copy(), sim.t_s)
            for case, make in CASES.items():
                sim.rng.bit_generator.state, sim.x, sim.t_s = state[0], state[1].copy(), state[2]
                rr.write_recording(rec_path, sim.next(int(watch_s * rr.FS_HZ), make(at_s)),
                                   rr.REFERENCE_S)
                header, blocks = watch(vibid, rec_path, ref_path)
                ref = header["reference"]
                row = {"seed": seed, "case": case, "at_s": at_s,
                       "sequential_threshold": ref["sequential_threshold"],
                       "sequential_band": ref["sequential_false_alarms_per_hour_95"],
                       "sequential_mean": ref["sequential_false_alarms_per_hour_mean"],
                       "window_threshold": ref["window_threshold"],
                       "sequential_before": sum(b["sequential"]["alarm"] for b in blocks
                                                if b["t_s"] <= at_s),
                       "window_before": sum(b["accumulated"]["alarm"] for b in blocks
                                            if b["t_s"] <= at_s),
                       "hours": watch_s / 3600.0}
                if case == "none":
                    row["sequential_alarms"] = sum(b["sequential"]["alarm"] for b in blocks)
                    row["window_alarms"] = sum(b["accumulated"]["alarm"] for b in blocks)
                else:
                    s = first(blocks, "sequential", at_s)
                    w = first(blocks, "accumulated", at_s)
                    row["sequential_delay_s"] = None if s is None else s - at_s
                    row["window_delay_s"] = None if w is None else w - at_s
                    onset = [b["sequential"]["onset_blocks"] for b in blocks if b["t_s"] == s]
                    row["onset_error_s"] = None if not onset else (s - 10.0 * onset[0]) - at_s
                    full = [b["accumulated"]["statistic"] for b in blocks
                            if b["accumulated"]["tested"] and b["t_s"] - 600.0 >= at_s + 600.0]
                    row["window_t2_after"] = full
                results.append(row)
                print(json.dumps({k: v for k, v in row.items() if k != "window_t2_after"}),
                      flush=True)
    summarise(results)
    if args.output:
        with open(args.output, "w") as f:
            json.dump(results, f, indent=1)
    return 0


def quartiles(x):
    """25, 50 and 75 % points (nearest rank; a change never alarmed counts as infinitely late)."""
    x = sorted(x)
    return [x[min(len(x) - 1, int(np.ceil(q * len(x))) - 1)] for q in (0.25, 0.5, 0.75)]


def summarise(results):
    p, m, k = 8, 144, 60
    print("\n| change | seeds | sequential delay s: median (quartiles) | alarmed within 5 min | "
          "window delay s: median (quartiles) | δ² per block | Lorden 2 ln(ARL)/δ² s |")
    arl_blocks = 3600.0 / 10.0 / 0.01
    for case in CASES:
        if case == "none":
            continue
        rows = [r for r in results if r["case"] == case]
        seq = [r["sequential_delay_s"] if r["sequential_delay_s"] is not None else np.inf
               for r in rows]
        win = [r["window_delay_s"] if r["window_delay_s"] is not None else np.inf for r in rows]
        t2 = [t for r in rows for t in r["window_t2_after"]]
        d2 = (np.median(t2) - p) / (k / (1.0 + k / m)) if t2 else float("nan")
        lorden = 2.0 * np.log(arl_blocks) / d2 * 10.0 if d2 > 0 else float("inf")
        sq, wq = quartiles(seq), quartiles(win)
        within = sum(1 for s in seq if s <= 300.0)
        print(f"| {case} | {len(rows)} | {sq[1]:.0f} ({sq[0]:.0f} … {sq[2]:.0f}) | {within} of "
              f"{len(rows)} | {wq[1]:.0f} ({wq[0]:.0f} … {wq[2]:.0f}) | {d2:.2f} | {lorden:.0f} |")
    none = [r for r in results if r["case"] == "none"]
    hours = sum(r["hours"] for r in none)
    print(f"\nunchanged: {len(none)} references, {hours:.1f} h: sequential alarms "
          f"{sum(r['sequential_alarms'] for r in none)} (the references' mean rates × hours: "
          f"{sum(r['sequential_mean'] * r['hours'] for r in none):.3f}), window alarms "
          f"{sum(r['window_alarms'] for r in none)}")
    changed = [r for r in results if r["case"] != "none"]
    print(f"false alarms before a change: sequential {sum(r['sequential_before'] for r in changed)}"
          f", window {sum(r['window_before'] for r in changed)}")


if __name__ == "__main__":
    sys.exit(main())
