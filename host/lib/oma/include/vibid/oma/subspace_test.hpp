// Change detection on the responses alone: the subspace residual test (methods §13; Basseville,
// Abdelghani & Benveniste, Automatica 36 2000; covariance estimated from data as in Döhler &
// Mevel, MSSP 38 2013).
//
// A reference record of the rig in its calibrated state gives the left null space S0 of its
// Hankel matrix of output covariances (the model order n = 2 × modes kept). For a later block of
// the same length, ζ = √N vec(S0ᵀ H) is zero-mean Gaussian while the rig is unchanged; a change
// of its modes moves the column space of H and gives ζ a mean. The reference is split in two
// parts (halves by default): the first gives S0, the second gives independent blocks whose
// residuals estimate ζ's mean and covariance. The statistic is Hotelling's T² of a new block
// against those blocks, and its threshold the exact prediction quantile (an F distribution), so the
// false-alarm rate per block is the one asked for whenever the blocks are independent and ζ
// Gaussian.
//
// Sensitivity is the block's: on the demo rig (modes at 4.5 and 10.6 Hz, ζ 2 to 4 %) one 10 s
// block flags a 20 % change of m2 (about 6 % in ω) in 18 blocks of 20, and not a 3 % one (about
// 1 % in ω, below the frequency scatter of 10 s of data); smaller changes need longer blocks.
#pragma once

#include <Eigen/Core>

namespace vibid::oma {

struct SubspaceTestOptions {
  double fs_hz = 0.0;    ///< Sample rate of the responses (> 0).
  double fmax_hz = 0.0;  ///< Top of the band (the data are decimated to about 2.5 fmax).
  int order = 0;         ///< Model order n = 2 × modes in the band (≥ 2, even).
  /// The Hankel matrix's lags span one period of this frequency; 0: fmax/10. Longer lags turn
  /// further with a change of frequency (a 1 % change of a 4.4 Hz mode: 0.08 rad over the default
  /// 0.4 s, 0.28 rad over 1.4 s), so a lower fmin sees smaller changes, as long as the lightly
  /// damped modes still ring at the longest lag. A block must span at least ten such periods.
  double fmin_hz = 0.0;
  double block_s = 10.0;      ///< Length of one tested block.
  double false_alarm = 1e-3;  ///< Probability that an unchanged block alarms, (0, 0.5).
  /// Share of the reference that gives the null space S0 (the rest gives the residuals' mean and
  /// covariance), in [0.1, 0.9]. An error of S0 only moves the residuals' mean, which the rest
  /// estimates, so a small share keeps the test exact and leaves more blocks for the statistics:
  /// a test accumulated over many blocks is limited by how well the reference's mean is known.
  double null_space_share = 0.5;

  void Validate() const;
};

struct SubspaceTestResult {
  double statistic = 0.0;  ///< Hotelling's T² of the block.
  double threshold = 0.0;  ///< Its (1 − false_alarm) quantile under the reference state.
  bool alarm = false;
};

/// The test's size for `channels` responses: what the reference and the blocks must hold.
struct SubspaceTestSize {
  int decimation = 1;
  int block_rows = 0;  ///< Of the Hankel matrix (p + 1) and its columns (q).
  int block_cols = 0;
  int lag_step = 1;  ///< τ: the Hankel matrix holds R_τ, R_2τ, … (decimated samples).
  int dof = 0;       ///< Residuals.
  long block_samples = 0;
  double min_block_s = 0.0;         ///< The shortest block the band allows.
  int reference_blocks_needed = 0;  ///< 2 × (dof + 10) after the null space's part.
  double min_reference_s = 0.0;     ///< The shortest reference.
};

/// Validates the options (InputError) and sizes the test.
SubspaceTestSize SubspaceTestSizeOf(const SubspaceTestOptions& options, int channels);

class SubspaceDetector {
 public:
  /// The reference: at least 2 × (dof + 10) blocks of the rig unchanged after the part that
  /// gives the null space (InputError naming how long a record is needed otherwise).
  SubspaceDetector(Eigen::Ref<const Eigen::MatrixXd> reference, const SubspaceTestOptions& options);

  /// One block of block_s seconds at fs_hz (exactly block_samples() rows).
  SubspaceTestResult Test(Eigen::Ref<const Eigen::MatrixXd> block) const;
  /// The block's residual ζ (dof() values), as Test compares it with the reference's: for a test
  /// accumulated over blocks (AccumulatedTest against reference_residuals()).
  Eigen::VectorXd BlockResidual(Eigen::Ref<const Eigen::MatrixXd> block) const;
  /// The residuals of the reference's independent blocks (after the null space's part):
  /// dof() × blocks.
  const Eigen::MatrixXd& reference_residuals() const { return reference_residuals_; }

  long block_samples() const { return block_samples_; }
  int dof() const { return static_cast<int>(mean_.size()); }
  int reference_blocks() const { return reference_blocks_; }
  double threshold() const { return threshold_; }

 private:
  Eigen::VectorXd Residual(Eigen::Ref<const Eigen::MatrixXd> block) const;

  SubspaceTestOptions options_;
  int decimation_ = 1;
  int block_rows_ = 0;  // p + 1
  int block_cols_ = 0;  // q
  int lag_step_ = 1;    // τ: the Hankel matrix holds R_τ, R_2τ, …
  long block_samples_ = 0;
  int reference_blocks_ = 0;
  Eigen::MatrixXd s0_;  // left null space of the reference Hankel matrix
  Eigen::MatrixXd reference_residuals_;
  Eigen::VectorXd mean_;       // of the reference blocks' residuals
  Eigen::MatrixXd precision_;  // inverse of their covariance
  double t2_scale_ = 0.0;      // T² = t2_scale F(dof, m − dof) for a new block
  double threshold_ = 0.0;
};

}  // namespace vibid::oma
