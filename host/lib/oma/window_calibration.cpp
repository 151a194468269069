// The law of a reference's own false-alarm probability, drawn over references (see the header).
#include "vibid/oma/window_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Core>

#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"
#include "vibid/numerics/quadratic_form.hpp"
#include "reference_draws.hpp"

namespace vibid::oma {

namespace {

constexpr int kDraws = 2000;
constexpr std::uint64_t kSeed = 20261207;

// One reference's error, whitened: T² = Σ wᵢ (zᵢ + δᵢ)².
struct Draw {
  Eigen::VectorXd weights;
  Eigen::VectorXd noncentrality;
};

std::vector<Draw> DrawReferences(int p, int m, int window) {
  detail::Variates v(kSeed);
  const double k = window;
  const double c = 1.0 / (1.0 / k + 1.0 / m);
  std::vector<Draw> draws(kDraws);
  for (Draw& d : draws) {
    const detail::ReferenceError r = detail::DrawReferenceError(v, p, m);
    d.weights = c / (k * r.eigenvalues.array());
    d.noncentrality = -std::sqrt(k) * r.mean_error;
  }
  return draws;
}

// h with P(Q > h) = alpha for one draw, by bisection on log h.
double ThresholdOf(const Draw& d, double alpha, double lo, double hi) {
  while (numerics::QuadraticFormTail(d.weights, d.noncentrality, lo) < alpha) lo *= 0.5;
  while (numerics::QuadraticFormTail(d.weights, d.noncentrality, hi) > alpha) hi *= 2.0;
  for (int it = 0; it < 60 && hi / lo > 1.0 + 1e-10; ++it) {
    const double mid = std::sqrt(lo * hi);
    (numerics::QuadraticFormTail(d.weights, d.noncentrality, mid) > alpha ? lo : hi) = mid;
  }
  return std::sqrt(lo * hi);
}

struct Band {
  double low = 0.0;
  double high = 0.0;
  double mean = 0.0;
};

Band BandAt(const std::vector<Draw>& draws, double h) {
  std::vector<double> prob;
  prob.reserve(draws.size());
  double sum = 0.0;
  for (const Draw& d : draws) {
    prob.push_back(numerics::QuadraticFormTail(d.weights, d.noncentrality, h));
    sum += prob.back();
  }
  return {detail::Quantile(prob, 0.025), detail::Quantile(prob, 0.975),
          sum / static_cast<double>(draws.size())};
}

WindowCalibration Calibrate(int p, int m, int window, double false_alarm) {
  WindowCalibration out;
  const double mm = m;
  out.f_threshold = (mm - 1.0) * p / (mm - p) * numerics::FQuantile(1.0 - false_alarm, p, mm - p);
  const std::vector<Draw> draws = DrawReferences(p, m, window);
  // Each draw's probability falls with h: it is at most the asked one for h at or above its own
  // threshold, so the 97.5 % point of the draws' thresholds keeps 97.5 % of them at or below it.
  std::vector<double> own;
  own.reserve(draws.size());
  for (const Draw& d : draws) {
    own.push_back(ThresholdOf(d, false_alarm, 0.5 * out.f_threshold, 2.0 * out.f_threshold));
  }
  out.threshold = detail::Quantile(own, 0.975);
  const Band at = BandAt(draws, out.threshold);
  out.low = at.low;
  out.high = at.high;
  out.mean = at.mean;
  const Band f = BandAt(draws, out.f_threshold);
  out.f_low = f.low;
  out.f_high = f.high;
  return out;
}

}  // namespace

WindowCalibration CalibrateWindow(int p, int m, int window, double false_alarm) {
  Require(p >= 1 && m >= p + 2, "window calibration: " + std::to_string(p) +
                                    " residuals need at least " + std::to_string(p + 2) +
                                    " reference observations, not " + std::to_string(m));
  Require(window >= 1, "window calibration: the window must hold at least 1 observation");
  Require(false_alarm > 0.0 && false_alarm < 0.5,
          "window calibration: the false-alarm probability per window must lie in (0, 0.5)");
  // The same sizes come again for every session of a process (tests, the bench's restarts).
  static std::mutex mutex;
  static std::map<std::tuple<int, int, int, double>, WindowCalibration> done;
  const auto key = std::make_tuple(p, m, window, false_alarm);
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = done.find(key); it != done.end()) return it->second;
  }
  const WindowCalibration c = Calibrate(p, m, window, false_alarm);
  const std::lock_guard<std::mutex> lock(mutex);
  done.emplace(key, c);
  return c;
}

ReferenceAdvice AdviseReference(int p, int m, int window, double false_alarm) {
  ReferenceAdvice advice;
  for (double factor : {1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0}) {
    const int longer = static_cast<int>(std::ceil(factor * m));
    const WindowCalibration c = CalibrateWindow(p, longer, window, false_alarm);
    if (c.low >= false_alarm / 5.0) {
      advice.observations = longer;
      advice.calibration = c;
      break;
    }
  }
  return advice;
}

}  // namespace vibid::oma
