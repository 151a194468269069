// Hotelling's two-sample T² of a window's mean against the reference observations.
#include "vibid/oma/accumulated_test.hpp"

#include <cmath>
#include <string>

#include <Eigen/Cholesky>

#include "vibid/common/error.hpp"

namespace vibid::oma {

AccumulatedTest::AccumulatedTest(Eigen::Ref<const Eigen::MatrixXd> reference, int window,
                                 double false_alarm)
    : window_(window), m_(static_cast<int>(reference.cols())) {
  const auto p = static_cast<int>(reference.rows());
  Require(window >= 1, "accumulated test: the window must hold at least 1 observation");
  Require(false_alarm > 0.0 && false_alarm < 0.5,
          "accumulated test: the false-alarm probability per window must lie in (0, 0.5)");
  Require(p >= 1 && m_ >= p + 2, "accumulated test: " + std::to_string(p) +
                                     " residuals need at least " + std::to_string(p + 2) +
                                     " reference observations, not " + std::to_string(m_));
  Require(reference.allFinite(), "accumulated test: a reference observation is not finite");
  mean_ = reference.rowwise().mean();
  const Eigen::MatrixXd centred = reference.colwise() - mean_;
  const Eigen::MatrixXd cov = centred * centred.transpose() / (m_ - 1.0);
  Eigen::LDLT<Eigen::MatrixXd> ldlt(cov);
  Require(ldlt.info() == Eigen::Success && ldlt.isPositive() && ldlt.vectorD().minCoeff() > 0.0,
          "accumulated test: the reference observations' covariance is singular");
  precision_ = ldlt.solve(Eigen::MatrixXd::Identity(p, p));
  calibration_ = CalibrateWindow(p, m_, window, false_alarm);
  threshold_ = calibration_.threshold;
  sum_ = Eigen::VectorXd::Zero(p);
}

double AccumulatedTest::Statistic(Eigen::Ref<const Eigen::MatrixXd> observations) const {
  Require(observations.rows() == mean_.size() && observations.cols() >= 1,
          "accumulated test: observations of " + std::to_string(mean_.size()) + " rows");
  const double k = static_cast<double>(observations.cols());
  const Eigen::VectorXd d = observations.rowwise().mean() - mean_;
  return d.dot(precision_ * d) / (1.0 / k + 1.0 / m_);
}

AccumulatedTestResult AccumulatedTest::Add(Eigen::Ref<const Eigen::VectorXd> observation) {
  Require(observation.size() == mean_.size() && observation.allFinite(),
          "accumulated test: an observation must hold " + std::to_string(mean_.size()) +
              " finite values");
  sum_ += observation;
  ++count_;
  AccumulatedTestResult r;
  r.count = count_;
  const Eigen::VectorXd d = sum_ / count_ - mean_;
  r.statistic = d.dot(precision_ * d) / (1.0 / count_ + 1.0 / m_);
  r.threshold = threshold_;
  r.complete = count_ == window_;
  r.alarm = r.complete && r.statistic > threshold_;
  if (r.complete) {
    sum_.setZero();
    count_ = 0;
  }
  return r;
}

}  // namespace vibid::oma
