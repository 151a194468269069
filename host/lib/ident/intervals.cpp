#include "vibid/ident/intervals.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"

namespace vibid::ident {

namespace {

// The normal distribution's 97.5 % point (the t quantile's limit).
constexpr double kZ975 = 1.959963984540054;

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
  // A fractional dof (Welch-Satterthwaite) takes the whole degrees below it: the wider interval.
  return numerics::StudentTQuantile(0.975, std::floor(dof));
}

double ChiSquare95(int dof) {
  Require(dof >= 1, "chi-square quantile: at least one degree of freedom");
  return numerics::ChiSquareQuantile(0.95, dof);
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
  std::string out = buf;
  if (ci.HasCalibration()) {
    std::snprintf(buf, sizeof buf, " = stat +- %.3g, cal +- %.3g", ci.statistical_half_width,
                  ci.calibration_half_width);
    out += buf;
  }
  return out;
}

void AddCalibration(Interval95& ci, double value, double relative_u, const std::string& what) {
  Require(std::isfinite(relative_u) && relative_u >= 0.0,
          "calibration: a relative uncertainty must be a number >= 0");
  if (!ci.Known() || relative_u == 0.0) return;
  // Normal coverage for the calibration part: a certificate's k refers to many degrees of freedom.
  constexpr double kZ95 = 1.959963984540054;
  const double stat = ci.HalfWidth();
  const double cal = kZ95 * relative_u * std::abs(value);
  const double centre = 0.5 * (ci.lo + ci.hi);
  const double half = std::hypot(stat, cal);
  ci.lo = centre - half;
  ci.hi = centre + half;
  ci.statistical_half_width = stat;
  ci.calibration_half_width = cal;
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3g %%", 100.0 * relative_u);
  ci.basis += "; with the calibration of " + what + " (" + buf + " standard)";
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
