#!/usr/bin/env python3
"""How much of a viscous + Coulomb ring-down's friction term a one-pole fit puts into zeta.

A mode with viscous decay sigma and Coulomb friction rings with the envelope dA/dt = -sigma A - r
(r = 2 F_q / (pi omega) for a modal friction force F_q), A = a e^(-sigma t) - b with b = r / sigma,
until it reaches 0. Its spectrum near the resonance is X(D) = int A(t) e^(-i D t) dt (D the offset
from the damped frequency). A least-squares fit of one pole c / (s + i D) to X over +- k sigma
gives the apparent decay s; (s - sigma) / sigma is the FRF's relative zeta bias, printed here in
terms of 2 b / a (the friction term the ring-down check reads, ringdown.cpp): 2.0-2.1 terms over
+- 5 half-power half-widths, 2.3-2.6 over +- 2, 3.2-4.1 over +- 1, for b / a from 0.001 to 0.05.
The ring-down check widens zeta's interval by 5 terms where friction is suspected or found on
another mode (kFrictionTerms).

    benchmarks/coverage/friction_fit_bias.py
"""

import numpy as np
from scipy.optimize import least_squares


def fitted_decay(eps: float, band: float) -> float:
    """The fitted s for sigma = 1, A(0) = 1, b / a = eps / (1 + eps), over |D| <= band."""
    a, b = 1.0 + eps, eps
    t = np.linspace(0.0, np.log(a / b), 200001)
    env = a * np.exp(-t) - b
    d = np.linspace(-band, band, 161)
    x = np.array([np.trapz(env * np.exp(-1j * w * t), t) for w in d])

    def residual(p):
        r = x - (p[0] + 1j * p[1]) / (p[2] + 1j * d)
        return np.concatenate([r.real, r.imag])

    return least_squares(residual, [1.0, 0.0, 1.0]).x[2]


def main() -> None:
    for eps in (0.001, 0.0025, 0.005, 0.01, 0.02, 0.05):
        terms = [(fitted_decay(eps, k) - 1.0) / (2.0 * eps) for k in (1.0, 2.0, 5.0)]
        print(f"b/A0 {eps:.4f}: zeta bias in terms 2b/a over +-1, +-2, +-5 half-widths: "
              + ", ".join(f"{x:.2f}" for x in terms))


if __name__ == "__main__":
    main()
