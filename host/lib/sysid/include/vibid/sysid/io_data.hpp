// Input–output records for identification: one input u, one output y, uniformly sampled.
//
// Every estimator in this module takes an IoData. It is built (and checked) once from user input,
// so the estimators themselves only deal with numerics.
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Core>

namespace vibid::sysid {

struct IoData {
  Eigen::VectorXd u;  ///< Input samples (SI, e.g. N or V).
  Eigen::VectorXd y;  ///< Output samples (SI, e.g. m).
  double dt_s = 1.0;  ///< Sample period, seconds (1 for records given in sample units).

  Eigen::Index samples() const { return y.size(); }
};

/// Builds an IoData and checks it: equal lengths, finite values, a positive sample period, at least
/// `min_samples` samples, and an input that is not constant (a constant input is not persistently
/// exciting: no dynamics can be told apart). Throws InputError naming the problem;
/// `u_name`/`y_name` name the signals in messages.
IoData MakeIoData(Eigen::Ref<const Eigen::VectorXd> u, Eigen::Ref<const Eigen::VectorXd> y,
                  double dt_s, const std::string& u_name = "input",
                  const std::string& y_name = "output", Eigen::Index min_samples = 8);

enum class Trend { kNone, kMean, kLinear };

/// Removes the mean or a least-squares straight line from each signal. The removed trend is
/// returned so a model's predictions can be put back on the original scale.
struct DetrendResult {
  IoData data;
  Eigen::Vector2d u_trend{0.0, 0.0};  ///< Removed offset and slope per sample of u.
  Eigen::Vector2d y_trend{0.0, 0.0};  ///< Removed offset and slope per sample of y.
};
DetrendResult Detrend(const IoData& data, Trend trend);

/// Samples [first, last) of the record. InputError when the range is empty or out of bounds.
IoData Slice(const IoData& data, Eigen::Index first, Eigen::Index last);

/// Parses a range "a:b" of sample indices, half-open [a, b). An empty bound means the start or end
/// of the record; negative indices are not accepted.
struct SampleRange {
  Eigen::Index first = 0;
  Eigen::Index last = 0;
};
SampleRange ParseSampleRange(const std::string& text, Eigen::Index samples);

/// The first `fraction` of the record for estimation, the rest for validation.
struct SplitData {
  IoData estimation;
  IoData validation;
};
SplitData Split(const IoData& data, double fraction);

/// Keeps every `factor`-th sample after low-pass filtering both signals with a linear-phase FIR
/// (windowed sinc, Blackman window, cut-off at 0.8 × the new Nyquist frequency, delay compensated
/// so the output is not shifted in time). The first and last half filter lengths use a shortened
/// kernel renormalised to unit DC gain, so a constant passes unchanged everywhere.
IoData Decimate(const IoData& data, int factor);

/// The anti-alias FIR used by Decimate: `taps` (odd) coefficients, cut-off `cutoff` in cycles per
/// input sample (0 < cutoff < 0.5), unit DC gain.
Eigen::VectorXd LowPassFir(int taps, double cutoff);

}  // namespace vibid::sysid
