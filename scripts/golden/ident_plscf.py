#!/usr/bin/python3
"""Reference poles of the poly-reference least-squares complex frequency method (pLSCF, "PolyMAX")
for host/lib/ident/stabilization_test.cpp, written from the method's papers:

  B. Peeters, H. Van der Auweraer, P. Guillaume, J. Leuridan, "The PolyMAX frequency-domain method:
  a new standard for modal parameter estimation?", Shock and Vibration 11 (2004) 395-409, §2.1-2.2;
  P. Guillaume, P. Verboven, S. Vanlanduit, H. Van der Auweraer, B. Peeters, "A poly-reference
  implementation of the least-squares complex frequency-domain estimator", IMAC XXI (2003).

Right matrix-fraction model with one input (the hammer): H_o(w) = B_o(W) / A(W), polynomials in
W(w) = exp(j w dt) with real coefficients. Per output o and line f the linearised error is
  E_o(f) = W_o(f) [W^0 .. W^p] beta_o - W_o(f) H_o(f) [W^0 .. W^p] alpha,
the Jacobian blocks X_o = W_o [W^r] and Y_o = -W_o H_o [W^r] give R_o = Re(X_o^H X_o),
S_o = Re(X_o^H Y_o), T_o = Re(Y_o^H Y_o); eliminating beta_o = -R_o^-1 S_o alpha leaves the
reduced normal equations M alpha = 0 with M = 2 sum_o (T_o - S_o^T R_o^-1 S_o); the constraint
alpha_p = 1 gives alpha_(0..p-1) = -M[:p,:p]^-1 M[:p,p]. The poles are the roots z of A, and
lambda = ln(z) / dt. dt = 1 / (2 f_hi): the band's highest line is the Nyquist frequency of the
z-domain basis (the paper's sampling time). Weights W_o(f) = sqrt(coherence) / max_f |H_o(f)| (the
paper's unity weighting, each output scaled to its largest value in the band).

The matrices are built explicitly here (the C++ builds their Toeplitz sequences instead) and the
roots come from numpy.roots. The FRF is the closed-form receptance of a 2-DOF chain (methods §1,
§3) with seeded complex noise and a made-up coherence, written out so both sides fit the same data.
Run with Debian's python3: /usr/bin/python3 scripts/golden/ident_plscf.py
"""
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "..", "host", "lib", "ident", "testdata")

M1, M2, K1, K2, C1, C2 = 1.2, 0.8, 3000.0, 2000.0, 0.9, 0.8
DF_HZ = 0.25
LINES = 800  # 0.25 .. 200 Hz
CASES = [  # (band min Hz, band max Hz (0: last line), order)
    (0.0, 0.0, 8),
    (2.0, 40.0, 12),
    (2.0, 40.0, 24),
]


def chain_receptance(omega):
    """Columns: response of m1 and m2 to a force on m2 (hammer at the driving point m2)."""
    jw = 1j * omega
    d11 = K1 + K2 - omega ** 2 * M1 + jw * (C1 + C2)
    d22 = K2 - omega ** 2 * M2 + jw * C2
    d12 = -K2 - jw * C2
    det = d11 * d22 - d12 * d12
    return np.stack([-d12 / det, d11 / det], axis=1)


def frf():
    rng = np.random.default_rng(20240515)
    freq = DF_HZ * np.arange(1, LINES + 1)
    h = chain_receptance(2 * np.pi * freq)
    noise = rng.standard_normal(h.shape) + 1j * rng.standard_normal(h.shape)
    h = h + 0.002 * np.abs(h) * noise
    coh = 0.9 + 0.1 * rng.random(h.shape)
    return freq, h, coh


def plscf_poles(freq, h, coh, fmin, fmax, order):
    sel = (freq > 0) & (freq >= fmin) & (freq <= (fmax if fmax > 0 else freq[-1]))
    f = freq[sel]
    dt = 1.0 / (2.0 * f[-1])
    basis = np.exp(1j * 2 * np.pi * np.outer(f, np.arange(order + 1)) * dt)  # lines x (p+1)
    m = np.zeros((order + 1, order + 1))
    for o in range(h.shape[1]):
        ho = h[sel, o]
        w = np.sqrt(coh[sel, o]) / np.max(np.abs(ho))
        x = w[:, None] * basis
        y = -(w * ho)[:, None] * basis
        r = np.real(x.conj().T @ x)
        s = np.real(x.conj().T @ y)
        t = np.real(y.conj().T @ y)
        m += 2.0 * (t - s.T @ np.linalg.solve(r, s))
    alpha = np.empty(order + 1)
    alpha[order] = 1.0
    alpha[:order] = -np.linalg.solve(m[:order, :order], m[:order, order])
    z = np.roots(alpha[::-1])  # numpy wants the highest power first
    return np.log(z.astype(complex)) / dt


def main():
    freq, h, coh = frf()
    with open(os.path.join(OUT, "plscf_frf.csv"), "w") as out:
        out.write("# 2-DOF chain receptance (m=1.2,0.8 kg; k=3000,2000 N/m; c=0.9,0.8 N*s/m), force on m2, "
                  "0.2 % complex noise, scripts/golden/ident_plscf.py\n")
        out.write("freq_hz,x1_re,x1_im,x1_coh,x2_re,x2_im,x2_coh\n")
        for k in range(len(freq)):
            out.write("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n" %
                      (freq[k], h[k, 0].real, h[k, 0].imag, coh[k, 0], h[k, 1].real, h[k, 1].imag, coh[k, 1]))
    with open(os.path.join(OUT, "plscf_poles.csv"), "w") as out:
        out.write("# pLSCF poles lambda = ln(z)/dt of plscf_frf.csv, scripts/golden/ident_plscf.py\n")
        out.write("fmin_hz,fmax_hz,order,re,im\n")
        for fmin, fmax, order in CASES:
            for lam in plscf_poles(freq, h, coh, fmin, fmax, order):
                out.write("%.17g,%.17g,%d,%.17g,%.17g\n" % (fmin, fmax, order, lam.real, lam.imag))


if __name__ == "__main__":
    main()
