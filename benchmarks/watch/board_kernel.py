"""The board's model test (its "model stale" flag) replayed off the board, for the studies that
count its trips on a logged or replayed d_hat: the kernel's integer arithmetic, the Poisson band a
count is judged against, and running vibid.

Kernel is fixed::ResidualCusum (shared/fixed/residual_cusum.cpp) step for step on int64; the
emulator's rate study (board_flag_rate_study.py) checks it bit for bit against the board's logged
`model_g`, so the studies on other simulators count with the board's own arithmetic.
"""
import math
import subprocess

import numpy as np

I32_MAX = 0x7FFFFFFF


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    return r.stdout


def poisson_band(mean, level=0.95):
    """The central `level` interval [lo, hi] of a Poisson count of this mean (exact quantiles)."""
    tail = (1.0 - level) / 2.0
    cdf, k, p = 0.0, 0, math.exp(-mean)
    lo = None
    while True:
        cdf += p
        if lo is None and cdf > tail:
            lo = k
        if cdf >= 1.0 - tail:
            return lo, k
        k += 1
        p *= mean / k


class Kernel:
    """fixed::ResidualCusum (shared/fixed/residual_cusum.cpp) on int64, restarted after a trip.

    The first p["holdoff_windows"] windows after construction, restart() or a trip (each the
    kernel's Reset, which rearms it) are computed but not judged, as the kernel's hold-off; a
    record without the field (written before the hold-off) holds off none.
    """

    def __init__(self, p):
        self.p = p
        self.tail = np.zeros(0, dtype=np.int64)  # a window's first samples left by the last chunk
        self.holdoff_left = int(p.get("holdoff_windows", 0))
        self.g = 0
        self.trips = 0
        self.windows = 0
        self.judged_windows = 0  # windows past the hold-off: the time a trip could happen in
        self.board_g = []  # g before the first restart, for the check against the board's log
        self.first_trip_window = None  # windows fed before the first trip, counting it

    def restart(self):
        """A new acquisition: the board's test starts from rest (an empty window, g = 0)."""
        self.tail = np.zeros(0, dtype=np.int64)
        self.holdoff_left = int(self.p.get("holdoff_windows", 0))
        self.g = 0

    def feed(self, d_hat):
        p = self.p
        w = p["window_samples"]
        d = np.concatenate([self.tail, d_hat.astype(np.int64)])
        n = len(d) // w
        self.tail = d[n * w:]
        acc = d[:n * w] * p["residual_gain"] + (1 << 31)
        r = np.clip(acc >> 32, -(1 << 23), (1 << 23) - 1)
        sums = (r * r).reshape(n, w).sum(axis=1)
        e = np.clip((sums >> p["sum_shift"]) - p["center"], -I32_MAX, I32_MAX)
        half = 1 << (p["z_shift"] - 1) if p["z_shift"] > 0 else 0
        for x in e.tolist():
            if self.holdoff_left > 0:  # the observer's start transient: not judged, g stays 0
                self.holdoff_left -= 1
                self.windows += 1
                if self.trips == 0:
                    self.board_g.append(self.g)
                continue
            self.judged_windows += 1
            z = min(max((x * p["z_gain"] + half) >> p["z_shift"], -I32_MAX - 1), I32_MAX)
            self.g = min(max(0, self.g + z - p["k_q16"]), 1 << 30)
            self.windows += 1
            if self.trips == 0:
                self.board_g.append(self.g)
            if self.g > p["h_q16"]:
                if self.trips == 0:
                    self.first_trip_window = self.windows
                self.trips += 1
                self.g = 0
                self.holdoff_left = int(p.get("holdoff_windows", 0))
