#!/usr/bin/python3
"""The trend of a watched recording (docs/watch.md's figure): vibid.watch over a recording as
`vibid acquire` writes it, then each mode's frequency and damping ratio with their 95 % intervals
block by block against the reference's, the window test's T² against its threshold (and each
block's T², shown), and the alarm.

usage: examples/watch_trend.py REC.csv -o FIGURE.png [--mark-s T] [--mark-label TEXT]
                               [--reference-s S] [--modes-s S] [--block-s S] [--window-blocks N]

--mark-s draws a known change's time (the emulator rig file's step). The analysis options are
vibid watch's, with its defaults. Prints the reference and the first alarm. Needs matplotlib.
PYTHONPATH names the package (build/host/host/python in the build tree)."""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import vibid  # noqa: E402

COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:purple"]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("recording")
    p.add_argument("-o", "--output", required=True, help="the figure (PNG)")
    p.add_argument("--mark-s", type=float, help="time of a known change, s")
    p.add_argument("--mark-label", default="change", help="its label")
    p.add_argument("--reference-s", type=float, default=1800.0)
    p.add_argument("--modes-s", type=float, default=120.0)
    p.add_argument("--block-s", type=float, default=10.0)
    p.add_argument("--window-blocks", type=int, default=60)
    a = p.parse_args()

    w = vibid.watch(a.recording, reference_s=a.reference_s, modes_s=a.modes_s,
                    block_s=a.block_s, window_blocks=a.window_blocks)
    ref = w.reference
    blocks = list(w)
    print(f"reference of {ref.seconds:.0f} s: " + ", ".join(
        f"{m.freq_hz:.3f} ± {m.freq_ci95_hz:.3f} Hz (ζ {100 * m.zeta:.2f} %)" for m in ref.modes))
    first = blocks[-1].first_alarm_t_s if blocks else None
    print(f"{len(blocks)} blocks; first alarm at {first:.0f} s" if first is not None else
          f"{len(blocks)} blocks; no alarm")

    n_modes = len(ref.modes)
    fig, axes = plt.subplots(n_modes + 2, 1, sharex=True, figsize=(9, 2.3 * (n_modes + 2)),
                             constrained_layout=True)
    t_end = blocks[-1].t_s if blocks else ref.seconds
    t_ref = blocks[0].t_s - a.block_s if blocks else ref.seconds

    def matched(b, k):
        """Block b's mode nearest the reference's mode k in frequency (within 20 %), or None."""
        near = [m for m in b.modes if abs(m.omega_rad_s / ref.modes[k].omega_rad_s - 1) < 0.2]
        return min(near, key=lambda m: abs(m.omega_rad_s - ref.modes[k].omega_rad_s),
                   default=None)

    def series(k, value, half):
        t, v, h = [], [], []
        for b in blocks:
            m = matched(b, k)
            if m is not None:
                t.append(b.t_s)
                v.append(value(m))
                h.append(half(m))
        return np.array(t), np.array(v), np.array(h)

    def reference_band(ax, value, half, colour):
        r_v, r_h = value, half
        ax.axhspan(r_v - r_h, r_v + r_h, color=colour, alpha=0.12, lw=0)
        ax.axhline(r_v, color=colour, lw=1, ls="--")

    # Each mode's frequency, its own panel (their scales differ).
    for k, rm in enumerate(ref.modes):
        ax = axes[k]
        c = COLOURS[k % len(COLOURS)]
        reference_band(ax, rm.freq_hz, rm.freq_ci95_hz, c)
        t, v, h = series(k, lambda m: m.freq_hz, lambda m: m.freq_ci95_hz)
        ax.fill_between(t, v - h, v + h, color=c, alpha=0.3, lw=0, label="95 % interval")
        ax.plot(t, v, ".-", color=c, ms=3, lw=1,
                label=f"mode {k + 1}, last {a.modes_s:g} s at each block")
        ax.plot([], [], color=c, ls="--", lw=1,
                label=f"reference {rm.freq_hz:.3f} ± {rm.freq_ci95_hz:.3f} Hz")
        ax.set_ylabel(f"mode {k + 1} (Hz)")
        ax.legend(loc="lower left", fontsize=8, ncol=3)

    # Damping ratios of every mode in one panel.
    ax = axes[n_modes]
    for k, rm in enumerate(ref.modes):
        c = COLOURS[k % len(COLOURS)]
        reference_band(ax, 100 * rm.zeta, 100 * rm.zeta_ci95, c)
        t, v, h = series(k, lambda m: 100 * m.zeta, lambda m: 100 * m.zeta_ci95)
        ax.errorbar(t, v, yerr=h, fmt=".", color=c, ms=3, lw=0.6, capsize=0,
                    label=f"mode {k + 1} (95 % intervals; dashed: reference)")
    ax.set_ylabel("damping ratio ζ (%)")
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper left", fontsize=8, ncol=2)

    # The window test: its running T² against the threshold, each full window's verdict.
    ax = axes[n_modes + 1]
    t = np.array([b.t_s for b in blocks])
    ax.plot(t, [b.statistic for b in blocks], ".", color="0.55", ms=3,
            label="block T² (shown, not an alarm)")
    ax.plot(t, [b.accumulated["statistic"] for b in blocks], "-", color="tab:red", lw=1.2,
            label=f"window T² ({a.window_blocks} blocks)")
    ax.plot(t, [b.accumulated["threshold"] for b in blocks], "--", color="tab:red", lw=1,
            label="window threshold")
    full = [b for b in blocks if b.accumulated["blocks"] == b.accumulated["window_blocks"]]
    ok = [b for b in full if not b.alarm]
    if ok:
        ax.plot([b.t_s for b in ok], [b.accumulated["statistic"] for b in ok], "o", mfc="none",
                color="tab:green", label="full window: no change")
    alarmed = [b for b in full if b.alarm]
    if alarmed:
        ax.plot([b.t_s for b in alarmed], [b.accumulated["statistic"] for b in alarmed], "X",
                color="tab:red", ms=9, label="full window: ALARM")
    ax.set_ylim(bottom=0)
    ax.set_ylabel("Hotelling T²")
    ax.set_xlabel("time (s)")
    ax.legend(loc="upper left", fontsize=8, ncol=1)

    for ax in axes:
        ax.axvspan(0, t_ref, color="0.9", lw=0, zorder=0)
        if a.mark_s is not None:
            ax.axvline(a.mark_s, color="k", lw=1, ls=":")
        ax.grid(True, lw=0.3)
    axes[0].text(t_ref / 2, 1.0, f"reference ({ref.seconds:.0f} s)", ha="center", va="bottom",
                 transform=axes[0].get_xaxis_transform(), fontsize=9)
    if a.mark_s is not None:
        axes[0].text(a.mark_s, 1.0, f" {a.mark_label}", ha="left", va="bottom",
                     transform=axes[0].get_xaxis_transform(), fontsize=9)
    if first is not None:
        axes[-1].annotate(f"alarm at {first:.0f} s", (first, next(
            b.accumulated["statistic"] for b in blocks if b.t_s == first)),
            textcoords="offset points", xytext=(-115, -4), fontsize=9, color="tab:red")
    axes[-1].set_xlim(0, t_end + a.block_s)
    fig.suptitle("vibid watch: modes and the window test over time", fontsize=11)
    fig.savefig(a.output, dpi=110)


if __name__ == "__main__":
    main()
