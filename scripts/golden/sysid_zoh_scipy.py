#!/usr/bin/python3
"""Golden values for the exact (ZOH) discretization and simulation of the two-cart model.

Run from the project root:  /usr/bin/python3 scripts/golden/sysid_zoh_scipy.py
Writes host/lib/sysid/testdata/zoh_scipy.json with scipy.signal.cont2discrete (method 'zoh') and
scipy.signal.dlsim of the methods §10 two-cart position-input model X1/Xi.
"""
import json
import os

import numpy as np
import scipy
from scipy import signal

# Course rig values (methods §10: carts 0.57 kg and 0.56 kg, springs 15 N/m) with the damping the
# tests use (host/lib/sysid/testing_systems.hpp).
M1, M2, B1, B2, K, BI = 0.57, 0.56, 0.6, 0.5, 15.0, 0.25
den = np.polysub(np.polymul([M1, B1, 2 * K], [M2, B2, 2 * K]), [K * K])
num = np.polymul([BI, 2 * K], [M2, B2, 2 * K])
num, den = num / den[0], den / den[0]
dt = 0.005

numd, dend, _ = signal.cont2discrete((num, den), dt, method="zoh")
numd = np.atleast_1d(np.squeeze(numd))

n = 400
u = np.zeros(n)
u[10:] = 0.01           # step of 1 cm at sample 10
u_pulse = np.zeros(n)
u_pulse[10:30] = 0.01   # 0.1 s pulse
_, y_step = signal.dlsim((numd, dend, dt), u)
_, y_pulse = signal.dlsim((numd, dend, dt), u_pulse)

out = {
    "source": f"scipy {scipy.__version__} signal.cont2discrete(zoh) + dlsim",
    "num": num.tolist(), "den": den.tolist(), "dt_s": dt,
    "numd": numd.tolist(), "dend": np.asarray(dend).tolist(),
    "u_step": u.tolist(), "y_step": y_step[:, 0].tolist(),
    "u_pulse": u_pulse.tolist(), "y_pulse": y_pulse[:, 0].tolist(),
}
path = os.path.join(os.path.dirname(__file__), "..", "..", "host", "lib", "sysid", "testdata", "zoh_scipy.json")
with open(path, "w") as f:
    json.dump(out, f)
    f.write("\n")
