#include "vibid/sysid/io_data.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include <Eigen/QR>

#include "vibid/common/error.hpp"

namespace vibid::sysid {

namespace {

Eigen::Index FirstNonFinite(const Eigen::VectorXd& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) return i;
  }
  return -1;
}

Eigen::Vector2d LineFit(const Eigen::VectorXd& v, Trend trend) {
  const Eigen::Index n = v.size();
  if (trend == Trend::kNone || n == 0) return {0.0, 0.0};
  if (trend == Trend::kMean || n == 1) return {v.mean(), 0.0};
  Eigen::MatrixXd phi(n, 2);
  phi.col(0).setOnes();
  phi.col(1) = Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1));
  return phi.colPivHouseholderQr().solve(v);
}

Eigen::VectorXd RemoveLine(const Eigen::VectorXd& v, const Eigen::Vector2d& line) {
  const Eigen::Index n = v.size();
  return v - (Eigen::VectorXd::Constant(n, line[0]) +
              line[1] * Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1)));
}

Eigen::VectorXd FilterCentered(const Eigen::VectorXd& x, const Eigen::VectorXd& h) {
  const Eigen::Index n = x.size();
  const Eigen::Index half = (h.size() - 1) / 2;
  Eigen::VectorXd out(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    double acc = 0.0;
    double gain = 0.0;
    for (Eigen::Index j = -half; j <= half; ++j) {
      const Eigen::Index k = i - j;
      if (k < 0 || k >= n) continue;
      acc += h[j + half] * x[k];
      gain += h[j + half];
    }
    out[i] = acc / gain;
  }
  return out;
}

}  // namespace

IoData MakeIoData(Eigen::Ref<const Eigen::VectorXd> u, Eigen::Ref<const Eigen::VectorXd> y,
                  double dt_s, const std::string& u_name, const std::string& y_name,
                  Eigen::Index min_samples) {
  Require(u.size() == y.size(), "input '" + u_name + "' has " + std::to_string(u.size()) +
                                    " samples but output '" + y_name + "' has " +
                                    std::to_string(y.size()) + ": lengths must match");
  Require(std::isfinite(dt_s) && dt_s > 0.0, "sample period must be a positive number of seconds");
  Require(y.size() >= min_samples, "record too short: " + std::to_string(y.size()) +
                                       " samples, at least " + std::to_string(min_samples) +
                                       " needed");
  IoData d{u, y, dt_s};
  if (const Eigen::Index i = FirstNonFinite(d.u); i >= 0) {
    throw InputError("input '" + u_name + "' is not finite (NaN or Inf) at sample " +
                     std::to_string(i));
  }
  if (const Eigen::Index i = FirstNonFinite(d.y); i >= 0) {
    throw InputError("output '" + y_name + "' is not finite (NaN or Inf) at sample " +
                     std::to_string(i));
  }
  const double u_range = d.u.maxCoeff() - d.u.minCoeff();
  Require(u_range > 1e-12 * std::max(1.0, d.u.cwiseAbs().maxCoeff()),
          "input '" + u_name +
              "' is constant: it is not persistently exciting, so no dynamics can be identified");
  return d;
}

DetrendResult Detrend(const IoData& data, Trend trend) {
  DetrendResult r;
  r.u_trend = LineFit(data.u, trend);
  r.y_trend = LineFit(data.y, trend);
  r.data = IoData{RemoveLine(data.u, r.u_trend), RemoveLine(data.y, r.y_trend), data.dt_s};
  return r;
}

IoData Slice(const IoData& data, Eigen::Index first, Eigen::Index last) {
  Require(first >= 0 && last <= data.samples() && first < last,
          "sample range " + std::to_string(first) + ":" + std::to_string(last) +
              " is empty or outside 0:" + std::to_string(data.samples()));
  return IoData{data.u.segment(first, last - first), data.y.segment(first, last - first),
                data.dt_s};
}

SampleRange ParseSampleRange(const std::string& text, Eigen::Index samples) {
  const auto colon = text.find(':');
  Require(colon != std::string::npos,
          "range '" + text + "' must be FIRST:LAST (sample indices, LAST excluded)");
  auto parse = [&](const std::string& part, Eigen::Index fallback) -> Eigen::Index {
    if (part.empty()) return fallback;
    std::size_t used = 0;
    long long v = -1;
    try {
      v = std::stoll(part, &used);
    } catch (...) {
      used = 0;
    }
    Require(used == part.size() && v >= 0,
            "range '" + text + "': '" + part + "' is not a sample index >= 0");
    return static_cast<Eigen::Index>(v);
  };
  SampleRange r{parse(text.substr(0, colon), 0), parse(text.substr(colon + 1), samples)};
  Require(r.first < r.last && r.last <= samples, "range '" + text +
                                                     "' is empty or beyond the record's " +
                                                     std::to_string(samples) + " samples");
  return r;
}

SplitData Split(const IoData& data, double fraction) {
  Require(fraction > 0.0 && fraction < 1.0, "split fraction must lie strictly between 0 and 1");
  const auto cut =
      static_cast<Eigen::Index>(std::floor(fraction * static_cast<double>(data.samples())));
  return SplitData{Slice(data, 0, cut), Slice(data, cut, data.samples())};
}

Eigen::VectorXd LowPassFir(int taps, double cutoff) {
  Require(taps >= 3 && taps % 2 == 1, "FIR length must be odd and at least 3");
  Require(cutoff > 0.0 && cutoff < 0.5, "FIR cut-off must lie in (0, 0.5) cycles per sample");
  Eigen::VectorXd h(taps);
  const int half = taps / 2;
  constexpr double kPi = std::numbers::pi;
  for (int i = 0; i < taps; ++i) {
    const double m = i - half;
    const double sinc = m == 0 ? 2.0 * cutoff : std::sin(2.0 * kPi * cutoff * m) / (kPi * m);
    const double x = static_cast<double>(i) / static_cast<double>(taps - 1);
    const double window = 0.42 - 0.5 * std::cos(2.0 * kPi * x) + 0.08 * std::cos(4.0 * kPi * x);
    h[i] = sinc * window;
  }
  return h / h.sum();
}

IoData Decimate(const IoData& data, int factor) {
  Require(factor >= 1, "decimation factor must be a positive integer");
  if (factor == 1) return data;
  Require(data.samples() / factor >= 8,
          "decimation by " + std::to_string(factor) + " leaves fewer than 8 samples");
  // 20 taps per output sample: the Blackman window gives about 74 dB stop-band attenuation from
  // roughly 1.1 x the new Nyquist frequency on.
  const Eigen::VectorXd h = LowPassFir(20 * factor + 1, 0.8 * 0.5 / factor);
  const Eigen::VectorXd uf = FilterCentered(data.u, h);
  const Eigen::VectorXd yf = FilterCentered(data.y, h);
  const Eigen::Index n = (data.samples() + factor - 1) / factor;
  IoData out{Eigen::VectorXd(n), Eigen::VectorXd(n), data.dt_s * factor};
  for (Eigen::Index i = 0; i < n; ++i) {
    out.u[i] = uf[i * factor];
    out.y[i] = yf[i * factor];
  }
  return out;
}

}  // namespace vibid::sysid
