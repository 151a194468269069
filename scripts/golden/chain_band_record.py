#!/usr/bin/python3
"""A 12-bit DAQ's hammer test of a 4-mass chain hit on mass 3, simulated independently of vibid.

The chain of host/emulator/rigs/chain4.json (m 1.4, 1.2, 1.0, 0.8 kg; k 4200, 3600, 3000,
2400 N/m; c 3, 2.5, 2, 1.5 N s/m; undamped modes 3.389, 8.487, 12.809, 15.673 Hz) is simulated
by chain_hammer.py beside this file (scipy: exact zero-order-hold stepping of each complex mode,
FIR anti-aliasing and decimation as a DAQ samples), hit once by a 2 ms half-sine of 120 N on mass
3, sampled at 2 kHz. Every channel is then quantised as a 12-bit converter quantises it (the
emulator's load cell of +-500 N, 0.244 N per code; accelerometers of +-200 m/s2, 0.0977 m/s2 per
code), with 0.5 code of Gaussian noise before the rounding. The 2 ms pulse's spectrum falls by
10 dB near 590 Hz and has its first notch near 750 Hz, where the force carries nothing but the
converter's noise: H1 there is noise over noise.

Writes a recording as vibid reads it, codes 0..4095 about mid-scale 2048 as the board records
them (columns force1_counts, acc1_counts, x1_counts, acc2_counts, x2_counts: the emulator's
chain4 sensors, accelerometers on masses 1 and 3, encoders of 1e-5 m per count on 2 and 4; no
time column: 2000 Hz):
    chain_band_record.py -o host/cli/ident/testdata/chain4_hammer3_12bit.csv
    chain_band_record.py --two-mass -o host/cli/ident/testdata/two_mass_hammer2_12bit.csv
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import chain_hammer  # noqa: E402

MASSES = [1.4, 1.2, 1.0, 0.8]
SPRINGS = [4200.0, 3600.0, 3000.0, 2400.0]
DAMPERS = [3.0, 2.5, 2.0, 1.5]
FS_HZ = 2000.0
FORCE_N_PER_CODE = 1000.0 / 4096.0
ACC_M_S2_PER_CODE = 400.0 / 4096.0
M_PER_COUNT = 1e-5


def record(seconds=16.0, seed=4):
    # One hit at 0.5 s (spacing longer than the record), no noise from the simulator: the
    # converter's own noise and rounding below.
    t, force, acc, disp = chain_hammer.simulate(MASSES, SPRINGS, DAMPERS, 3, fs_hz=FS_HZ,
                                                seconds=seconds, spacing_s=2 * seconds,
                                                width_s=0.002, peak_n=120.0, noise=0.0,
                                                seed=seed, displacements=True)
    rng = np.random.default_rng(seed + 7)

    def adc(x, per_code):
        # Mid-scale 2048, clamped to 0..4095 as the converter clamps.
        c = np.round(x / per_code + 0.5 * rng.standard_normal(x.size)) + 2048
        return np.clip(c, 0, 4095).astype(int)

    # The rig's sensors: acc1 on mass 1, encoder x1 on mass 2, acc2 on mass 3, x2 on mass 4.
    cols = [adc(force, FORCE_N_PER_CODE), adc(acc[0], ACC_M_S2_PER_CODE),
            np.round(disp[1] / M_PER_COUNT).astype(int), adc(acc[2], ACC_M_S2_PER_CODE),
            np.round(disp[3] / M_PER_COUNT).astype(int)]
    return np.column_stack(cols)


def two_mass_record(seconds=38.0, seed=5):
    """The emulator's built-in rig (effective masses 1.82, 1.53 kg; k 3520, 2760 N/m; c 5, 3.5
    N s/m; modes 4.444 and 10.646 Hz) hit on mass 2 by 4 ms half-sines of 100 N every 12.5 s,
    sampled at 500 Hz by the same 12-bit converters: force1_counts, acc1_counts, acc2_counts."""
    t, force, acc = chain_hammer.simulate([1.82, 1.53], [3520.0, 2760.0], [5.0, 3.5], 2,
                                          fs_hz=500.0, seconds=seconds, spacing_s=12.5,
                                          width_s=0.004, peak_n=100.0, noise=0.0, seed=seed)
    rng = np.random.default_rng(seed + 7)

    def adc(x, per_code):
        c = np.round(x / per_code + 0.5 * rng.standard_normal(x.size)) + 2048
        return np.clip(c, 0, 4095).astype(int)

    return np.column_stack([adc(force, FORCE_N_PER_CODE), adc(acc[0], ACC_M_S2_PER_CODE),
                            adc(acc[1], ACC_M_S2_PER_CODE)])


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--two-mass", action="store_true",
                   help="the built-in 2-mass rig instead (two_mass_record)")
    p.add_argument("-o", "--output", required=True)
    a = p.parse_args()
    if a.two_mass:
        codes, names = two_mass_record(), "force1_counts,acc1_counts,acc2_counts"
    else:
        codes, names = record(), "force1_counts,acc1_counts,x1_counts,acc2_counts,x2_counts"
    with open(a.output, "w") as out:
        out.write(names + "\n")
        for row in codes:
            out.write(",".join(str(v) for v in row) + "\n")


if __name__ == "__main__":
    main()
