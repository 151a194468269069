#!/usr/bin/python3
"""Reference resonances of the LADISK hammer record (host/lib/ident/impact_test.cpp).

Independent of vibid: the ratio of the whole record's DFTs, X / F (one hit, no window, force about
its median, acceleration about its first 20 samples), and the four most prominent maxima of |X / F|
between 5 Hz and 5 kHz by scipy.signal.find_peaks. The line spacing is 50 kHz / 50030 samples
(about 1 Hz): the values are the DFT lines, good to half a line.
Run with Debian's python3 (numpy + scipy): /usr/bin/python3 scripts/golden/ladisk_peaks.py
"""
import os

import numpy as np
from scipy import signal

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "..", "..", "shared", "data", "ladisk_impact_hammer",
                    "impact_acceleration_force.csv")
DATA = os.environ.get("LADISK_CSV", DATA)


def main():
    d = np.genfromtxt(DATA, delimiter=",", names=True)
    t = d["t_s"]
    fs = 1.0 / np.median(np.diff(t))
    f = d["force_N"] - np.median(d["force_N"])
    a = d["acceleration_g"] * 9.80665
    a = a - np.mean(a[:20])
    h = np.fft.rfft(a) / np.fft.rfft(f)
    freq = np.fft.rfftfreq(len(f), 1.0 / fs)
    band = (freq > 5.0) & (freq < 5000.0)
    mag = np.abs(h[band])
    peaks, props = signal.find_peaks(mag, prominence=0)
    strongest = sorted(np.argsort(props["prominences"])[::-1][:4])
    print("# fs_hz %.6f, line spacing %.6f Hz" % (fs, freq[1]))
    print("freq_hz,magnitude_m_s2_per_n")
    for i in strongest:
        print("%.3f,%.4f" % (freq[band][peaks[i]], mag[peaks[i]]))


if __name__ == "__main__":
    main()
