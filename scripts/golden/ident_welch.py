#!/usr/bin/python3
"""Golden vectors for the Welch spectra and FRF estimators (host/lib/ident/spectral_test.cpp).

The signals are generated from integer arithmetic (a 32-bit LCG) and a fixed IIR filter so the C++
test reproduces them exactly; scipy.signal.welch/csd/coherence compute the reference spectra.
Run with Debian's python3 (numpy + scipy): /usr/bin/python3 scripts/golden/ident_welch.py
"""
import os

import numpy as np
from scipy import signal

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "..", "host", "lib", "ident", "testdata")

N = 4096
FS = 1000.0


def lcg_noise(n, seed):
    """u[k] in [-0.5, 0.5): x <- (1664525 x + 1013904223) mod 2^32, u = x / 2^32 - 0.5."""
    x = seed
    out = np.empty(n)
    for k in range(n):
        x = (1664525 * x + 1013904223) % (1 << 32)
        out[k] = x / 4294967296.0 - 0.5
    return out


def signals():
    n = np.arange(N)
    force = lcg_noise(N, 12345) + 0.5 * np.sin(0.37 * n)
    # Two resonators (poles at radius 0.98 / 0.95, angles 0.3 / 0.9 rad) as the two responses.
    b1, a1 = [0.2, 0.1, 0.0], [1.0, -2 * 0.98 * np.cos(0.3), 0.98 ** 2]
    b2, a2 = [0.0, 0.5, -0.25], [1.0, -2 * 0.95 * np.cos(0.9), 0.95 ** 2]
    y1 = signal.lfilter(b1, a1, force) + 0.05 * lcg_noise(N, 777)
    y2 = signal.lfilter(b2, a2, force) + 0.05 * lcg_noise(N, 999)
    return force, np.stack([y1, y2])


def write_case(name, window, nperseg, noverlap, detrend):
    f, ys = signals()
    kw = dict(fs=FS, window=window, nperseg=nperseg, noverlap=noverlap, detrend=detrend)
    freq, pff = signal.welch(f, **kw)
    cols = [freq, pff]
    header = ["freq_hz", "gff"]
    for j, y in enumerate(ys, start=1):
        _, pyy = signal.welch(y, **kw)
        _, pfy = signal.csd(f, y, **kw)
        _, coh = signal.coherence(f, y, **kw)
        cols += [pyy, pfy.real, pfy.imag, coh]
        header += [f"gxx{j}", f"gfx{j}_re", f"gfx{j}_im", f"coh{j}"]
    path = os.path.join(OUT, f"welch_{name}.csv")
    with open(path, "w") as fh:
        fh.write(f"# scipy {__import__('scipy').__version__} signal.welch/csd/coherence window={window} "
                 f"nperseg={nperseg} noverlap={noverlap} detrend={detrend} fs={FS}\n")
        fh.write(",".join(header) + "\n")
        for row in np.stack(cols, axis=1):
            fh.write(",".join(repr(float(v)) for v in row) + "\n")
    print("wrote", path)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    write_case("hann256", "hann", 256, 128, False)
    write_case("hamming200", "hamming", 200, 50, "constant")
