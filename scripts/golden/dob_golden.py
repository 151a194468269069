#!/usr/bin/python3
"""Reference values for the disturbance-observer design tests (host/lib/dob), from scipy.signal.

Writes host/lib/dob/testdata/dob_golden.json:
  butterworth[N]      analog Butterworth denominators (scipy.signal.butter(N, 1, analog=True)),
                      ascending powers, N = 1..8
  q_n5_r4             Q(s) of methods Eq. 14, N = 5, r = 4, tau = 0.002 s, from those coefficients,
                      and its Tustin (pre-warped at 1/tau) response at fs = 5 kHz
                      (scipy.signal.bilinear_zpk with fs chosen so 2 fs = w / tan(w / 2 fs_board))
  zoh                 a 2-pole/1-zero system discretized by scipy.signal.cont2discrete(method='zoh'),
                      frequency response at test points (and q_n5_r4.zoh_response for Q)
  siso_path           Q G_A^-1 for the 2-DOF chain (force on m2 to displacement of m2), Tustin
                      pre-warped, response at test points
  lowpass             scipy.signal.butter(4, 2 Hz, fs=5000, output='sos') and sosfilt/sosfiltfilt of a
                      test signal
Run: /usr/bin/python3 scripts/golden/dob_golden.py
"""
import json
import os

import numpy as np
from scipy import signal

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "host", "lib", "dob", "testdata", "dob_golden.json")

# 2-DOF chain used across the DOB tests: ground -k1- m1 -k2- m2, dashpots c1, c2 in parallel.
M1, M2, K1, K2, C1, C2 = 2.5, 2.0, 4000.0, 3000.0, 3.0, 3.0
FS = 5000.0
TAU = 0.002
FREQS_HZ = [0.5, 5.0, 16.0, 40.0, 79.577, 150.0, 600.0, 2000.0]


def resp_zpk(z, p, k, fs, freqs):
    _, h = signal.freqz_zpk(z, p, k, worN=np.asarray(freqs), fs=fs)
    return [[float(v.real), float(v.imag)] for v in h]


def tustin_prewarped(z, p, k, w_rad_s, fs):
    # bilinear_zpk maps s = 2 fs' (z-1)/(z+1); pre-warping at w means 2 fs' = w / tan(w / (2 fs)).
    fs_eff = w_rad_s / np.tan(w_rad_s / (2.0 * fs)) / 2.0
    return signal.bilinear_zpk(z, p, k, fs_eff)


def main():
    out = {"source": "scipy " + __import__("scipy").__version__ + ", scripts/golden/dob_golden.py"}
    out["butterworth"] = {}
    for n in range(1, 9):
        _, a = signal.butter(n, 1.0, analog=True)
        out["butterworth"][str(n)] = [float(v) for v in a[::-1] / a[0]]

    # Q(s), N = 5, r = 4.
    a = np.asarray(out["butterworth"]["5"])  # ascending
    n, r = 5, 4
    den = np.array([a[k] * TAU**k for k in range(n, -1, -1)])
    num = np.array([a[k] * TAU**k for k in range(n - r, -1, -1)])
    zq, pq, kq = signal.tf2zpk(num, den)
    zd, pd, kd = tustin_prewarped(zq, pq, kq, 1.0 / TAU, FS)
    out["q_n5_r4"] = {"tau_s": TAU, "num": num.tolist(), "den": den.tolist(), "fs_hz": FS,
                      "freqs_hz": FREQS_HZ, "tustin_response": resp_zpk(zd, pd, kd, FS, FREQS_HZ)}

    # Zero-order hold of (s + 30) * 900 / (s^2 + 2 0.1 300 s + 300^2) at 5 kHz.
    num_z = [900.0, 900.0 * 30.0]
    den_z = [1.0, 60.0, 90000.0]
    bd, ad, _ = signal.cont2discrete((num_z, den_z), 1.0 / FS, method="zoh")
    _, h = signal.freqz(bd.ravel(), ad, worN=np.asarray(FREQS_HZ), fs=FS)
    out["zoh"] = {"num": num_z, "den": den_z, "fs_hz": FS, "freqs_hz": FREQS_HZ,
                  "response": [[float(v.real), float(v.imag)] for v in h]}
    # ... and of Q itself (5 poles spread over 500 rad/s, gain 1e11 in the polynomial form).
    bq, aq, _ = signal.cont2discrete((num, den), 1.0 / FS, method="zoh")
    _, h = signal.freqz(bq.ravel(), aq, worN=np.asarray(FREQS_HZ), fs=FS)
    out["q_n5_r4"]["zoh_response"] = [[float(v.real), float(v.imag)] for v in h]

    # SISO path Q G_A^-1 for the chain, force on m2 -> displacement of m2.
    # det(M s^2 + C s + K) and the (2,2) cofactor m1 s^2 + (c1+c2) s + (k1+k2).
    p11 = np.array([M1, C1 + C2, K1 + K2])
    p22 = np.array([M2, C2, K2])
    p12 = np.array([-C2, -K2])
    det = np.polysub(np.polymul(p11, p22), np.polymul(p12, p12))
    g_num = p11  # receptance H22 = p11 / det
    zg = np.roots(g_num)
    pg = np.roots(det)
    z_path = np.concatenate([zq, pg])
    p_path = np.concatenate([pq, zg])
    k_path = kq * det[0] / g_num[0]
    zd, pd, kd = tustin_prewarped(z_path, p_path, k_path, 1.0 / TAU, FS)
    out["siso_path"] = {"m": [M1, M2], "k": [K1, K2], "c": [C1, C2], "receptance_num": g_num.tolist(),
                        "receptance_den": det.tolist(), "freqs_hz": FREQS_HZ,
                        "tustin_response": resp_zpk(zd, pd, kd, FS, FREQS_HZ)}

    # Offline low-pass.
    sos = signal.butter(4, 2.0, fs=FS, output="sos")
    t = np.arange(2000) / FS
    x = np.sin(2 * np.pi * 1.0 * t) + 0.5 * np.sin(2 * np.pi * 50.0 * t) + 0.1 * (t > 0.1)
    out["lowpass"] = {"order": 4, "cutoff_hz": 2.0, "fs_hz": FS, "sos": sos.tolist(),
                      "input": x.tolist(), "sosfilt": signal.sosfilt(sos, x).tolist(),
                      "sosfiltfilt": signal.sosfiltfilt(sos, x).tolist()}
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
