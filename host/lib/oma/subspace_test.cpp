// The subspace residual test: S0 from the first half of the reference, the residuals' mean and
// covariance from independent blocks of the second half, Hotelling's T² with its exact threshold.
#include "vibid/oma/subspace_test.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"
#include "vibid/oma/ssi_cov.hpp"

namespace vibid::oma {
namespace {

// H(a, b) = R_{(a+b+1)τ}, a = 0 … rows−1, b = 0 … cols−1: the covariances of the system sampled
// every τ samples (A^τ in place of A), so a small matrix spans long lags.
Eigen::MatrixXd Hankel(Eigen::Ref<const Eigen::MatrixXd> y, int rows, int cols, int step) {
  const int l = static_cast<int>(y.cols());
  const Eigen::MatrixXd r = OutputCovariances(y, (rows + cols - 1) * step);
  Eigen::MatrixXd h(rows * l, cols * l);
  for (int a = 0; a < rows; ++a) {
    for (int b = 0; b < cols; ++b) {
      h.block(a * l, b * l, l, l) = r.middleCols((a + b + 1) * step * l, l);
    }
  }
  return h;
}

}  // namespace

void SubspaceTestOptions::Validate() const {
  Require(std::isfinite(fs_hz) && fs_hz > 0.0, "subspace test: fs_hz must be positive");
  Require(std::isfinite(fmax_hz) && fmax_hz > 0.0 && fmax_hz <= fs_hz / 2.0,
          "subspace test: fmax_hz must lie in (0, fs/2]");
  Require(order >= 2 && order % 2 == 0 && order <= 40,
          "subspace test: order must be even, 2 to 40 (twice the modes in the band)");
  Require(std::isfinite(fmin_hz) && fmin_hz >= 0.0 && fmin_hz < fmax_hz,
          "subspace test: fmin_hz must lie in [0, fmax_hz) (0: fmax/10)");
  Require(std::isfinite(block_s) && block_s > 0.0, "subspace test: block_s must be positive");
  Require(null_space_share >= 0.1 && null_space_share <= 0.9,
          "subspace test: null_space_share must lie in [0.1, 0.9]");
  Require(false_alarm > 0.0 && false_alarm < 0.5,
          "subspace test: false_alarm must lie in (0, 0.5)");
}

SubspaceTestSize SubspaceTestSizeOf(const SubspaceTestOptions& options, int channels) {
  options.Validate();
  Require(channels >= 1, "subspace test: at least one response channel");
  const int l = channels;
  SubspaceTestSize z;
  z.decimation = std::max(1, static_cast<int>(std::floor(options.fs_hz / (2.5 * options.fmax_hz))));
  // The smallest Hankel matrix that can hold the order (q l ≥ n, (p + 1) l > n): a small
  // residual, so that its covariance is well estimated from a few dozen reference blocks.
  z.block_cols = (options.order + l - 1) / l;
  z.block_rows = options.order / l + 1;
  // The lags span about one period of the lowest mode the band may hold (fmin, by default
  // fmax / 10): a change of frequency turns the phase of the long lags, which is what the
  // residual sees.
  const double fs_d_hz = options.fs_hz / z.decimation;
  const double fmin_hz = options.fmin_hz > 0.0 ? options.fmin_hz : 0.1 * options.fmax_hz;
  z.lag_step =
      std::max(1, static_cast<int>(std::lround(fs_d_hz / fmin_hz / (z.block_rows + z.block_cols))));
  z.dof = (z.block_rows * l - options.order) * z.block_cols * l;
  z.block_samples = std::lround(options.block_s * options.fs_hz);
  const long needed = 10 * (z.block_rows + z.block_cols) * z.lag_step;
  z.min_block_s = static_cast<double>((needed + 48) * z.decimation) / options.fs_hz;
  z.reference_blocks_needed = 2 * (z.dof + 10);
  z.min_reference_s =
      z.reference_blocks_needed * options.block_s / (1.0 - options.null_space_share);
  return z;
}

SubspaceDetector::SubspaceDetector(Eigen::Ref<const Eigen::MatrixXd> reference,
                                   const SubspaceTestOptions& options)
    : options_(options) {
  const int l = static_cast<int>(reference.cols());
  const SubspaceTestSize size = SubspaceTestSizeOf(options, l);
  Require(reference.allFinite(), "subspace test: the reference holds a non-finite value");
  decimation_ = size.decimation;
  block_cols_ = size.block_cols;
  block_rows_ = size.block_rows;
  lag_step_ = size.lag_step;
  const int null_dim = block_rows_ * l - options.order;
  const int dof = size.dof;
  block_samples_ = size.block_samples;
  Require(block_samples_ / decimation_ - 48 >= 10 * (block_rows_ + block_cols_) * lag_step_,
          "subspace test: block_s is too short for the band (at least " +
              std::to_string(size.min_block_s) + " s)");

  // S0 from the first part of the reference (null_space_share of it).
  const auto half = static_cast<Eigen::Index>(
      std::floor(options.null_space_share * static_cast<double>(reference.rows())));
  const int needed_blocks = size.reference_blocks_needed;
  const Eigen::Index have_blocks = (reference.rows() - half) / block_samples_;
  if (have_blocks < needed_blocks) {
    throw InputError("subspace test: the reference is too short: " + std::to_string(dof) +
                     " residuals need at least " + std::to_string(needed_blocks) + " blocks of " +
                     std::to_string(options.block_s) + " s after the part that gives the null " +
                     "space, " +
                     std::to_string(static_cast<long>(std::ceil(size.min_reference_s - 1e-9))) +
                     " s of reference in all (or shorten block_s)");
  }
  const Eigen::MatrixXd h0 =
      Hankel(Decimate(reference.topRows(half), decimation_), block_rows_, block_cols_, lag_step_);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(h0, Eigen::ComputeFullU);
  s0_ = svd.matrixU().rightCols(null_dim);

  // The residuals of independent blocks of the second half: mean and covariance.
  reference_blocks_ = static_cast<int>(have_blocks);
  Eigen::MatrixXd z(dof, reference_blocks_);
  for (int j = 0; j < reference_blocks_; ++j) {
    z.col(j) = Residual(reference.middleRows(half + j * block_samples_, block_samples_));
  }
  reference_residuals_ = z;
  mean_ = z.rowwise().mean();
  const Eigen::MatrixXd centred = z.colwise() - mean_;
  const Eigen::MatrixXd cov = centred * centred.transpose() / (reference_blocks_ - 1.0);
  Eigen::LDLT<Eigen::MatrixXd> ldlt(cov);
  Require(ldlt.info() == Eigen::Success && ldlt.isPositive() && ldlt.vectorD().minCoeff() > 0.0,
          "subspace test: the reference residuals' covariance is singular (constant channels?)");
  precision_ = ldlt.solve(Eigen::MatrixXd::Identity(dof, dof));
  // A new observation against m reference observations (sample mean and covariance):
  // T² · m (m − p) / ((m + 1)(m − 1) p) ~ F(p, m − p).
  const double m = reference_blocks_;
  const double p = dof;
  t2_scale_ = (m + 1.0) * (m - 1.0) * p / (m * (m - p));
  threshold_ = t2_scale_ * numerics::FQuantile(1.0 - options.false_alarm, p, m - p);
}

Eigen::VectorXd SubspaceDetector::Residual(Eigen::Ref<const Eigen::MatrixXd> block) const {
  const Eigen::MatrixXd yd = Decimate(block, decimation_);
  const Eigen::MatrixXd h = Hankel(yd, block_rows_, block_cols_, lag_step_);
  // Normalised by the block's own output power: a change of the excitation's level alone does
  // not move the statistic.
  const double power =
      (yd.rowwise() - yd.colwise().mean()).squaredNorm() / static_cast<double>(yd.rows());
  const Eigen::MatrixXd r = s0_.transpose() * h / power;
  return std::sqrt(static_cast<double>(yd.rows())) *
         Eigen::Map<const Eigen::VectorXd>(r.data(), r.size());
}

Eigen::VectorXd SubspaceDetector::BlockResidual(Eigen::Ref<const Eigen::MatrixXd> block) const {
  Require(block.rows() == block_samples_ && block.cols() == s0_.rows() / block_rows_,
          "subspace test: a block must hold " + std::to_string(block_samples_) + " samples of " +
              std::to_string(s0_.rows() / block_rows_) + " channels");
  return Residual(block);
}

SubspaceTestResult SubspaceDetector::Test(Eigen::Ref<const Eigen::MatrixXd> block) const {
  const Eigen::VectorXd d = BlockResidual(block) - mean_;
  SubspaceTestResult r;
  r.statistic = d.dot(precision_ * d);
  r.threshold = threshold_;
  r.alarm = r.statistic > threshold_;
  return r;
}

}  // namespace vibid::oma
