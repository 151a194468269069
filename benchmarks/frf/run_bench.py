#!/usr/bin/python3
"""H1 + coherence on a 3-channel record of 2^22 samples: vibid against scipy.signal.csd/welch.

Generates the record once (force + two accelerations, 2^22 samples, CSV), then times on the same
file, in one run:
  - vibid: `vibid frf-estimate` end to end (CSV read, estimation, FRF file written), the CSV read
    alone and the estimation alone (bench_frf; estimation best of 3);
  - scipy: reading the CSV with numpy, and the estimation alone (scipy.signal.csd for both
    responses, scipy.signal.welch for the auto-spectra, H1 and coherence; best of 3).
Prints a Markdown table of the wall times (process CPU time beside them: vibid's includes both
threads), the ratios of the wall times (peer / vibid) and the targets, and the load average.
Usage (from the project root, after building the host preset):
  /usr/bin/python3 benchmarks/frf/run_bench.py [BUILD_DIR]
With VIBID_BENCH_SMOKE=1 (benchmarks/smoke.py) the record is 2^14 samples and each time is taken
once: the same path end to end in seconds, its figures not meaningful.
"""
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import signal

SMOKE = os.environ.get("VIBID_BENCH_SMOKE") == "1"
N = 1 << (14 if SMOKE else 22)
FS = 2000.0
SEG = 4096
REPEATS = 1 if SMOKE else 3


def make_record(path):
    rng = np.random.default_rng(1)
    f = rng.standard_normal(N)
    # Two resonators driven by the force, plus sensor noise.
    b1, a1 = signal.butter(2, [40 / (FS / 2), 60 / (FS / 2)], btype="band")
    b2, a2 = signal.butter(2, [150 / (FS / 2), 190 / (FS / 2)], btype="band")
    x1 = signal.lfilter(b1, a1, f) + 0.01 * rng.standard_normal(N)
    x2 = signal.lfilter(b2, a2, f) + 0.01 * rng.standard_normal(N)
    t = np.arange(N) / FS
    np.savetxt(path, np.column_stack([t, f, x1, x2]), delimiter=",", fmt="%.10g",
               header="t_s,force_n,acc1_m_s2,acc2_m_s2", comments="")


def scipy_h1(f, x):
    kw = dict(fs=FS, window="hann", nperseg=SEG, noverlap=SEG // 2, detrend=False)
    _, pff = signal.welch(f, **kw)
    _, pxx = signal.welch(x, axis=-1, **kw)
    _, pfx = signal.csd(f[None, :], x, axis=-1, **kw)
    h1 = pfx / pff
    coh = np.abs(pfx) ** 2 / (pff * pxx)
    return h1, coh


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join("build", "host")
    vibid = os.path.join(build, "host", "cli", "vibid")
    bench = os.path.join(build, "benchmarks", "frf", "bench_frf")
    with tempfile.TemporaryDirectory() as tmp:
        rec = os.path.join(tmp, "rec.csv")
        t0 = time.perf_counter()
        make_record(rec)
        print(f"record: {N} samples x 3 channels, {os.path.getsize(rec) / 1e6:.0f} MB CSV ({time.perf_counter() - t0:.1f} s to write)")

        t0 = time.perf_counter()
        c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([vibid, "frf-estimate", rec, "--force", "force_n", "--response", "acc1_m_s2,acc2_m_s2",
                        "--segment", str(SEG), "--window", "hann", "--kind", "accelerance", "-o",
                        os.path.join(tmp, "frf.csv")], check=True, stdout=subprocess.DEVNULL)
        vibid_total = time.perf_counter() - t0
        c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        vibid_total_cpu = (c1.ru_utime + c1.ru_stime) - (c0.ru_utime + c0.ru_stime)
        out = subprocess.run([bench, rec, str(SEG), str(REPEATS)], check=True, capture_output=True, text=True).stdout.split()
        vibid_load = float(out[out.index("load_s") + 1])
        vibid_compute = float(out[out.index("compute_s") + 1])
        vibid_load_cpu = float(out[out.index("load_cpu_s") + 1])
        vibid_compute_cpu = float(out[out.index("compute_cpu_s") + 1])

        t0, p0 = time.perf_counter(), time.process_time()
        data = np.loadtxt(rec, delimiter=",", skiprows=1)
        scipy_load, scipy_load_cpu = time.perf_counter() - t0, time.process_time() - p0
        f, x = data[:, 1].copy(), data[:, 2:4].T.copy()
        best = best_cpu = 1e300
        for _ in range(REPEATS):
            t0, p0 = time.perf_counter(), time.process_time()
            h1, coh = scipy_h1(f, x)
            best = min(best, time.perf_counter() - t0)
            best_cpu = min(best_cpu, time.process_time() - p0)
        scipy_compute, scipy_compute_cpu = best, best_cpu

    rows = [
        (f"CSV read (2^{N.bit_length() - 1} x 4 columns)", vibid_load, vibid_load_cpu, "numpy.loadtxt", scipy_load, scipy_load_cpu, 3.0),
        ("H1 + coherence, 4096 Hann, 50 %", vibid_compute, vibid_compute_cpu, "scipy.signal csd/welch", scipy_compute,
         scipy_compute_cpu, 3.0),
        ("frf-estimate end to end", vibid_total, vibid_total_cpu, "numpy read + scipy", scipy_load + scipy_compute,
         scipy_load_cpu + scipy_compute_cpu, 2.0),
    ]
    print(f"load average at the end: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print("| path | vibid wall (CPU) | peer | peer wall (CPU) | peer / vibid, wall | target |")
    print("|---|---|---|---|---|---|")
    for name, ours, ours_cpu, peer, theirs, theirs_cpu, target in rows:
        ratio = theirs / ours
        mark = "met" if ratio >= target else "NOT met"
        print(f"| {name} | {ours:.3f} s ({ours_cpu:.3f} s) | {peer} | {theirs:.3f} s ({theirs_cpu:.3f} s) | "
              f"{ratio:.2f}x | >= {target:g}x ({mark}) |")

if __name__ == "__main__":
    main()
