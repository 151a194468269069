#!/usr/bin/env python3
"""The board's model test on the emulator over many seeds: how long after the built-in 3 % mass
step (host/emulator/rigs/chain2_mass_step.json, at 600 s) the board's flag trips, and whether it
stays down on the same rig without the step.

Each seed is a fresh vibid-emu (--seed): the observer is designed from the rig's truth (1 kHz,
force 1 and the last mass's position) and uploaded, a calibration day of --day-s seconds is
recorded under the `operate` scenario with it running, the model test is built from that day
(`vibid cal upload --watch-day`, default false-alarm rate), and a run of --run-s seconds under
the same scenario is logged at 200 Hz with the board's model columns. Prints one line per seed
and a summary; the figures in docs/dob.md come from it.

    /usr/bin/python3 benchmarks/watch/board_flag_study.py --build build/host --seeds 20

With VIBID_BENCH_SMOKE=1 (benchmarks/smoke.py) one seed and a run of 60 s: the same path end to
end, its figures not meaningful.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

from emulator_port import emulator_port

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    return r.stdout


def first_stale_s(path):
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["model_stale"] not in ("0", "0.0"):
                return float(row["t_s"])
    return None


def one_seed(build, seed, rig, day_s, run_s, work):
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
        run([vibid, *dev, "cal", "upload", truth, "--design", design, "--sensors", sensors])
        run([vibid, *dev, "cal", "commit"])
        run([vibid, *dev, "dob", "start"])
        day = os.path.join(work, "day.csv")
        run([vibid, *dev, "acquire", "--seconds", str(day_s), "--rate-hz", "1000", "--channels",
             "force1,x2", "--scenario", "operate", "-o", day])
        text = run([vibid, *dev, "cal", "upload", truth, "--design", design, "--sensors", sensors,
                    "--watch-day", day])
        run([vibid, *dev, "cal", "commit"])
        run([vibid, *dev, "dob", "start"])
        out = os.path.join(work, "run.csv")
        run([vibid, *dev, "acquire", "--seconds", str(run_s), "--rate-hz", "1000",
             "--log-rate-hz", "200", "--channels", "acc1,acc2", "--scenario", "operate",
             "-o", out])
        info = json.loads(run([vibid, *dev, "info", "--json"]))["model_stale"]
        return first_stale_s(out), info, text.strip()
    finally:
        emu.terminate()
        emu.wait()
        log.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build/host")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--day-s", type=float, default=500.0)
    ap.add_argument("--run-s", type=float, default=1800.0)
    ap.add_argument("--no-step", action="store_true", help="the same rig without its step")
    a = ap.parse_args()
    if os.environ.get("VIBID_BENCH_SMOKE") == "1":
        a.seeds, a.run_s = 1, 60.0
    rig = os.path.join(ROOT, "host/emulator/rigs/chain2_mass_step.json")
    with tempfile.TemporaryDirectory() as work:
        if a.no_step:
            with open(rig) as f:
                r = json.load(f)
            r.pop("changes")
            rig = os.path.join(work, "rig.json")
            with open(rig, "w") as f:
                json.dump(r, f)
        delays = []
        for seed in range(a.first_seed, a.first_seed + a.seeds):
            t, info, text = one_seed(a.build, seed, rig, a.day_s, a.run_s, work)
            delay = None if t is None else t - 600.0
            delays.append(delay)
            print(f"seed {seed:3d}: first stale record at {t if t is not None else '-'} s"
                  f" (board: {info['tripped_at_s']}); windows {info['window_samples']} samples,"
                  f" h {info['threshold']:.2f}", flush=True)
    tripped = [d for d in delays if d is not None]
    print(f"{len(tripped)} of {len(delays)} seeds tripped within {a.run_s:g} s"
          + ("" if a.no_step else " (step at 600 s)"))
    if tripped and not a.no_step:
        tripped.sort()
        before = sum(1 for d in tripped if d < 0)
        after = [d for d in tripped if d >= 0]
        print(f"before the step: {before}; after it: delays {', '.join(f'{d:.0f}' for d in after)} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
