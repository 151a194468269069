#!/usr/bin/python3
"""Reference values for the model library, computed with scipy/numpy (independent of Eigen).

Writes host/lib/model/testdata/model_golden.json:
  eigh    generalized symmetric eigenproblem K phi = w^2 M phi (scipy.linalg.eigh) of a 3-DOF model
          with a full mass matrix; shapes mass-normalised, sign: first nonzero entry positive
  lsim    exact zero-order-hold response (scipy.signal.lsim, interp=False) of the damped 2-DOF rig
          to a two-channel force table, from a nonzero initial state
  ss2tf   receptance transfer function coefficients (scipy.signal.ss2tf) of the same rig, in 1 → out 2
  frf     receptance H = (K - w^2 M + j w C)^-1 (numpy.linalg.solve) of a 3-DOF non-proportional model

Run:  /usr/bin/python3 scripts/golden/model_golden.py
"""
import json
import os

import numpy as np
import scipy.linalg
import scipy.signal

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "..", "host", "lib", "model", "testdata", "model_golden.json")


def fix_sign(shapes):
    for i in range(shapes.shape[1]):
        col = shapes[:, i]
        scale = np.max(np.abs(col))
        for v in col:
            if abs(v) > 1e-9 * scale:
                if v < 0:
                    shapes[:, i] = -col
                break
    return shapes


def state_space(m, c, k):
    n = m.shape[0]
    minv = np.linalg.inv(m)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ c]])
    b = np.vstack([np.zeros((n, n)), minv])
    return a, b


def main():
    golden = {"generator": "scripts/golden/model_golden.py", "scipy": scipy.__version__, "numpy": np.__version__}

    # eigh: 3-DOF, full (consistent) mass matrix, semidefinite-free stiffness.
    m3 = np.array([[2.0, 0.3, 0.0], [0.3, 1.5, 0.2], [0.0, 0.2, 1.0]])
    k3 = np.array([[7000.0, -3000.0, 0.0], [-3000.0, 5000.0, -2000.0], [0.0, -2000.0, 2000.0]])
    w2, phi = scipy.linalg.eigh(k3, m3)
    golden["eigh"] = {
        "M": m3.tolist(), "K": k3.tolist(),
        "omega_rad_s": np.sqrt(w2).tolist(),
        "shapes": fix_sign(phi).tolist(),  # columns are modes
    }

    # lsim: damped 2-DOF chain (rig A-like), force table on both DOFs, nonzero initial state.
    m = np.diag([2.0, 1.5])
    k = np.array([[7000.0, -3000.0], [-3000.0, 3000.0]])
    c = np.array([[3.0, -1.0], [-1.0, 1.0]])
    a, b = state_space(m, c, k)
    cmat = np.hstack([np.eye(2), np.zeros((2, 2))])
    dmat = np.zeros((2, 2))
    dt = 1e-3
    t = np.arange(400) * dt
    rng = np.random.default_rng(7)
    u = np.zeros((t.size, 2))
    u[20:60, 0] = 5.0                       # a 40 ms pulse on DOF 1
    u[:, 1] = rng.normal(0.0, 1.0, t.size)  # broadband force on DOF 2
    x0 = np.array([1e-3, -2e-3, 0.05, 0.0])
    _, y, _ = scipy.signal.lsim((a, b, cmat, dmat), u, t, X0=x0, interp=False)
    golden["lsim"] = {
        "M": m.tolist(), "C": c.tolist(), "K": k.tolist(),
        "dt_s": dt, "t_s": t.tolist(), "force_n": u.tolist(),
        "x0_m": x0[:2].tolist(), "v0_m_s": x0[2:].tolist(),
        "x_m": y.tolist(),
    }

    # ss2tf: receptance input DOF 1 → output DOF 2 of the same rig.
    num, den = scipy.signal.ss2tf(a, b, cmat, dmat, input=0)
    num = num[1]
    # ss2tf leaves rounding residue (~1e-14) in the leading coefficients that are zero by
    # structure; drop those, judged at the rig's frequency scale a0^(1/order).
    scale = den[-1] ** (1.0 / (den.size - 1))
    weighted = np.abs(num) * scale ** np.arange(num.size - 1, -1, -1)
    num = num[np.argmax(weighted > 1e-9 * weighted.max()):]
    golden["ss2tf"] = {
        "M": m.tolist(), "C": c.tolist(), "K": k.tolist(), "input_dof": 1, "output_dof": 2,
        "num": num.tolist(), "den": den.tolist(),
    }

    # frf: 3-DOF non-proportional damping, H[out, in] at a few frequencies.
    c3 = np.array([[4.0, -1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 0.5]])
    omegas = np.array([1.0, 20.0, 45.0, 60.0, 80.0, 150.0])
    h = np.array([np.linalg.solve(k3 - w * w * m3 + 1j * w * c3, np.eye(3)) for w in omegas])
    golden["frf"] = {
        "M": m3.tolist(), "C": c3.tolist(), "K": k3.tolist(), "omega_rad_s": omegas.tolist(),
        "input_dof": 1, "output_dof": 3,
        "re": h[:, 2, 0].real.tolist(), "im": h[:, 2, 0].imag.tolist(),
    }

    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(golden, f, indent=1)
        f.write("\n")
    print("wrote", os.path.relpath(OUT))


if __name__ == "__main__":
    main()
