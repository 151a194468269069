// Known systems and excitation records shared by the sysid tests: the cart-track models of
// methods §10 with the course's rig values (carts 0.57 kg and 0.56 kg, springs 15 N/m).
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Core>

#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/greybox.hpp"
#include "vibid/sysid/io_data.hpp"

namespace vibid::sysid::testing {

/// Viscous friction values are not given by the source; these give damping ratios of 3–8 %,
/// typical of carts on linear guides.
inline Eigen::VectorXd OneCartValues() { return Eigen::Vector4d(0.57, 0.6, 15.0, 0.25); }  // M, B, k, Bi
inline Eigen::VectorXd TwoCartValues() {
  Eigen::VectorXd v(6);
  v << 0.57, 0.56, 0.6, 0.5, 15.0, 0.25;  // M1, M2, B1, B2, k, Bi
  return v;
}

/// X1/Xi for one cart (2nd order) and two carts (4th order), position input through the first spring.
inline TransferFunction OneCartTf() {
  return Normalized(CartTf(CartConfig{1, CartInput::kPosition}, OneCartValues()));
}
inline TransferFunction TwoCartTf() {
  return Normalized(CartTf(CartConfig{2, CartInput::kPosition}, TwoCartValues()));
}

/// A step of `amplitude` at sample `start`.
inline Eigen::VectorXd Step(Eigen::Index samples, Eigen::Index start, double amplitude) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(samples);
  u.tail(samples - start).setConstant(amplitude);
  return u;
}

/// A rectangular pulse of `amplitude` over samples [start, start + width).
inline Eigen::VectorXd Pulse(Eigen::Index samples, Eigen::Index start, Eigen::Index width, double amplitude) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(samples);
  u.segment(start, width).setConstant(amplitude);
  return u;
}

/// White Gaussian noise with standard deviation `sigma`, seeded.
inline Eigen::VectorXd WhiteNoise(Eigen::Index samples, double sigma, std::uint32_t seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  Eigen::VectorXd e(samples);
  for (Eigen::Index i = 0; i < samples; ++i) e[i] = normal(gen);
  return e;
}

inline double Rms(const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / static_cast<double>(v.size())); }

/// Largest relative coefficient error between two monic TFs of the same orders.
inline double MaxRelativeError(const TransferFunction& estimate, const TransferFunction& truth) {
  double worst = 0.0;
  for (Eigen::Index i = 1; i < truth.den.size(); ++i) {
    worst = std::max(worst, std::abs(estimate.den[i] - truth.den[i]) / std::abs(truth.den[i]));
  }
  for (Eigen::Index i = 0; i < truth.num.size(); ++i) {
    worst = std::max(worst, std::abs(estimate.num[i] - truth.num[i]) / std::abs(truth.num[i]));
  }
  return worst;
}

}  // namespace vibid::sysid::testing
