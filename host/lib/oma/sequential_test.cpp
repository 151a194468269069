// The window-limited GLR on the block residuals and its threshold for the reference in hand
// (see the header).
#include "vibid/oma/sequential_test.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Cholesky>

#include "reference_draws.hpp"
#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"
#include "vibid/numerics/quadratic_form.hpp"

namespace vibid::oma {

namespace {

constexpr int kDraws = 2000;
constexpr std::uint64_t kSeed = 20261208;
constexpr std::uint64_t kFitSeed = 20261209;
// A is fitted where the simulation resolves the rate to about 4 %: 600 crossings.
constexpr double kFitRate = 1e-3;
constexpr int kFitCrossings = 600;
constexpr long kFitMaxBlocks = 2000000;

// Siegmund's approximation of the expected overshoot factor ν (Siegmund, Sequential Analysis,
// 1985, eq. 4.38).
double Nu(double x) {
  if (x < 1e-8) return 1.0;
  const double phi = std::exp(-0.125 * x * x) / std::sqrt(2.0 * std::numbers::pi);
  const double cdf = numerics::NormalCdf(0.5 * x);
  return (2.0 / x) * (cdf - 0.5) / (0.5 * x * cdf + phi);
}

// The level h in units of the quadratic form's dominant scale: Q = Σ wᵢ (zᵢ + δᵢ)² reaches h
// mostly along its heaviest terms, and the scan's clumping there is that of a chi-square field at
// h / w_eff, w_eff the weights' mean over their shares cᵢ of h at the saddlepoint ŝ (K'(ŝ) = h,
// cᵢ = wᵢ/(1 − 2ŝwᵢ) + wᵢδᵢ²/(1 − 2ŝwᵢ)²). Equal weights give h itself.
double EffectiveLevel(const Eigen::VectorXd& w, const Eigen::VectorXd& d, double h) {
  const auto shares = [&](double s, double* k1, double* k2, double* wc) {
    *k1 = *k2 = *wc = 0.0;
    for (Eigen::Index i = 0; i < w.size(); ++i) {
      const double a = 1.0 - 2.0 * s * w(i);
      const double c = w(i) / a + w(i) * d(i) * d(i) / (a * a);
      *k1 += c;
      *wc += w(i) * c;
      *k2 += 2.0 * w(i) * w(i) / (a * a) + 4.0 * w(i) * w(i) * d(i) * d(i) / (a * a * a);
    }
  };
  const double s_max = 0.5 / w.maxCoeff();
  double lo = -s_max;
  double hi = s_max;
  double k1 = 0.0;
  double k2 = 0.0;
  double wc = 0.0;
  while ((shares(lo, &k1, &k2, &wc), k1) > h) lo *= 2.0;
  double s = 0.0;
  for (int it = 0; it < 100; ++it) {
    shares(s, &k1, &k2, &wc);
    (k1 > h ? hi : lo) = s;
    double next = s - (k1 - h) / k2;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - s) <= 1e-12 * s_max) break;
    s = next;
  }
  shares(s, &k1, &k2, &wc);
  return h * k1 / wc;
}

int MinOnset(int max_blocks) { return std::min(kSequentialMinOnsetBlocks, max_blocks); }

// The two-sample weight of onset k against m reference blocks: k (ȳₖ − μ̂) has covariance
// Σ (1 + k/m) while nothing changed.
double Shrink(int k, int m) { return 1.0 + static_cast<double>(k) / m; }

// Σₖ qₖ(h) Pₖ(h) for a reference with covariance eigenvalues `lambda` and mean error `e`: the
// local rate of a chi-square scan over onsets, (b²/2k)² ν(b/√k)² per onset at b² the level.
double ScanSum(const Eigen::VectorXd& lambda, const Eigen::VectorXd& e, int m, int max_blocks,
               double h) {
  double sum = 0.0;
  for (int k = MinOnset(max_blocks); k <= max_blocks; ++k) {
    const Eigen::VectorXd w = lambda.cwiseInverse() / Shrink(k, m);
    const Eigen::VectorXd d = std::sqrt(static_cast<double>(k)) * e;
    const double b2 = EffectiveLevel(w, d, h);
    const double nu = Nu(std::sqrt(b2 / k));
    const double q = 0.25 * b2 * b2 / (static_cast<double>(k) * k) * nu * nu;
    sum += q * numerics::QuadraticFormTail(w, d, h);
  }
  return sum;
}

// The exact reference's GLR simulated from N(0, I) residuals at h: crossings per block, with the
// test started afresh after each.
double SimulatedRate(int p, int m, int max_blocks, double h) {
  detail::Variates v(kFitSeed);
  // cum holds the running sums C_{n−j}, j = 0 … L (a ring), since the last restart.
  std::vector<Eigen::VectorXd> cum(static_cast<std::size_t>(max_blocks) + 1,
                                   Eigen::VectorXd::Zero(p));
  Eigen::VectorXd now = Eigen::VectorXd::Zero(p);
  Eigen::VectorXd y(p);
  long held = 0;
  std::size_t head = 0;
  long crossings = 0;
  long blocks = 0;
  const std::size_t ring = cum.size();
  for (; blocks < kFitMaxBlocks && crossings < kFitCrossings; ++blocks) {
    for (int i = 0; i < p; ++i) y(i) = v.Normal();
    now += y;
    head = (head + 1) % ring;
    cum[head] = now;
    held = std::min<long>(held + 1, max_blocks);
    double g = 0.0;
    for (long k = MinOnset(max_blocks); k <= held; ++k) {
      const Eigen::VectorXd& back = cum[(head + ring - static_cast<std::size_t>(k)) % ring];
      g = std::max(g, (now - back).squaredNorm() /
                          (static_cast<double>(k) * Shrink(static_cast<int>(k), m)));
    }
    if (g > h) {
      ++crossings;
      held = 0;
      now.setZero();
      for (auto& c : cum) c.setZero();
    }
  }
  return static_cast<double>(crossings) / static_cast<double>(blocks);
}

// Solves f(h) = 0 for f decreasing in h (the log of a rate over the one asked), from h0.
double SolveDecreasing(const std::function<double(double)>& f, double h0) {
  double lo = h0;
  double flo = f(lo);
  double hi = h0;
  double fhi = flo;
  if (flo > 0.0) {
    while (fhi > 0.0) {
      lo = hi;
      flo = fhi;
      hi *= 1.25;
      fhi = f(hi);
    }
  } else {
    while (flo <= 0.0) {
      hi = lo;
      fhi = flo;
      lo /= 1.25;
      flo = f(lo);
    }
  }
  // Illinois: f is close to linear in h (a rate falls about as e^{−h/2}).
  int side = 0;
  for (int it = 0; it < 60 && hi - lo > 1e-9 * hi; ++it) {
    const double mid = lo + flo * (hi - lo) / (flo - fhi);
    const double fm = f(mid);
    if (std::abs(fm) < 1e-10) return mid;
    if (fm > 0.0) {
      lo = mid;
      flo = fm;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      hi = mid;
      fhi = fm;
      if (side == 1) flo *= 0.5;
      side = 1;
    }
  }
  return 0.5 * (lo + hi);
}

double CrossingConstant(int p, int m, int max_blocks, double* fit_rate, double* fit_h) {
  static std::mutex mutex;
  static std::map<std::tuple<int, int, int>, std::tuple<double, double, double>> done;
  const auto key = std::make_tuple(p, m, max_blocks);
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = done.find(key); it != done.end()) {
      *fit_rate = std::get<1>(it->second);
      *fit_h = std::get<2>(it->second);
      return std::get<0>(it->second);
    }
  }
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(p);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(p);
  const double h = SolveDecreasing(
      [&](double x) { return std::log(ScanSum(ones, zero, m, max_blocks, x) / kFitRate); },
      numerics::ChiSquareQuantile(1.0 - kFitRate, p));
  const double rate = SimulatedRate(p, m, max_blocks, h);
  const double a = rate / ScanSum(ones, zero, m, max_blocks, h);
  const std::lock_guard<std::mutex> lock(mutex);
  done.emplace(key, std::make_tuple(a, rate, h));
  *fit_rate = rate;
  *fit_h = h;
  return a;
}

SequentialCalibration Calibrate(int p, int m, int max_blocks, double false_alarm) {
  SequentialCalibration out;
  out.crossing_constant = CrossingConstant(p, m, max_blocks, &out.fit_rate, &out.fit_threshold);
  const double a = out.crossing_constant;
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(p);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(p);
  out.exact_threshold = SolveDecreasing(
      [&](double x) { return std::log(a * ScanSum(ones, zero, m, max_blocks, x) / false_alarm); },
      out.fit_threshold);
  detail::Variates v(kSeed);
  std::vector<detail::ReferenceError> draws;
  draws.reserve(kDraws);
  for (int i = 0; i < kDraws; ++i) draws.push_back(detail::DrawReferenceError(v, p, m));
  std::vector<double> rates(draws.size());
  const auto rates_at = [&](double h) {
    for (std::size_t i = 0; i < draws.size(); ++i) {
      rates[i] = a * ScanSum(draws[i].eigenvalues, draws[i].mean_error, m, max_blocks, h);
    }
  };
  rates_at(out.exact_threshold);
  out.exact_low = detail::Quantile(rates, 0.025);
  out.exact_high = detail::Quantile(rates, 0.975);
  // The 97.5 % point of the references' rates falls with h: h where it is the rate asked.
  out.threshold = SolveDecreasing(
      [&](double h) {
        rates_at(h);
        return std::log(detail::Quantile(rates, 0.975) / false_alarm);
      },
      out.exact_threshold);
  rates_at(out.threshold);
  out.low = detail::Quantile(rates, 0.025);
  out.high = detail::Quantile(rates, 0.975);
  double sum = 0.0;
  for (double r : rates) sum += r;
  out.mean = sum / static_cast<double>(rates.size());
  return out;
}

}  // namespace

double SequentialCrossingRate(const Eigen::VectorXd& eigenvalues, const Eigen::VectorXd& mean_error,
                              int m, int max_blocks, double h, double crossing_constant) {
  return crossing_constant * ScanSum(eigenvalues, mean_error, m, max_blocks, h);
}

SequentialCalibration CalibrateSequential(int p, int m, int max_blocks, double false_alarm) {
  Require(p >= 1 && m >= p + 2, "sequential calibration: " + std::to_string(p) +
                                    " residuals need at least " + std::to_string(p + 2) +
                                    " reference observations, not " + std::to_string(m));
  Require(max_blocks >= 1 && max_blocks <= 720,
          "sequential calibration: the onsets looked back over must number 1 … 720 blocks");
  Require(false_alarm > 0.0 && false_alarm <= 0.05,
          "sequential calibration: the false-alarm probability per block must lie in (0, 0.05]");
  static std::mutex mutex;
  static std::map<std::tuple<int, int, int, double>, SequentialCalibration> done;
  const auto key = std::make_tuple(p, m, max_blocks, false_alarm);
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = done.find(key); it != done.end()) return it->second;
  }
  const SequentialCalibration c = Calibrate(p, m, max_blocks, false_alarm);
  const std::lock_guard<std::mutex> lock(mutex);
  done.emplace(key, c);
  return c;
}

SequentialTest::SequentialTest(Eigen::Ref<const Eigen::MatrixXd> reference, int max_blocks,
                               double false_alarm)
    : max_blocks_(max_blocks) {
  const auto p = static_cast<int>(reference.rows());
  const auto m = static_cast<int>(reference.cols());
  Require(p >= 1 && m >= p + 2, "sequential test: " + std::to_string(p) +
                                    " residuals need at least " + std::to_string(p + 2) +
                                    " reference observations, not " + std::to_string(m));
  Require(reference.allFinite(), "sequential test: a reference observation is not finite");
  mean_ = reference.rowwise().mean();
  const Eigen::MatrixXd centred = reference.colwise() - mean_;
  const Eigen::LLT<Eigen::MatrixXd> llt(centred * centred.transpose() / (m - 1.0));
  Require(llt.info() == Eigen::Success && llt.matrixL().toDenseMatrix().diagonal().minCoeff() > 0.0,
          "sequential test: the reference observations' covariance is singular");
  whiten_ = llt.matrixL().solve(Eigen::MatrixXd::Identity(p, p));
  calibration_ = CalibrateSequential(p, m, max_blocks, false_alarm);
  m_ = m;
  recent_ = Eigen::MatrixXd::Zero(p, max_blocks);
  sum_ = Eigen::VectorXd::Zero(p);
}

SequentialTestResult SequentialTest::Add(Eigen::Ref<const Eigen::VectorXd> observation) {
  Require(observation.size() == mean_.size() && observation.allFinite(),
          "sequential test: an observation must hold " + std::to_string(mean_.size()) +
              " finite values");
  newest_ = (newest_ + 1) % max_blocks_;
  recent_.col(newest_).noalias() = whiten_ * (observation - mean_);
  held_ = std::min(held_ + 1, max_blocks_);
  SequentialTestResult r;
  r.threshold = calibration_.threshold;
  r.blocks = held_;
  sum_.setZero();
  for (int k = 1; k <= held_; ++k) {
    sum_ += recent_.col((newest_ - k + 1 + max_blocks_) % max_blocks_);
    if (k < MinOnset(max_blocks_)) continue;
    const double g = sum_.squaredNorm() / (k * Shrink(k, m_));
    if (g > r.statistic) {
      r.statistic = g;
      r.onset_blocks = k;
    }
  }
  r.alarm = r.statistic > r.threshold;
  if (r.alarm) held_ = 0;
  return r;
}

}  // namespace vibid::oma
