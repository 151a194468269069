#include "vibid/ident/intervals.hpp"

#include <algorithm>
#include <cstdio>

#include "vibid/common/error.hpp"

namespace vibid::ident {

namespace {

// Two-sided 95 % point of Student's t, 1 to 30 degrees of freedom (standard tables, e.g. NIST/
// SEMATECH e-Handbook 1.3.6.7.2; ν = 1: tan(0.475 π), ν = 2: 0.95 / sqrt(2 · 0.975 · 0.025)).
constexpr double kT95[30] = {12.706204736, 4.302652730, 3.182446305, 2.776445105, 2.570581836,
                             2.446911851,  2.364624252, 2.306004135, 2.262157163, 2.228138852,
                             2.200985160,  2.178812830, 2.160368656, 2.144786688, 2.131449546,
                             2.119905299,  2.109815578, 2.100922040, 2.093024054, 2.085963447,
                             2.079613845,  2.073873068, 2.068657610, 2.063898562, 2.059538553,
                             2.055529439,  2.051830516, 2.048407142, 2.045229642, 2.042272456};

// 95 % points of chi-square, 1 to 30 degrees of freedom (NIST/SEMATECH e-Handbook 1.3.6.7.4).
constexpr double kChi95[30] = {3.841459,  5.991465,  7.814728,  9.487729,  11.070498, 12.591587,
                               14.067140, 15.507313, 16.918978, 18.307038, 19.675138, 21.026070,
                               22.362032, 23.684791, 24.995790, 26.296228, 27.587112, 28.869299,
                               30.143527, 31.410433, 32.670573, 33.924438, 35.172462, 36.415029,
                               37.652484, 38.885139, 40.113272, 41.337138, 42.556968, 43.772972};

constexpr double kZ975 = 1.959963984540054;
constexpr double kZ95One = 1.6448536269514722;

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

Uncertainty Uncertainty::Missing(std::string why) {
  Uncertainty u;
  u.missing = std::move(why);
  return u;
}

Uncertainty Uncertainty::ExactValue(std::string basis) {
  Uncertainty u;
  u.variance = 0.0;
  u.basis = std::move(basis);
  return u;
}

double StudentT95(double dof) {
  Require(dof >= 1.0, "t quantile: at least one degree of freedom");
  if (!std::isfinite(dof)) return kZ975;
  const double v = std::floor(dof);
  if (v <= 30.0) return kT95[static_cast<int>(v) - 1];
  // Cornish-Fisher expansion in 1/v (Abramowitz & Stegun 26.7.5): below 3e-8 from 31 on.
  const double z = kZ975, z2 = z * z;
  return z + z * (z2 + 1.0) / (4.0 * v) + z * ((5.0 * z2 + 16.0) * z2 + 3.0) / (96.0 * v * v) +
         z * (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) / (384.0 * v * v * v) +
         z * ((((79.0 * z2 + 776.0) * z2 + 1482.0) * z2 - 1920.0) * z2 - 945.0) /
             (92160.0 * v * v * v * v);
}

double ChiSquare95(int dof) {
  Require(dof >= 1, "chi-square quantile: at least one degree of freedom");
  if (dof <= 30) return kChi95[dof - 1];
  // Wilson-Hilferty (A&S 26.4.17): 0.01 % high at 31, less beyond.
  const double v = dof, a = 2.0 / (9.0 * v);
  const double c = 1.0 - a + kZ95One * std::sqrt(a);
  return v * c * c * c;
}

Interval95 IntervalOf(double value, const Uncertainty& u) {
  Interval95 out;
  if (!u.Known() || !std::isfinite(value)) {
    out.missing = !u.missing.empty()      ? u.missing
                  : !std::isfinite(value) ? "no value"
                                          : "zero variance: " + u.basis;
    return out;
  }
  const double hw = StudentT95(u.dof) * std::sqrt(u.variance);
  out.lo = value - hw;
  out.hi = value + hw;
  out.basis = u.basis;
  if (!(out.hi > out.lo)) {
    // Below the value's resolution: no interval is better than one of zero width.
    out = {};
    out.missing = "the spread is below the value's resolution: " + u.basis;
  }
  return out;
}

std::string FormatInterval(const Interval95& ci, double value) {
  char buf[64];
  if (!ci.Known())
    return "n/a (" + (ci.missing.empty() ? std::string("not estimated") : ci.missing) + ")";
  std::snprintf(buf, sizeof buf, "+- %.3g (%.2g %%)", ci.HalfWidth(),
                100.0 * ci.HalfWidth() / std::abs(value));
  return buf;
}

Uncertainty Propagate(const std::vector<double>& gradient, const std::vector<Uncertainty>& parts,
                      std::string basis) {
  Require(gradient.size() == parts.size(), "propagation: one gradient entry per part");
  double var = 0.0, denom = 0.0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (gradient[i] == 0.0 || parts[i].Exact()) continue;
    if (!parts[i].Known())
      return Uncertainty::Missing(parts[i].missing.empty() ? "no variance" : parts[i].missing);
    const double term = gradient[i] * gradient[i] * parts[i].variance;
    var += term;
    if (std::isfinite(parts[i].dof)) denom += term * term / parts[i].dof;
  }
  Uncertainty u;
  u.variance = var;
  u.dof = denom > 0.0 ? var * var / denom : std::numeric_limits<double>::infinity();
  u.basis = std::move(basis);
  if (!(var > 0.0)) u.missing = "no input varies it";
  return u;
}

MeanOfTests MeanOfRepeats(const std::vector<double>& values, const std::vector<Uncertainty>& each,
                          std::string_view what) {
  Require(!values.empty() && values.size() == each.size(), "mean of repeats: one value per test");
  MeanOfTests out;
  const auto t = static_cast<double>(values.size());
  for (double v : values) out.mean += v;
  out.mean /= t;
  if (values.size() == 1) {
    out.uncertainty = each.front();
    if (!out.uncertainty.Known()) {
      out.uncertainty.missing =
          "one test only (no scatter), and " +
          (out.uncertainty.missing.empty() ? std::string("no variance") : out.uncertainty.missing);
    }
    return out;
  }
  double ss = 0.0;
  for (double v : values) ss += (v - out.mean) * (v - out.mean);
  const double scatter_var = ss / (t - 1.0) / t;
  const std::string count = std::to_string(values.size()) + " " + std::string(what);
  Uncertainty scatter;
  scatter.variance = scatter_var;
  scatter.dof = t - 1.0;
  scatter.basis = "scatter of " + count + " (t, " + std::to_string(values.size() - 1) + " dof)";
  if (!(scatter_var > 0.0)) scatter.missing = "the " + count + " give the same value";
  const bool all_known =
      std::all_of(each.begin(), each.end(), [](const Uncertainty& u) { return u.Known(); });
  if (!all_known) {
    out.uncertainty = scatter;
    if (!scatter.missing.empty()) {
      const auto bad =
          std::find_if(each.begin(), each.end(), [](const Uncertainty& u) { return !u.Known(); });
      out.uncertainty.missing +=
          " and " + (bad->missing.empty() ? std::string("no variance") : bad->missing);
    }
    return out;
  }
  double model_var = 0.0, denom = 0.0, chi2 = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double term = each[i].variance / (t * t);
    model_var += term;
    if (std::isfinite(each[i].dof)) denom += term * term / each[i].dof;
    chi2 += (values[i] - out.mean) * (values[i] - out.mean) / each[i].variance;
  }
  const double limit = ChiSquare95(static_cast<int>(values.size()) - 1);
  if (chi2 > limit && scatter.missing.empty()) {
    out.uncertainty = scatter;
    out.uncertainty.basis += ": the tests disagree beyond their own intervals (chi2 " +
                             Number(chi2) + " > " + Number(limit) + ")";
    return out;
  }
  out.uncertainty.variance = model_var;
  out.uncertainty.dof =
      denom > 0.0 ? model_var * model_var / denom : std::numeric_limits<double>::infinity();
  out.uncertainty.basis = each.front().basis + ", mean of " + count + " (consistent: chi2 " +
                          Number(chi2) + " <= " + Number(limit) + ")";
  return out;
}

}  // namespace vibid::ident
