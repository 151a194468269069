#!/usr/bin/python3
"""Designs the anti-aliasing decimator's FIR stages, verifies the specification on the quantized
coefficients for every supported factor, and writes the C++ tables and the golden test vectors.

Specification (output rate fs_out = fs_in / D, D = 2^a 5^b <= 1000):
  passband  0 .. 0.4 fs_out flat within +-0.1 dB (whole chain, quantized coefficients);
  aliasing  every input component that folds into [0, 0.4 fs_out) at the output is attenuated by
            >= 80 dB (whole chain, quantized coefficients, every intermediate fold included).

Design: a cascade of decimate-by-2 and decimate-by-5 stages, each a linear-phase FIR of odd length
(frequencies below in units of the stage's own input rate; M is the decimation still to come after
a stage):
  sharp2      the final /2 stage: passband 0 .. 0.2, stopband 0.3 .. 0.5. The bands are symmetric
              about 0.25, so it is a half-band filter: every second tap is zero and the centre is
              exactly 1/2, about half the multiplies of a general design of the same selectivity.
  sharp5      the final /5 stage: passband 0 .. 0.08, stopband 0.12 .. 0.5 (from 0.6 of its output
              rate), equiripple.
  coarse2_mK  a /2 stage with M >= K: only 0.5 - p .. 0.5 folds onto the protected band
              0 .. p = 0.4 / (2 K), so again a half-band filter, short (15 taps for K = 2, 7 for 8).
  coarse5_mK  a /5 stage with M >= K: passband 0 .. p = 0.4 / (5 K), stopbands 0.2 k +- p only
              (k = 1, 2); the rest folds where the later stages remove it (don't-care bands).
The coarse designs are graded by the M they serve (COARSE_MIN_M) because the first stage runs at
the input rate: at D = 50 the first /5 stage needs 17 taps instead of the 31 the M = 2 case needs.
Why remez: it meets an equiripple stopband bound with the fewest taps (for sharp5 a Kaiser-window
firwin needs 117 taps against 95, the best beta in 7..9 and cutoff near 0.1), and a half-band remez design (the Vaidyanathan/Nguyen
trick: a one-band type II filter of half length, zeros interleaved) keeps the zero taps exactly
zero; firls minimises the stopband energy, not its worst lobe, which is what aliasing needs bounded.
Quantization: Q30 integers (int32), the double design scaled to unit DC gain first and the
rounding residual put on the largest pairs so every stage's integer taps sum to exactly 2^30: a
constant input then passes every stage exactly (the kernel's DC gain is exactly one).
The stage order of each factor is the one with the fewest multiplies per input sample over all
orders of its stages (final stage sharp2 or sharp5), ties broken by the worst single output tick
and then by the state size.

Writes:
  shared/fixed/decimator_coefficients.inc   the integer taps, stage designs and per-factor plans
  shared/fixed/testdata/decimator_vectors.inc golden vectors: expected integers from an exact
      integer model of the kernel (bit-exact target for the host and the Cortex-M4) and the
      double-precision reference (scipy.signal.upfirdn with the same quantized taps, no rounding)
Prints the stage table and the per-factor verification table.
Run: /usr/bin/python3 scripts/golden/decimator_design.py
"""
import itertools
import os
import warnings

import numpy as np
import scipy
from scipy import signal

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
COEF_OUT = os.path.join(ROOT, "shared", "fixed", "decimator_coefficients.inc")
VEC_OUT = os.path.join(ROOT, "shared", "fixed", "testdata", "decimator_vectors.inc")

Q = 30                    # coefficient format: Q30 in int32
PASS = 0.4                # passband edge, fraction of fs_out
ATTEN_DB = 80.0           # required alias attenuation
RIPPLE_DB = 0.1           # allowed passband deviation of the whole chain (+-)
MARGIN_DB = 0.5           # design margin on each stage's stopband
MAX_FACTOR = 1000
INT32_MIN, INT32_MAX = -(1 << 31), (1 << 31) - 1


# --------------------------------------------------------------------------- design

def quantize(h):
    """Q30 integers with an exact DC sum of 2^30; symmetry kept."""
    h = np.asarray(h, dtype=float)
    h = (h + h[::-1]) / (2.0 * h.sum())  # exactly symmetric, unit DC gain
    q = np.round(h * (1 << Q)).astype(np.int64)
    n = len(q)
    c = n // 2
    res = (1 << Q) - int(q.sum())
    if res % 2:
        q[c] += 1 if res > 0 else -1
        res = (1 << Q) - int(q.sum())
    order = np.argsort(-np.abs(q[:c]), kind="stable")
    i = 0
    while res != 0:
        step = 1 if res > 0 else -1
        k = order[i % c]
        if q[k] != 0:  # never turn a structural zero (half-band) into a tap
            q[k] += step
            q[n - 1 - k] += step
            res -= 2 * step
        i += 1
    assert int(q.sum()) == 1 << Q and np.array_equal(q, q[::-1])
    return q


def response(taps, f):
    """Frequency response of an FIR at f (fraction of its own sample rate); exact DTFT."""
    n = np.arange(len(taps))
    f = np.atleast_1d(np.asarray(f, dtype=float))
    out = np.empty(len(f), dtype=complex)
    for i in range(0, len(f), 20000):  # chunks keep the matrix small
        out[i:i + 20000] = np.exp(-2j * np.pi * np.outer(f[i:i + 20000], n)) @ taps
    return out


def stage_figures(q, pb, stopbands):
    h = q / float(1 << Q)
    a = np.abs(response(h, np.linspace(0.0, pb, 2001)))
    ripple = float(np.max(np.abs(20 * np.log10(a))))
    worst = 0.0
    for lo, hi in stopbands:
        worst = max(worst, float(np.max(np.abs(response(h, np.linspace(lo, min(hi, 0.5), 8001))))))
    return ripple, -20 * np.log10(worst)


def halfband(pb, length):
    k = (length + 1) // 4
    g = signal.remez(2 * k, [0.0, 2 * pb], [1.0], fs=1.0, maxiter=1000, grid_density=64)
    h = np.zeros(4 * k - 1)
    h[0::2] = g / (2 * g.sum())  # side taps sum to 1/2 exactly: unit DC gain with the 1/2 centre
    h[2 * k - 1] = 0.5
    return h


def shortest(name, factor, pb, stopbands, ripple_budget_db, halfband_form):
    """The shortest design whose quantized taps meet the stage's bands with margin."""
    for length in range(7, 301, 4 if halfband_form else 2):
        if halfband_form:
            candidates = [halfband(pb, length)]
        else:
            bands, desired = [0.0, pb], [1.0]
            for lo, hi in stopbands:
                bands += [lo, min(hi, 0.5)]
                desired.append(0.0)
            candidates = []
            for w in (1, 3, 10, 30, 64, 100, 200):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    candidates.append(signal.remez(length, bands, desired, weight=[1] + [w] * len(stopbands),
                                                   fs=1.0, maxiter=1000, grid_density=64))
        for h in candidates:
            q = quantize(h)
            ripple, atten = stage_figures(q, pb, stopbands)
            if atten >= ATTEN_DB + MARGIN_DB and ripple <= ripple_budget_db:
                return {"name": name, "factor": factor, "taps": q, "pb": pb, "stopbands": stopbands,
                        "ripple_db": ripple, "atten_db": atten, "halfband": halfband_form}
    raise SystemExit("no design for " + name)


# A coarse stage followed by M more decimation only has to protect 0 .. 0.4 / (r M) of its input
# rate, so the larger M, the shorter the filter. Each coarse design is made for a minimum M (the
# worst case it serves) and the plan uses the shortest one whose minimum the position meets.
COARSE_MIN_M = {2: (2, 4, 8), 5: (2, 4, 10, 25)}


def coarse(factor, m):
    p = PASS / (factor * m)
    if factor == 2:
        # Only 0.5 - p .. 0.5 folds onto the protected band: a half-band filter.
        return shortest("coarse2_m%d" % m, 2, p, [(0.5 - p, 0.5)], 0.01, True)
    return shortest("coarse5_m%d" % m, 5, p, [(0.2 - p, 0.2 + p), (0.4 - p, 0.4 + p)], 0.01, False)


def designs():
    out = [
        shortest("sharp2", 2, 0.2, [(0.3, 0.5)], 0.01, True),
        shortest("sharp5", 5, 0.08, [(0.12, 0.5)], 0.05, False),
    ]
    for d in out:
        d["min_m"] = 1
    for factor, levels in COARSE_MIN_M.items():
        for m in levels:
            out.append(coarse(factor, m))
            out[-1]["min_m"] = m
    for d in out:
        q = d["taps"]
        c = len(q) // 2
        stride = 2 if d["halfband"] else 1
        dists = list(range(1, c + 1, stride))
        if d["halfband"]:
            assert all(q[c - e] == 0 for e in range(2, c + 1, 2)) and q[c] == 1 << (Q - 1)
        d["stride"] = stride
        d["pairs"] = [int(q[c - e]) for e in dists]
        d["center"] = int(q[c])
        d["mults"] = 1 + 2 * len(dists)  # multiply-accumulates per output (two per stored pair)
        # The kernel's accumulator: |sum| <= sum|h| * 2^31 + 2^29 must stay below 2^63.
        assert int(np.abs(q).sum()) <= (1 << 32) - 1
    return out


# --------------------------------------------------------------------------- plans

def supported():
    return [d for d in range(1, MAX_FACTOR + 1) if d == 2 ** _v(d, 2) * 5 ** _v(d, 5)]


def _v(d, p):
    n = 0
    while d % p == 0:
        d //= p
        n += 1
    return n


def plan_cost(plan, des):
    rate, per_input, worst = 1, 0.0, 0
    for s in plan:
        rate *= des[s]["factor"]
        per_input += des[s]["mults"] / rate
        worst += des[s]["mults"]
    return per_input, worst


def best_plan(d, des):
    """The cheapest cascade for factor d: every order of its coarse stages (final stage sharp2 or
    sharp5), each position given the shortest coarse design valid for the decimation after it."""
    idx = {x["name"]: i for i, x in enumerate(des)}
    a, b = _v(d, 2), _v(d, 5)
    if d == 1:
        return []
    options = []
    for final, fa, fb in (("sharp2", 1, 0), ("sharp5", 0, 1)):
        if a < fa or b < fb:
            continue
        for order in set(itertools.permutations([2] * (a - fa) + [5] * (b - fb))):
            plan = []
            for i, r in enumerate(order):
                after = int(np.prod(order[i + 1:], dtype=np.int64)) * des[idx[final]]["factor"]
                valid = [j for j, x in enumerate(des) if x["factor"] == r and 1 < x["min_m"] <= after]
                plan.append(min(valid, key=lambda j: (des[j]["mults"], len(des[j]["taps"]))))
            plan.append(idx[final])
            cost = plan_cost(plan, des)
            options.append((cost[0], cost[1], state_words(plan, des), plan))
    options.sort()
    return options[0][3]


def delay_ticks(plan, des):
    rate, delay = 1, 0
    for s in plan:
        delay += (len(des[s]["taps"]) - 1) // 2 * rate
        rate *= des[s]["factor"]
    return delay


def state_words(plan, des):
    return sum(2 * len(des[s]["taps"]) for s in plan)  # the kernel's double-written windows


def worst_case_gain(plan, des):
    """Largest l1 norm of the impulse response from the input to any stage output: no stage
    output can exceed this multiple of the largest input magnitude."""
    h, rate, worst = np.array([1.0]), 1, 1.0
    for s in plan:
        taps = des[s]["taps"] / float(1 << Q)
        up = np.zeros((len(taps) - 1) * rate + 1)
        up[::rate] = taps
        h = np.convolve(h, up)
        rate *= des[s]["factor"]
        worst = max(worst, float(np.abs(h).sum()))
    return worst


def verify(d, plan, des):
    """Chain passband deviation and worst alias gain, in dB, for factor d (frequencies in fs_out)."""
    if not plan:
        return 0.0, float("inf")
    stage_rates = []  # input rate of each stage in units of fs_out
    rate = d
    for s in plan:
        stage_rates.append(rate)
        rate //= des[s]["factor"]

    def chain(f):
        g = np.ones(len(f))
        for s, r in zip(plan, stage_rates):
            g *= np.abs(response(des[s]["taps"] / float(1 << Q), f / r))
        return g

    ripple = float(np.max(np.abs(20 * np.log10(chain(np.linspace(0.0, PASS, 801))))))
    g = np.linspace(0.0, PASS, 401)  # output frequencies the spec protects (0.4 included: margin)
    f = np.concatenate([k + s * g for k in range(1, d // 2 + 1) for s in (-1, 1)])
    f = f[(f >= 1.0 - PASS) & (f <= d / 2.0)]
    worst = float(np.max(chain(f)))
    return ripple, -20 * np.log10(worst)


# --------------------------------------------------------------------------- test signals
# Mirrored exactly by decimator_test.cpp (integer arithmetic only, so both sides agree bit for bit).

def xorshift32(state):
    state ^= (state << 13) & 0xFFFFFFFF
    state ^= state >> 17
    state ^= (state << 5) & 0xFFFFFFFF
    return state


class Oscillator:
    """Integer 'magic circle' oscillator: c -= (k s) >> 30; s += (k c) >> 30, k = 2 sin(pi f)."""

    def __init__(self, k_q30):
        self.k, self.c, self.s = k_q30, 1 << 30, 0

    def step(self):
        self.c -= (self.k * self.s) >> 30
        self.s += (self.k * self.c) >> 30
        return self.c


OSC_K = (7421156, 1093158116)  # 2 sin(pi f) in Q30 for f = 0.0011 and 0.17 (fractions of fs_in)
CHANNELS = 4                 # ADC-like, encoder-like, near-full-scale Q31 tones + noise, full-scale square


def clamp32(v):
    return max(INT32_MIN, min(INT32_MAX, v))


def test_input(frames):
    lo, hi = Oscillator(OSC_K[0]), Oscillator(OSC_K[1])
    rng = 0x2545F491
    x = np.zeros((frames, CHANNELS), dtype=np.int64)
    clamps = 0
    for n in range(frames):
        a, b = lo.step(), hi.step()
        rng = xorshift32(rng)
        r = rng
        code = 2048 + ((a * 1500) >> 30) + ((b * 300) >> 30) + (r >> 24) - 128
        x[n, 0] = max(0, min(4095, code)) * 16
        x[n, 1] = ((a * (1 << 23)) >> 30) + ((b * (1 << 16)) >> 30) + ((r >> 12) & 0xFFF) - 2048
        v = ((a * 1352914698) >> 30) + ((b * 429496729) >> 30) + ((r & 0x1FFFFFFF) - (1 << 28))
        clamps += v != clamp32(v)
        x[n, 2] = clamp32(v)
        x[n, 3] = INT32_MAX if (n // 700) % 2 == 0 else INT32_MIN
    assert clamps == 0
    # Channel 2 is full-scale Q31 within 2 %: the oscillators peak at 1.0 and 1.16 x 2^30 (the fast
    # one's orbit is an ellipse), so 0.63 + 0.2 x 1.16 + 0.125 of 2^31.
    assert np.max(np.abs(x[:, 2])) > 0.95 * 2 ** 31 or frames < 20000
    return x


def integer_model(x, plan, des):
    """The kernel's arithmetic in exact integers: per stage, the full convolution kept at every
    factor-th index, rounded half up ((acc + 2^29) >> 30) and saturated to int32."""
    sats = np.zeros(x.shape[1], dtype=np.int64)
    y = x.astype(np.int64)
    for s in plan:
        q = des[s]["taps"].astype(np.int64)
        r = des[s]["factor"]
        out = np.empty((len(range(0, y.shape[0], r)), y.shape[1]), dtype=np.int64)
        for ch in range(y.shape[1]):
            acc = _exact_convolve(y[:, ch], q)[0::r]
            v = (acc + (1 << (Q - 1))) >> Q
            sats[ch] += int(np.sum((v > INT32_MAX) | (v < INT32_MIN)))
            out[:, ch] = np.clip(v, INT32_MIN, INT32_MAX)
        y = out
    return y, sats


def _exact_convolve(x, q):
    # |x| < 2^31, |q| < 2^31 and sum|q| < 2^32: every partial sum fits int64, so numpy's integer
    # convolution is exact (no FFT for integer arrays).
    return np.convolve(x, q)[:len(x)]


def double_reference(x, plan, des):
    """scipy.signal.upfirdn of the same quantized taps in double precision, no rounding."""
    y = x.astype(float)
    for s in plan:
        h = des[s]["taps"] / float(1 << Q)
        r = des[s]["factor"]
        n_out = len(range(0, y.shape[0], r))
        y = np.stack([signal.upfirdn(h, y[:, ch], up=1, down=r)[:n_out] for ch in range(y.shape[1])], axis=1)
    return y


# --------------------------------------------------------------------------- output

def write_coefficients(des, plans):
    names = {d["name"]: "k" + "".join(w.capitalize() for w in d["name"].split("_")) for d in des}
    lines = [
        "// Generated by scripts/golden/decimator_design.py (scipy %s). Do not edit." % scipy.__version__,
        "// Included by decimator.cpp inside namespace vibid::fixed. Taps are Q30 (2^30 = 1.0); each",
        "// design stores its centre tap and one tap per symmetric pair, innermost pair first, the pair",
        "// at distance 1 + i * stride from the centre (stride 2: half-band, the even distances are",
        "// exactly zero). Every design's full tap sum is exactly 2^30 (unit DC gain).",
        "",
    ]
    for d in des:
        lines.append("// %s: /%d, %d taps, ripple %.4f dB over 0..%.2f fs_in, stopband %s fs_in >= %.1f dB."
                     % (d["name"], d["factor"], len(d["taps"]), d["ripple_db"], d["pb"],
                        ", ".join("%.2f..%.2f" % (lo, min(hi, 0.5)) for lo, hi in d["stopbands"]), d["atten_db"]))
        lines.append("inline constexpr std::int32_t %sPairs[%d] = {" % (names[d["name"]], len(d["pairs"])))
        for i in range(0, len(d["pairs"]), 8):
            lines.append("    " + " ".join("%d," % v for v in d["pairs"][i:i + 8]))
        lines.append("};")
    lines.append("")
    lines.append("inline constexpr DecimatorStageDesign kStageDesigns[%d] = {" % len(des))
    for d in des:
        lines.append("    {.factor = %d, .length = %d, .stride = %d, .pair_count = %d, .center = %d, .pairs = %sPairs},  // %s"
                     % (d["factor"], len(d["taps"]), d["stride"], len(d["pairs"]), d["center"], names[d["name"]], d["name"]))
    lines.append("};")
    lines.append("")
    max_stages = max(len(p) for p in plans.values())
    lines.append("// Stage order per factor: fewest multiplies per input sample (final stage sharp).")
    lines.append("inline constexpr std::size_t kPlanMaxStages = %d;" % max_stages)
    lines.append("inline constexpr std::size_t kPlanMaxStateWords = %d;  // per channel, 2 x taps per stage"
                 % max(state_words(p, des) for p in plans.values()))
    lines.append("inline constexpr DecimatorPlan kPlans[%d] = {" % len(plans))
    for d, p in plans.items():
        lines.append("    {.factor = %d, .stage_count = %d, .stages = {%s}},  // %s"
                     % (d, len(p), ", ".join(str(s) for s in p), " ".join(des[s]["name"] for s in p) or "copy"))
    lines.append("};")
    with open(COEF_OUT, "w") as f:
        f.write("\n".join(lines) + "\n")


def c_double(v):
    return repr(float(v))


def write_vectors(des, plans, vec):
    lines = [
        "// Generated by scripts/golden/decimator_design.py (scipy %s, numpy %s). Do not edit."
        % (scipy.__version__, np.__version__),
        "// Input: GoldenInput in decimator_test.cpp (integer oscillators + xorshift32, mirrored exactly",
        "// by test_input() in the script), 4 channels: ADC-like 12.4, encoder-like counts, Q31 tones +",
        "// noise peaking at 98 % of full scale, full-scale square wave (period 1400 frames). Per factor:",
        "//   expected  the integer model of the kernel (exact integers, round half up, saturate) -",
        "//             the bit-exact target on the host and on the Cortex-M4;",
        "//   reference scipy.signal.upfirdn(h, x, 1, r) per stage with the same quantized taps in",
        "//             double precision (no rounding, no saturation), channels 0..2 only;",
        "//   delay     the chain's group delay in input samples; saturations: the model's count;",
        "//   edge_db   the quantized chain's gain at 0.4 fs_out (numpy DTFT of the taps).",
        "",
        "struct DecimatorVector {",
        "  std::uint32_t factor;",
        "  std::size_t frames;          // input frames",
        "  std::size_t outputs;         // output frames = ceil(frames / factor)",
        "  std::uint32_t delay;",
        "  std::uint32_t saturations;",
        "  double edge_db;",
        "  const std::int32_t* expected;  // outputs x 4, interleaved",
        "  const double* reference;       // outputs x 3, interleaved",
        "};",
        "",
    ]
    entries = []
    for d, (frames, expected, reference, sats) in vec.items():
        lines.append("constexpr std::int32_t kExpected%d[%d] = {" % (d, expected.size))
        flat = expected.reshape(-1)
        for i in range(0, len(flat), 8):
            lines.append("    " + " ".join("%d," % v for v in flat[i:i + 8]))
        lines.append("};")
        lines.append("constexpr double kReference%d[%d] = {" % (d, reference.size))
        flat = reference.reshape(-1)
        for i in range(0, len(flat), 4):
            lines.append("    " + " ".join("%s," % c_double(v) for v in flat[i:i + 4]))
        lines.append("};")
        plan = plans[d]
        edge = 20 * np.log10(_chain_gain(d, plan, des, PASS))
        entries.append("    {%d, %d, %d, %d, %d, %s, kExpected%d, kReference%d},"
                       % (d, frames, expected.shape[0], delay_ticks(plan, des), sats, c_double(edge), d, d))
    lines.append("constexpr DecimatorVector kVectors[%d] = {" % len(entries))
    lines += entries
    lines.append("};")
    lines.append("")
    lines.append("// Per supported factor: DecimatorDelayTicks (the script's own sum over the plan) and the")
    lines.append("// quantized chain's gain at 0.4 fs_out in dB (numpy DTFT of the taps).")
    lines.append("struct FactorFacts {")
    lines.append("  std::uint32_t factor;")
    lines.append("  std::uint32_t delay;")
    lines.append("  double edge_db;")
    lines.append("};")
    lines.append("constexpr FactorFacts kFactorFacts[%d] = {" % len(plans))
    for d, p in plans.items():
        lines.append("    {%d, %d, %s}," % (d, delay_ticks(p, des), c_double(20 * np.log10(_chain_gain(d, p, des, PASS)))))
    lines.append("};")
    os.makedirs(os.path.dirname(VEC_OUT), exist_ok=True)
    with open(VEC_OUT, "w") as f:
        f.write("\n".join(lines) + "\n")


def _chain_gain(d, plan, des, f_out):
    g, rate = 1.0, d
    for s in plan:
        g *= abs(response(des[s]["taps"] / float(1 << Q), [f_out / rate])[0])
        rate //= des[s]["factor"]
    return g


VECTOR_FACTORS = (2, 5, 10, 200)
VECTOR_OUTPUTS = 400


def main():
    des = designs()
    print("stage designs (Q30, quantized taps; frequencies in units of the stage input rate)")
    print("  %-12s %6s %5s %6s %12s %10s  %s" % ("stage", "factor", "taps", "mults", "ripple dB", "atten dB", "bands"))
    for d in des:
        print("  %-12s %6d %5d %6d %12.5f %10.2f  pass 0..%.4g, stop %s" % (
            d["name"], d["factor"], len(d["taps"]), d["mults"], d["ripple_db"], d["atten_db"], d["pb"],
            ", ".join("%.4g..%.4g" % (lo, min(hi, 0.5)) for lo, hi in d["stopbands"])))
    for d in des:
        step = np.cumsum(d["taps"]) / float(1 << Q)
        print("  %-12s step response peak %.4f (the most a full-scale input can overshoot)" % (d["name"], step.max()))
    plans = {d: best_plan(d, des) for d in supported()}
    print()
    print("per factor (whole chain, quantized): delay in input samples, passband 0..0.4 fs_out deviation, worst")
    print("alias into [0, 0.4 fs_out), multiplies per input sample and at the worst tick, state words per channel")
    print("  %5s %6s %10s %8s %8s %6s %6s  %s" % ("D", "delay", "ripple dB", "alias dB", "mult/in", "worst",
                                                 "state", "stages (taps)"))
    ok = True
    for d, p in plans.items():
        ripple, alias = verify(d, p, des)
        per_in, worst = plan_cost(p, des)
        good = ripple <= RIPPLE_DB and alias >= ATTEN_DB
        ok &= good
        print("  %5d %6d %10.4f %8.1f %8.2f %6d %6d  %s%s" % (
            d, delay_ticks(p, des), ripple, alias, per_in, worst, state_words(p, des),
            " ".join("%s(%d)" % (des[s]["name"], len(des[s]["taps"])) for s in p) or "copy",
            "" if good else "  FAILS"))
    if not ok:
        raise SystemExit("specification not met")
    gain, at = max((worst_case_gain(p, des), d) for d, p in plans.items())
    print("worst-case gain from the input to any stage output: %.4f (D = %d); inputs below 2^31 / %.4f"
          " = %.0f never clip" % (gain, at, gain, 2.0 ** 31 / gain))
    # The header promises that encoder counts and 12.4 ADC values (|x| < 2^30) never saturate.
    assert gain < 2.0
    write_coefficients(des, plans)

    vec = {}
    for d in VECTOR_FACTORS:
        frames = d * VECTOR_OUTPUTS - d // 2  # not a multiple of D: the last frame is not an output tick
        x = test_input(frames)
        expected, per_channel = integer_model(x, plans[d], des)
        # Only the square wave may clip: the double reference of channels 0..2 has no saturation.
        assert per_channel[:3].sum() == 0, per_channel
        sats = int(per_channel.sum())
        reference = double_reference(x[:, :3], plans[d], des)
        vec[d] = (frames, expected, reference, sats)
        err = expected[:, :3] - reference
        snr = 10 * np.log10(np.sum(reference ** 2, axis=0) / np.sum(err ** 2, axis=0))
        print("vector D=%d: %d frames, %d outputs, saturations %d; per channel (ADC, encoder, Q31):"
              " SNR %s dB, max |int - double| %s LSB" % (
                  d, frames, expected.shape[0], sats, " ".join("%.1f" % v for v in snr),
                  " ".join("%.3f" % v for v in np.max(np.abs(err), axis=0))))
    write_vectors(des, plans, vec)
    print("wrote", os.path.relpath(COEF_OUT, ROOT), "and", os.path.relpath(VEC_OUT, ROOT))


if __name__ == "__main__":
    main()
