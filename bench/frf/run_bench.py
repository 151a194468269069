#!/usr/bin/python3
"""H1 + coherence on a 3-channel record of 2^22 samples: vibid against scipy.signal.csd/welch.

Generates the record once (force + two accelerations, 2^22 samples, CSV), then times on the same
file, in one run:
  - vibid: `vibid frf-estimate` end to end (CSV read, estimation, FRF file written), and the
    estimation alone (bench_frf, best of 3);
  - scipy: reading the CSV with numpy, and the estimation alone (scipy.signal.csd for both
    responses, scipy.signal.welch for the auto-spectra, H1 and coherence; best of 3).
Prints the times and the ratios. Usage (from the project root, after building the host preset):
  /usr/bin/python3 bench/frf/run_bench.py [BUILD_DIR]
"""
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import signal

N = 1 << 22
FS = 2000.0
SEG = 4096


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
    bench = os.path.join(build, "bench", "frf", "bench_frf")
    with tempfile.TemporaryDirectory() as tmp:
        rec = os.path.join(tmp, "rec.csv")
        t0 = time.perf_counter()
        make_record(rec)
        print(f"record: {N} samples x 3 channels, {os.path.getsize(rec) / 1e6:.0f} MB CSV ({time.perf_counter() - t0:.1f} s to write)")

        t0 = time.perf_counter()
        subprocess.run([vibid, "frf-estimate", rec, "--force", "force_n", "--response", "acc1_m_s2,acc2_m_s2",
                        "--segment", str(SEG), "--window", "hann", "--kind", "accelerance", "-o",
                        os.path.join(tmp, "frf.csv")], check=True, stdout=subprocess.DEVNULL)
        vibid_total = time.perf_counter() - t0
        out = subprocess.run([bench, rec, str(SEG), "3"], check=True, capture_output=True, text=True).stdout.split()
        vibid_load = float(out[out.index("load_s") + 1])
        vibid_compute = float(out[out.index("compute_s") + 1])

        t0 = time.perf_counter()
        data = np.loadtxt(rec, delimiter=",", skiprows=1)
        scipy_load = time.perf_counter() - t0
        f, x = data[:, 1].copy(), data[:, 2:4].T.copy()
        best = 1e300
        for _ in range(3):
            t0 = time.perf_counter()
            h1, coh = scipy_h1(f, x)
            best = min(best, time.perf_counter() - t0)
        scipy_compute = best

    print(f"vibid frf-estimate end to end : {vibid_total:8.3f} s")
    print(f"vibid CSV read                : {vibid_load:8.3f} s")
    print(f"vibid H1 + coherence          : {vibid_compute:8.3f} s   (best of 3)")
    print(f"numpy.loadtxt CSV read        : {scipy_load:8.3f} s")
    print(f"scipy csd/welch H1 + coherence: {scipy_compute:8.3f} s   (best of 3)")
    print(f"ratio H1 + coherence, scipy / vibid : {scipy_compute / vibid_compute:6.2f}")
    print(f"ratio read + estimate, scipy / vibid: {(scipy_load + scipy_compute) / vibid_total:6.2f}")


if __name__ == "__main__":
    main()
