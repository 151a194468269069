// Known systems and excitation records shared by the sysid tests: the cart-track models of
// methods §10 with the course's rig values (carts 0.57 kg and 0.56 kg, springs 15 N/m).
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include <Eigen/Core>

#include "vibid/model/model.hpp"
#include "vibid/model/simulate.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/greybox.hpp"
#include "vibid/sysid/io_data.hpp"

namespace vibid::sysid::testing {

/// Viscous friction values are not given by the source; these give damping ratios of 3–8 %,
/// typical of carts on linear guides.
inline Eigen::VectorXd OneCartValues() {
  return Eigen::Vector4d(0.57, 0.6, 15.0, 0.25);
}  // M, B, k, Bi
inline Eigen::VectorXd TwoCartValues() {
  Eigen::VectorXd v(6);
  v << 0.57, 0.56, 0.6, 0.5, 15.0, 0.25;  // M1, M2, B1, B2, k, Bi
  return v;
}

/// X1/Xi for one cart (2nd order) and two carts (4th order), position input through the first
/// spring.
inline TransferFunction OneCartTf() {
  return Normalized(CartTf(CartConfig{1, CartInput::kPosition}, OneCartValues()));
}
inline TransferFunction TwoCartTf() {
  return Normalized(CartTf(CartConfig{2, CartInput::kPosition}, TwoCartValues()));
}

/// Force-driven cart track of the model core (ground –k– M1 [–k– M2] –k– ground), one or two
/// carts, simulated exactly (ZOH) by the model core with the force `shape` (a model::ForceShape
/// spec, e.g. "pulse:dof=1,amp=5,width=0.1,t0=0.1"). Returns the force on cart 1 and its position.
struct ModelCoreRecord {
  Eigen::VectorXd force_n;
  Eigen::VectorXd x1_m;
  TransferFunction truth;  ///< X1/F from the model core's first-principle TF.
};
inline ModelCoreRecord SimulateCartTrack(int carts, const std::string& shape, double dt_s,
                                         double t_end_s) {
  const Eigen::VectorXd v = carts == 1 ? OneCartValues() : TwoCartValues();
  const Eigen::VectorXd masses =
      carts == 1 ? Eigen::VectorXd(v.head(1)) : Eigen::VectorXd(v.head(2));
  const Eigen::VectorXd frictions =
      carts == 1 ? Eigen::VectorXd(v.segment(1, 1)) : Eigen::VectorXd(v.segment(2, 2));
  const double k = v[2 * carts];
  const model::Model m = model::MakeCartTrack(masses, k, frictions);
  model::ForceInput force;
  force.shapes.push_back(model::ParseForceShape(shape));
  model::SimulationOptions o;
  o.method = model::Method::kExact;
  o.dt_s = dt_s;
  o.t_end_s = t_end_s;
  const model::SimulationResult r = model::Simulate(m, force, o);
  const TransferFunction tf =
      CartTf(CartConfig{carts, CartInput::kForce},
             carts == 1 ? Eigen::VectorXd(v.head(3)) : Eigen::VectorXd(v.head(5)));
  return {r.force_n.col(0), r.x_m.col(0), tf};
}

/// A step of `amplitude` at sample `start`.
inline Eigen::VectorXd Step(Eigen::Index samples, Eigen::Index start, double amplitude) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(samples);
  u.tail(samples - start).setConstant(amplitude);
  return u;
}

/// A rectangular pulse of `amplitude` over samples [start, start + width).
inline Eigen::VectorXd Pulse(Eigen::Index samples, Eigen::Index start, Eigen::Index width,
                             double amplitude) {
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

inline double Rms(const Eigen::VectorXd& v) {
  return std::sqrt(v.squaredNorm() / static_cast<double>(v.size()));
}

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
