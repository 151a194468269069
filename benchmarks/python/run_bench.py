#!/usr/bin/python3
"""The Python package's cost over the library's own: frf_estimate and modes on a 2^22-sample
record (force + two accelerations of the nominal rig under a random force, 5 kHz), and the time
of `import vibid`.

Generates the record once, then in one run: bench_workflow (the library's calls, best of REPEATS),
the same calls from Python on the same input (best of REPEATS; frf_estimate on numpy arrays read
in place), and `import vibid` in fresh interpreters (best of 5, the module files in the page
cache). Library and Python runs alternate, so the machine's load hits both alike. Prints a
Markdown table with the Python / library ratios.
Usage (from the project root, after building the host preset):
  /usr/bin/python3 benchmarks/python/run_bench.py [BUILD_DIR] [REPEATS]
With VIBID_BENCH_SMOKE=1 (benchmarks/smoke.py) the record is 2^14 samples, each call runs once
and `import vibid` once: the same calls in seconds, their figures not meaningful.
"""
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import signal

SMOKE = os.environ.get("VIBID_BENCH_SMOKE") == "1"
N = 1 << (14 if SMOKE else 22)
FS = 5000.0


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join("build", "host")
    repeats = 1 if SMOKE else int(sys.argv[2]) if len(sys.argv) > 2 else 5
    pkg = os.path.join(build, "host", "python")
    sys.path.insert(0, pkg)
    import vibid

    # The nominal rig's accelerances (bilinear discretisation) driven by white noise.
    model = vibid.load_model(os.path.join("examples", "rig_nominal.json"))
    n = model.dofs
    minv = np.linalg.inv(model.m_kg)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ model.k_n_per_m, -minv @ model.c_ns_per_m]])
    b = np.concatenate([np.zeros(n), minv[:, 1]])[:, None]
    c = a[n:, :]
    d = minv[:, 1][:, None]
    rng = np.random.default_rng(1)
    f = rng.standard_normal(N)
    resp = np.empty((2, N))
    for i in range(2):
        num, den = signal.ss2tf(a, b, c[i:i + 1], d[i:i + 1])
        bz, az = signal.bilinear(num[0], den, FS)
        resp[i] = signal.lfilter(bz, az, f) + 1e-3 * rng.standard_normal(N)
    rec = vibid.Recording(names=["force_n", "acc1_m_s2", "acc2_m_s2"], data=np.vstack([f, resp]),
                          fs_hz=FS)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "rec.csv")
        rec.write_csv(path)
        force, responses = rec.data[0], rec.data[1:]  # views of the recording's array
        assert responses.flags.c_contiguous and responses.dtype == np.float64
        # Alternately, one library run and one Python run of each call, so that the machine's
        # load (2 cores shared with builds) hits both sides alike.
        lib_est, lib_modes, py_est, py_modes = [], [], [], []
        for _ in range(repeats):
            out = subprocess.run([os.path.join(build, "benchmarks", "python", "bench_workflow"), path, "1"],
                                 check=True, capture_output=True, text=True).stdout.split()
            lib_est.append(float(out[out.index("estimate_s") + 1]))
            lib_modes.append(float(out[out.index("modes_s") + 1]))
            t0 = time.perf_counter()
            vibid.frf_estimate_arrays(force, responses, FS, "force_n", ["acc1_m_s2", "acc2_m_s2"])
            py_est.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            vibid.modes(path, force="force_n", responses="acc1_m_s2,acc2_m_s2")
            py_modes.append(time.perf_counter() - t0)

    env = dict(os.environ, PYTHONPATH=pkg)
    imports = []
    for _ in range(1 if SMOKE else 5):
        t = subprocess.run([sys.executable, "-c", "import time; t = time.perf_counter(); import vibid; "
                            "print(time.perf_counter() - t)"], env=env, check=True,
                           capture_output=True, text=True).stdout
        imports.append(float(t))
    print(f"record: {N} samples x 3 channels at {FS:g} Hz; best of {repeats}; "
          f"load average {os.getloadavg()[0]:.2f}")
    print("| call | library, best (median) | Python, best (median) | Python / library, best (median) |")
    print("|---|---|---|---|")
    for name, lib, py in (("frf_estimate (arrays, Welch H1 + coherence)", lib_est, py_est),
                          ("modes (CSV read, estimation, pLSCF, JSON)", lib_modes, py_modes)):
        print(f"| {name} | {min(lib):.4f} s ({np.median(lib):.4f} s) | {min(py):.4f} s "
              f"({np.median(py):.4f} s) | {min(py) / min(lib):.3f} ({np.median(py) / np.median(lib):.3f}) |")
    print(f"| import vibid | | {min(imports):.3f} s (best of 5; worst {max(imports):.3f} s) | target < 0.2 s |")


if __name__ == "__main__":
    main()
