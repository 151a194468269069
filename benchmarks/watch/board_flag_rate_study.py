#!/usr/bin/env python3
"""The board's model test in control: how many times it trips per hour on the unchanged emulator
rig (host/emulator/rigs/chain2_mass_step.json without its step) against the band of rates its
calibration day is stated to give, two-sided.

Each seed is a fresh vibid-emu (--seed): the observer from the rig's truth is uploaded and started,
a calibration day of --day-s seconds is recorded under the `operate` scenario, and the test is
built from that day once per stated rate (`vibid cal upload --watch-day
--watch-false-alarms-per-hour R`); `vibid cal show --json` gives each design's kernel parameters.
Then --hours of the same rig in operation are logged at the observer's rate with the board's
d_hat, in acquisitions of --chunk-s seconds. The board latches its flag at the first trip, so the
count is taken off-line: the board's integer kernel (shared/fixed/residual_cusum.cpp, its
arithmetic copied below) is replayed on the logged d_hat, restarting from g = 0 after each trip
as a restarted observer run does. The replay is checked against the board itself: over the first
acquisition, up to the board's own first trip, its g equals the logged `model_g` at every
window's end, bit for bit. The board restarts its test (g from 0) at each acquisition, and the
observer's own start shows in the first windows after it (z up to about 3.6 spreads in the first
0.15 s): the count restarts at each acquisition too and leaves its first --settle-s seconds out,
so that it counts the test in steady operation.

The design states, with the rate asked, the band of rates its calibration day gives on the hours
after it ("this calibration gives between x and y false alarms per hour (95 %)", the upper end the
rate asked). A trip count over T hours is, the windows being nearly independent, a renewal count
close to Poisson: a day's count is inside its band when it lies between the 2.5 % Poisson point of
x T and the 97.5 % point of y T. Per seed and rate the count, the band and the verdict are printed,
and per rate the days inside. The figures in docs/dob.md come from it.

    /usr/bin/python3 benchmarks/watch/board_flag_rate_study.py --build build/host --seeds 10 --hours 0.5

With VIBID_BENCH_SMOKE=1 (benchmarks/smoke.py) one seed, a day of 60 s and 60 s of run: the same
path end to end, its figures not meaningful.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

from board_kernel import Kernel, poisson_band, run
from emulator_port import emulator_port

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def read_log(path):
    """d_hat_q31 and model_g (Q16) of a log at the observer's rate."""
    with open(path) as f:
        names = f.readline().strip().split(",")
    cols = (names.index("d_hat_q31"), names.index("model_g"))
    a = np.loadtxt(path, delimiter=",", skiprows=1, usecols=cols, ndmin=2)
    return a[:, 0].astype(np.int64), np.rint(a[:, 1] * 65536).astype(np.int64)


def one_seed(build, seed, rig, rates, day_s, hours, chunk_s, settle_s, work):
    emu_bin = os.path.join(build, "host/emulator/vibid-emu")
    vibid = os.path.join(build, "host/cli/vibid")
    log = open(os.path.join(work, "emu.log"), "w+")
    emu = subprocess.Popen([emu_bin, "--rig", rig, "--port", "0", "--seed", str(seed)],
                           stdout=log, stderr=subprocess.STDOUT)
    try:
        port = emulator_port(emu, log, seed)
        dev = ["--device", f"usbip://127.0.0.1:{port}"]
        truth = os.path.join(work, "truth.json")
        with open(truth, "w") as f:
            f.write(run([emu_bin, "--rig", rig, "--print-truth"]))
        sensors = os.path.join(ROOT, "examples/sensors.json")
        design = os.path.join(work, "design.json")
        run([vibid, "dob", "design", truth, "--fs-hz", "1000", "--sensors", sensors, "-o", design])
        upload = [vibid, *dev, "cal", "upload", truth, "--design", design, "--sensors", sensors]
        run(upload)
        run([vibid, *dev, "cal", "commit"])
        run([vibid, *dev, "dob", "start"])
        day = os.path.join(work, "day.csv")
        run([vibid, *dev, "acquire", "--seconds", str(day_s), "--rate-hz", "1000", "--channels",
             "force1,x2", "--scenario", "operate", "-o", day])
        kernels = {}
        for rate in rates:
            said = run(upload + ["--watch-day", day, "--watch-false-alarms-per-hour", str(rate)])
            band = re.search(r"gives between (\S+) and (\S+) false alarms per hour", said)
            if not band:
                sys.exit(f"seed {seed}: no band of rates in the design's words: {said}")
            run([vibid, *dev, "cal", "commit"])
            kernels[rate] = Kernel(json.loads(run([vibid, *dev, "cal", "show", "--json"]))
                                   ["model_test"])
            kernels[rate].band = (float(band.group(1)), float(band.group(2)))
        # The board runs the last design; its own g over the first acquisition checks a replay
        # of that one from the acquisition's first sample.
        run([vibid, *dev, "dob", "start"])
        board = Kernel(kernels[rates[-1]].p)
        left = hours * 3600.0
        chunk = os.path.join(work, "chunk.csv")
        settle = int(round(settle_s * 1000.0))
        n = None
        while left > 1e-9:
            s = min(chunk_s, left)
            run([vibid, *dev, "acquire", "--seconds", f"{s + settle_s:g}", "--rate-hz", "1000",
                 "--channels", "force1,x2", "--scenario", "operate", "-o", chunk])
            d_hat, g = read_log(chunk)
            if n is None:
                board.feed(d_hat)
                w = board.p["window_samples"]
                ends = g[w - 1::w][:len(board.board_g)]
                n = len(ends)
                if n == 0 or not np.array_equal(ends, np.array(board.board_g[:n])):
                    sys.exit(f"seed {seed}: the replay's g differs from the board's logged model_g")
            for k in kernels.values():
                k.restart()
                k.feed(d_hat[settle:])
            left -= s
        os.remove(chunk)
        return kernels, n
    finally:
        emu.terminate()
        emu.wait()
        log.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build/host")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--rates", default="10,30,60", help="stated false alarms per hour")
    ap.add_argument("--day-s", type=float, default=500.0)
    ap.add_argument("--hours", type=float, default=1.5, help="in-control hours per seed")
    ap.add_argument("--chunk-s", type=float, default=1800.0,
                    help="seconds counted per acquisition")
    ap.add_argument("--settle-s", type=float, default=2.0,
                    help="seconds left out at each acquisition's start (the observer's start)")
    a = ap.parse_args()
    if os.environ.get("VIBID_BENCH_SMOKE") == "1":
        a.seeds, a.day_s, a.hours = 1, 60.0, 60.0 / 3600.0
    rates = [float(r) for r in a.rates.split(",")]
    with open(os.path.join(ROOT, "host/emulator/rigs/chain2_mass_step.json")) as f:
        rig_spec = json.load(f)
    rig_spec.pop("changes")
    totals = {r: [0, 0.0] for r in rates}
    inside = {r: 0 for r in rates}
    with tempfile.TemporaryDirectory() as work:
        rig = os.path.join(work, "rig.json")
        with open(rig, "w") as f:
            json.dump(rig_spec, f)
        for seed in range(a.first_seed, a.first_seed + a.seeds):
            kernels, checked = one_seed(a.build, seed, rig, rates, a.day_s, a.hours, a.chunk_s,
                                        a.settle_s, work)
            for rate, k in kernels.items():
                p = k.p
                hours = k.judged_windows * p["window_samples"] / 1000.0 / 3600.0
                expected = hours * 3600.0 * 1000.0 / (p["window_samples"] *
                                                      p["in_control_arl_windows"])
                low, high = k.band
                lo, hi = poisson_band(low * hours)[0], poisson_band(high * hours)[1]
                ok = lo <= k.trips <= hi
                inside[rate] += ok
                totals[rate][0] += k.trips
                totals[rate][1] += hours
                print(f"seed {seed:3d} rate {rate:g}/h: {k.trips} trips in {hours:.3f} h"
                      f" ({k.trips / hours:.1f} per hour); this calibration's band {low:.3g} to"
                      f" {high:.3g} per hour, {lo} to {hi} trips with the count's own scatter:"
                      f" {'inside' if ok else 'OUTSIDE'}; {expected:.1f} at its own estimates;"
                      f" W {p['window_samples']}, h {p['h_q16'] / 65536:.2f}", flush=True)
            print(f"seed {seed:3d}: the replay equals the board's g over its first {checked}"
                  f" windows", flush=True)
    for rate, (trips, hours) in totals.items():
        print(f"rate {rate:g}/h over {a.seeds} seeds: {trips} trips in {hours:.2f} h"
              f" ({trips / hours:.1f} per hour, {trips / hours / rate:.2f} x the rate asked);"
              f" inside this calibration's band on {inside[rate]} of {a.seeds} days")
    return 0


if __name__ == "__main__":
    sys.exit(main())
