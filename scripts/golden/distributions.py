#!/usr/bin/python3
"""Reference quantiles and distribution values for host/lib/numerics/distributions_test.cpp,
from scipy.stats (an independent implementation: Cephes' incomplete gamma and beta).
Run: /usr/bin/python3 scripts/golden/distributions.py"""
import scipy
from scipy import stats

print(f"// scipy {scipy.__version__}")
for p, dof in [(0.975, 1), (0.975, 5), (0.975, 19), (0.975, 100), (0.995, 3), (0.05, 7)]:
    print(f"t    p={p} dof={dof}: {stats.t.ppf(p, dof)!r}")
for p, dof in [(0.95, 1), (0.95, 10), (0.99, 10), (0.999, 64), (0.9999, 200), (0.01, 4)]:
    print(f"chi2 p={p} dof={dof}: {stats.chi2.ppf(p, dof)!r}")
for p, d1, d2 in [(0.95, 3, 10), (0.999, 64, 400), (0.99, 1, 1), (0.5, 7, 30)]:
    print(f"F    p={p} d1={d1} d2={d2}: {stats.f.ppf(p, d1, d2)!r}")
for p in [0.975, 0.5, 1e-6]:
    print(f"norm p={p}: {stats.norm.ppf(p)!r}")
print(f"chi2.cdf(3.0, 2.5): {stats.chi2.cdf(3.0, 2.5)!r}")
# scipy 1.10's t.ppf(0.995, 3) is 1.7e-9 off; mpmath at 40 digits settles it.
import mpmath as mp  # noqa: E402
mp.mp.dps = 40
tail = lambda t: mp.betainc(1.5, 0.5, 0, 3 / (3 + t * t), regularized=True) / 2  # noqa: E731
print(f"t    p=0.995 dof=3 (mpmath): {mp.nstr(mp.findroot(lambda t: tail(t) - mp.mpf('0.005'), 5.84), 20)}")
print(f"t.cdf(-2.0, 4): {stats.t.cdf(-2.0, 4)!r}")
print(f"f.cdf(1.7, 5, 12): {stats.f.cdf(1.7, 5, 12)!r}")
