// Output covariances and the anti-aliased decimation in front of SSI-cov.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "vibid/common/error.hpp"
#include "vibid/oma/ssi_cov.hpp"

namespace vibid::oma {

Eigen::MatrixXd OutputCovariances(Eigen::Ref<const Eigen::MatrixXd> y, int lags) {
  const Eigen::Index n = y.rows();
  const Eigen::Index l = y.cols();
  Require(lags >= 0 && n > lags, "output covariances: fewer samples than lags");
  const Eigen::RowVectorXd mean = y.colwise().mean();
  const Eigen::MatrixXd centred = y.rowwise() - mean;
  Eigen::MatrixXd r(l, l * (lags + 1));
  for (int k = 0; k <= lags; ++k) {
    // R_k = E[y_{t+k} y_tᵀ]: the rows k.. against the rows ..n−k, one product per lag.
    r.middleCols(k * l, l).noalias() =
        centred.bottomRows(n - k).transpose() * centred.topRows(n - k) / static_cast<double>(n - k);
  }
  return r;
}

Eigen::MatrixXd Decimate(Eigen::Ref<const Eigen::MatrixXd> y, int factor) {
  Require(factor >= 1, "decimation: the factor must be at least 1");
  if (factor == 1) return y;
  // Windowed sinc, cut-off at 0.45 of the output rate, Hann window of 48 output periods (its
  // transition band 0.41 … 0.49 of the output rate): the band kept (up to 0.4 of the output
  // rate) passes within 0.3 %, and what would fold back onto it (above 0.6 of the output rate) is
  // attenuated by the window's sidelobes, at least 40 dB.
  // Symmetric taps, applied centred: zero phase, so the modes' phases between channels are kept.
  const int half = 24 * factor;
  const double fc = 0.45 / factor;  // cycles per input sample
  Eigen::VectorXd taps(2 * half + 1);
  for (int j = -half; j <= half; ++j) {
    const double x = 2.0 * fc * j;
    const double sinc = j == 0 ? 1.0 : std::sin(std::numbers::pi * x) / (std::numbers::pi * x);
    const double window = 0.5 * (1.0 + std::cos(std::numbers::pi * j / (half + 1)));
    taps(j + half) = 2.0 * fc * sinc * window;
  }
  taps /= taps.sum();  // unit gain at DC
  const Eigen::Index n = y.rows();
  Require(n > 2 * half + factor, "decimation: the record is shorter than the anti-aliasing filter");
  // Output samples only where the whole filter lies inside the record.
  const Eigen::Index count = (n - 2 * half - 1) / factor + 1;
  Eigen::MatrixXd out(count, y.cols());
  for (Eigen::Index k = 0; k < count; ++k) {
    const Eigen::Index start = k * factor;
    out.row(k).noalias() = taps.transpose() * y.middleRows(start, 2 * half + 1);
  }
  return out;
}

}  // namespace vibid::oma
