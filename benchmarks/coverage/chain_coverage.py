#!/usr/bin/env python3
"""Coverage of `vibid identify`'s 95 % intervals on m, k and c, by an independent simulator.

Each case is a chain (2, 3 or 4 masses), the mass the hammer hits, the hits' spacing (the record
length), the noise and the friction; each seed is one hammer test simulated by chain_sim.py
(numpy/scipy, exact integration, anti-aliased and decimated as a DAQ samples), identified by
`vibid identify` as a user runs it (the driving point named), and every parameter's interval held
against the simulated chain's own value. Per case and parameter: the seeds whose interval holds
the truth, the misses below and above it, the withheld ones (with the reason vibid gives), the
bias and scatter of the estimates over the seeds, and the mean half-width against 1.96 times that
scatter (1 is an interval of the right width).

    benchmarks/coverage/chain_coverage.py --vibid build/host/host/cli/vibid [--seeds 40]
        [--case NAME ...] [--markdown table.md] [--json out.json] [--jobs 2]

`--check` turns the tallies into a pass/fail (exit 1), with bounds for the seeds run: what the
CI-sized run (host/cli/ident/CMakeLists.txt, `chain_coverage_ci`) asserts.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import chain_sim  # noqa: E402

# The rigs: truth, and a nominal model 6-10 % off (what a user starts from).
CHAINS = {
    2: (chain_sim.Chain([1.82, 1.53], [3520.0, 2760.0], [5.0, 3.5]),
        chain_sim.Chain([2.0, 1.5], [4000.0, 3000.0], [0.0, 0.0])),
    3: (chain_sim.Chain([1.0, 0.8, 0.6], [4000.0, 3000.0, 2000.0], [3.0, 2.0, 1.5]),
        chain_sim.Chain([1.07, 0.744, 0.642], [4400.0, 2700.0, 2200.0], [0.0, 0.0, 0.0])),
    4: (chain_sim.Chain([1.4, 1.2, 1.0, 0.8], [4200.0, 3600.0, 3000.0, 2400.0],
                        [3.0, 2.5, 2.0, 1.5]),
        chain_sim.Chain([1.5, 1.25, 1.0, 0.85], [4400.0, 3800.0, 3100.0, 2500.0],
                        [0.0, 0.0, 0.0, 0.0])),
}


def case(name, masses, hammer, hits=5, spacing=(8.0, 9.0), noise=0.01, friction_n=0.0,
         mass_tests=False, fs_hz=500.0, pulse_s=0.004):
    return dict(name=name, masses=masses, hammer=hammer, hits=hits, spacing=spacing, noise=noise,
                friction_n=friction_n, mass_tests=mass_tests, fs_hz=fs_hz, pulse_s=pulse_s)


# Hits 8-9 s apart on 2 and 3 masses; 20-21 s on 4, whose first mode (3.4 Hz, zeta 0.74 %) keeps
# 29 % of its amplitude after 8 s (identify withholds every interval there) and 4 % after 20 s.
CASES = [case(f"{n}-mass, hammer on {h}", n, h, spacing=(20.0, 21.0) if n == 4 else (8.0, 9.0))
         for n in (2, 3, 4) for h in range(1, n + 1)]
CASES += [
    case("3-mass, hammer on 1, hits 40 s apart", 3, 1, hits=3, spacing=(40.0, 40.0)),
    case("3-mass, hammer on 3, 3 hits 12-13 s apart", 3, 3, hits=3, spacing=(12.0, 13.0)),
    case("3-mass, hammer on 3, noise 0.3 %", 3, 3, noise=0.003),
    case("3-mass, hammer on 3, noise 3 %", 3, 3, noise=0.03),
    case("3-mass, hammer on 3, mass tests", 3, 3, mass_tests=True),
]


# `vibid update mass` on one mass alone on its spring, as the demo's mass tests are: the
# emulated rig's mass 2 (1.53 kg, 2760 N/m, 3.5 N s/m; 6.8 Hz, zeta 2.7 %), 5 kHz, hits 3.5-6.5 s
# apart, the spring fitted, with the command's defaults (no exponential window).
MASS_TESTS = [
    dict(name="1-DOF update mass, defaults", kind="mass", m=1.53, k=2760.0, c=3.5, fs=5000.0,
         hits=8, spacing=(3.5, 6.5), noise=0.005, peak_n=250.0, args=[]),
    dict(name="1-DOF update mass, defaults, noise 0.03 %", kind="mass", m=1.53, k=2760.0, c=3.5,
         fs=5000.0, hits=8, spacing=(3.5, 6.5), noise=0.0003, peak_n=250.0, args=[]),
    dict(name="1-DOF update mass, --exp-window 0.1", kind="mass", m=1.53, k=2760.0, c=3.5,
         fs=5000.0, hits=8, spacing=(3.5, 6.5), noise=0.005, peak_n=250.0,
         args=["--exp-window", "0.1"]),
]


# The CI-sized run: the cases whose intervals missed before (a true chain refused by the
# chi-square test, intervals narrower than the method's error, dampers of the mass-test path,
# update mass's defaults), a few seeds each.
CI_CASES = ["3-mass, hammer on 1, hits 40 s apart", "4-mass, hammer on 4",
            "3-mass, hammer on 3, mass tests", "1-DOF update mass, defaults"]
CI_SEEDS = 6


# The library's identification without the CLI (coverage_identify.cpp), when given.
DRIVER = ""


def run_mass_seed(vibid: str, c: dict, seed: int) -> dict:
    one = chain_sim.Chain([c["m"]], [c["k"]], [c["c"]])
    spec = chain_sim.HammerSpec(hammer_mass=1, fs_hz=c["fs"], hits=c["hits"],
                                spacing_min_s=c["spacing"][0], spacing_max_s=c["spacing"][1],
                                noise=c["noise"], peak_n=c["peak_n"], pulse_width_s=0.002,
                                oversample=8, seed=5000 + seed)
    t, f, a = chain_sim.hammer_test(one, spec)
    with tempfile.TemporaryDirectory(prefix="vibid-cov-") as d:
        rec = os.path.join(d, "mass.csv")
        chain_sim.write_recording(rec, t, f, a, ["acc1_m_s2"])
        nominal_kg = str(round(1.07 * c["m"], 3))
        cmd = [vibid, "update", "mass", rec, "--impact", "--force", "force1_n", "--response",
               "acc1_m_s2", "--nominal-kg", nominal_kg, "--json"] + c["args"]
        if DRIVER:
            cmd = [DRIVER, "mass", rec, nominal_kg] + c["args"][1:]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        return {"seed": seed, "error": r.stderr.strip().splitlines()[-1:] or ["?"],
                "exit": r.returncode}
    j = json.loads(r.stdout)
    vals = {}
    for q, key in (("m", "mass_kg"), ("k", "k_n_per_m"), ("c", "c_ns_per_m")):
        vals[q] = {"value": j[key], "ci": j.get(key + "_ci95"),
                   "missing": j.get(key + "_ci95_missing", "")}
    return {"seed": seed, "values": vals,
            "warnings": [l for l in r.stderr.splitlines() if "warning" in l]}


def truth_of(c: dict) -> dict:
    if c.get("kind") == "mass":
        return {"m": c["m"], "k": c["k"], "c": c["c"]}
    return CHAINS[c["masses"]][0].truth()


def run_seed(vibid: str, c: dict, seed: int) -> dict:
    if c.get("kind") == "mass":
        return run_mass_seed(vibid, c, seed)
    truth, nominal = CHAINS[c["masses"]]
    n = truth.n
    names = [f"acc{j + 1}_m_s2" for j in range(n)]
    with tempfile.TemporaryDirectory(prefix="vibid-cov-") as d:
        nom = os.path.join(d, "nominal.json")
        chain_sim.write_model(nom, nominal)
        spec = chain_sim.HammerSpec(hammer_mass=c["hammer"], hits=c["hits"], fs_hz=c["fs_hz"],
                                    pulse_width_s=c["pulse_s"],
                                    spacing_min_s=c["spacing"][0], spacing_max_s=c["spacing"][1],
                                    noise=c["noise"], friction_n=c["friction_n"],
                                    seed=1000 * c["masses"] + 100 * c["hammer"] + seed)
        t, f, a = chain_sim.hammer_test(truth, spec)
        rec = os.path.join(d, "modal.csv")
        chain_sim.write_recording(rec, t, f, a, names)
        cmd = [vibid, "identify", "--nominal", nom, "--modal-test", rec,
               "--modal-responses", ",".join(names), "--driving-point", str(c["hammer"]),
               "-o", os.path.join(d, "out.json"), "--report", d]
        if c["mass_tests"]:
            for p in range(n):
                one = chain_sim.Chain([truth.masses_kg[p]], [truth.springs_n_per_m[p]],
                                      [truth.dampers_ns_per_m[p]])
                ms = chain_sim.HammerSpec(hammer_mass=1, hits=c["hits"], fs_hz=c["fs_hz"],
                                          pulse_width_s=c["pulse_s"],
                                          spacing_min_s=c["spacing"][0],
                                          spacing_max_s=c["spacing"][1], noise=c["noise"],
                                          seed=spec.seed * 10 + p + 1)
                tm, fm, am = chain_sim.hammer_test(one, ms)
                path = os.path.join(d, f"mass{p + 1}.csv")
                chain_sim.write_recording(path, tm, fm, am, [f"acc{p + 1}_m_s2"])
                cmd += ["--mass-test", f"{p + 1}={path}", "--mass-spring", f"{p + 1}=fit"]
            cmd += ["--mass-response", ",".join(names)]
        if DRIVER:
            cmd = [DRIVER, "identify", nom, str(c["hammer"]), rec] + [
                os.path.join(d, f"mass{p + 1}.csv") for p in range(n) if c["mass_tests"]]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        if r.returncode != 0:
            return {"seed": seed, "error": r.stderr.strip().splitlines()[-1:] or ["?"],
                    "exit": r.returncode}
        if DRIVER:
            rep = json.loads(r.stdout)
        else:
            with open(os.path.join(d, "report.json")) as fh:
                rep = json.load(fh)
    warnings = rep.get("warnings") or [l for l in r.stderr.splitlines() if "warning" in l]
    out = {"seed": seed, "values": {}, "warnings": warnings, "chi2": rep.get("chi2"),
           "dof": rep.get("dof")}
    for p in rep["parameters"]:
        i = p["position"]
        for q, key in (("m", "m_kg"), ("k", "k_n_per_m"), ("c", "c_ns_per_m")):
            ci = p.get(key + "_ci95")
            out["values"][f"{q}{i}"] = {"value": p[key], "ci": ci,
                                        "missing": p.get(key + "_ci95_missing", "")}
    return out


def tally(c: dict, results: list[dict], truth: dict | None = None) -> dict:
    """Per parameter of `truth` (the case's chain's, by default): the seeds inside, below, above
    and withheld, the estimates' bias and scatter, and the width ratio."""
    truth = truth or truth_of(c)
    rows = {}
    for name, v in truth.items():
        t = dict(n=0, inside=0, below=0, above=0, withheld=0, absent=0, est=[], hw=[], why="")
        for r in results:
            if "values" not in r:
                continue
            # A result without the parameter (a mode the seed's test does not show) counts
            # apart: no estimate to tally.
            e = r["values"].get(name)
            if e is None:
                t["absent"] += 1
                continue
            t["n"] += 1
            t["est"].append(e["value"] / v)
            if e["ci"] is None:
                t["withheld"] += 1
                t["why"] = e["missing"]
                continue
            lo, hi = e["ci"]
            t["hw"].append(0.5 * (hi - lo) / abs(v))
            if v < lo:
                t["below"] += 1
            elif v > hi:
                t["above"] += 1
            else:
                t["inside"] += 1
        est = np.array(t["est"])
        t["bias"] = float(est.mean() - 1) if est.size else float("nan")
        t["sd"] = float(est.std(ddof=1)) if est.size > 1 else float("nan")
        t["mean_hw"] = float(np.mean(t["hw"])) if t["hw"] else float("nan")
        t["width_ratio"] = t["mean_hw"] / (1.96 * t["sd"]) if t["hw"] else float("nan")
        del t["est"], t["hw"]
        rows[name] = t
    return rows


def check(c: dict, rows: dict) -> list[str]:
    """Bounds for `seeds` seeds at a true 95 % rate: inside ~ Binomial(seeds, 0.95), misses on
    one side ~ Binomial(seeds, 0.025); the bounds below fail a true 95 % interval about once in
    a hundred per parameter (exact binomial tails). Withheld intervals must say why; the width
    ratio (too narrow) is checked where there are enough seeds for the scatter to mean something."""
    from scipy import stats
    fails = []
    for name, t in rows.items():
        known = t["n"] - t["withheld"]
        if t["withheld"]:
            if not t["why"]:
                fails.append(f"{c['name']} {name}: withheld without a reason")
            if known:
                pass
            else:
                continue
        min_inside = int(stats.binom.ppf(0.005, known, 0.95))
        max_side = int(stats.binom.ppf(0.995, known, 0.025))
        if t["inside"] < min_inside:
            fails.append(f"{c['name']} {name}: {t['inside']}/{known} inside (< {min_inside})")
        for side in ("below", "above"):
            if t[side] > max_side:
                fails.append(f"{c['name']} {name}: {t[side]} misses {side} (> {max_side})")
        # Too narrow fails; wider than the scatter is conservative, which the table states.
        if known >= 20 and not t["width_ratio"] > 0.6:
            fails.append(f"{c['name']} {name}: half-width / (1.96 sd) {t['width_ratio']:.2f}")
    return fails


def markdown(cases: list[dict], all_rows: list[dict], seeds: int) -> str:
    """One table per parameter set (2, 3, 4 masses; the 1-DOF tests), a row per case; each cell
    `inside/known (below/above) width`, width the mean half-width over 1.96 times the scatter of
    the estimates over the seeds, or `withheld` and a note with the reason."""
    groups: dict[tuple, list] = {}
    for c, rows in zip(cases, all_rows):
        groups.setdefault(tuple(rows), []).append((c, rows))
    out, notes = [], []
    for names, members in groups.items():
        out.append("| case | " + " | ".join(names) + " |")
        out.append("|---" * (len(names) + 1) + "|")
        for c, rows in members:
            cells = []
            for nm in names:
                t = rows[nm]
                known = t["n"] - t["withheld"]
                if not known:
                    if t["why"] not in notes:
                        notes.append(t["why"])
                    cells.append(f"withheld [{notes.index(t['why']) + 1}]")
                    continue
                cell = f"{t['inside']}/{known}"
                if t["below"] or t["above"]:
                    cell += f" ({t['below']}/{t['above']})"
                if not math.isnan(t["width_ratio"]) and known >= 20:
                    cell += f" {t['width_ratio']:.2f}"
                if t["withheld"]:
                    if t["why"] not in notes:
                        notes.append(t["why"])
                    cell += f", withheld {t['withheld']} [{notes.index(t['why']) + 1}]"
                if t.get("absent"):
                    cell += f", not found in {t['absent']}"
                cells.append(cell)
            name = c["name"]
            if c.get("refused"):
                name += f" (refused in {c['refused']} of {seeds}: {c['refused_why']})"
            out.append(f"| {name} | " + " | ".join(cells) + " |")
        out.append("")
    for k, w in enumerate(notes):
        out.append(f"[{k + 1}] {w}  ")
    return "\n".join(out) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vibid", help="the vibid binary")
    ap.add_argument("--driver", help="coverage_identify (the library alone) instead of vibid")
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--case", action="append", help="substring of a case name (repeatable)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--markdown")
    ap.add_argument("--json")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--verbose", action="store_true")
    ap.add_argument("--fs-hz", type=float, help="every case's sample rate instead of its own")
    ap.add_argument("--noise", type=float,
                    help="every case's noise instead of its own (0.0001: the method's own error)")
    ap.add_argument("--ci", action="store_true",
                    help="the CI-sized run: the cases of CI_CASES, CI_SEEDS seeds each")
    a = ap.parse_args()
    global DRIVER
    DRIVER = a.driver or ""
    if not (a.vibid or a.driver):
        ap.error("--vibid or --driver is needed")
    if a.ci:
        a.case = a.case or CI_CASES
        a.seeds = CI_SEEDS
    cases = [c for c in CASES + MASS_TESTS if not a.case or any(s in c["name"] for s in a.case)]
    if a.fs_hz is not None:
        cases = [dict(c, fs_hz=a.fs_hz, name=f"{c['name']} ({a.fs_hz:g} Hz)") for c in cases]
    if a.noise is not None:
        cases = [dict(c, noise=a.noise, name=f"{c['name']} (noise {100 * a.noise:g} %)")
                 for c in cases]
    if not cases:
        print("no case matches", file=sys.stderr)
        return 2
    start = time.time()
    all_rows, fails, dump = [], [], []
    seeds = range(a.first_seed, a.first_seed + a.seeds)
    for c in cases:
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
            results = list(ex.map(lambda s: run_seed(a.vibid, c, s), seeds))
        errors = [r for r in results if "error" in r]
        if errors:
            c["refused"] = len(errors)
            c["refused_why"] = errors[0]["error"][0][:160]
        for r in errors:
            fails.append(f"{c['name']} seed {r['seed']}: vibid exit {r['exit']}: {r['error']}")
        rows = tally(c, results)
        all_rows.append(rows)
        dump.append({"case": c, "rows": rows, "results": results})
        print(f"== {c['name']} ({time.time() - start:.0f} s)")
        for nm, t in rows.items():
            print(f"  {nm}: {t['inside']} inside, {t['below']} below, {t['above']} above, "
                  f"{t['withheld']} withheld; bias {100 * t['bias']:+.3f} %, sd "
                  f"{100 * t['sd']:.3f} %, hw {100 * t['mean_hw']:.3f} %, ratio "
                  f"{t['width_ratio']:.2f} {t['why'][:100]}")
        if a.verbose:
            for r in results:
                if "values" in r:
                    print("   seed", r["seed"], " ".join(
                        f"{k}={v['value']:.5g}" + ("" if v["ci"] is None else
                                                   f"[{v['ci'][0]:.5g},{v['ci'][1]:.5g}]")
                        for k, v in r["values"].items()))
                    for w in r["warnings"]:
                        print("     ", w[:200])
        if a.check:
            fails += check(c, rows)
        # After every case, so that a run stopped part way keeps what it did.
        if a.markdown:
            with open(a.markdown, "w") as fh:
                fh.write(markdown(cases[:len(all_rows)], all_rows, a.seeds))
        if a.json:
            with open(a.json, "w") as fh:
                json.dump(dump, fh, indent=1)
    print(f"total {time.time() - start:.0f} s")
    for f in fails:
        print("FAIL:", f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
