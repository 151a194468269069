#include "vibid/oma/testing/ambient.hpp"

#include <cmath>

namespace vibid::oma::testing {

AmbientRig::AmbientRig(const model::Model& model, const AmbientOptions& options)
    : options_(options), rng_(options.seed) {
  const int n = model.dofs();
  excited_ = options.excited;
  if (excited_.empty()) {
    for (int k = 0; k < n; ++k) excited_.push_back(k);
  }
  force_ = Eigen::VectorXd::Zero(n);
  noise_rms_ = Eigen::VectorXd::Zero(n);
  model::SimulationOptions sim;
  sim.method = model::Method::kExact;
  sim.dt_s = 1.0 / options.fs_hz;
  simulator_ = std::make_unique<model::Simulator>(model, sim);
  // Settle into the stationary state, then measure each channel's rms for the noise.
  const auto settle = static_cast<Eigen::Index>(std::llround(20.0 * options.fs_hz));
  Eigen::VectorXd out(n);
  Eigen::VectorXd sum_sq = Eigen::VectorXd::Zero(n);
  for (Eigen::Index t = 0; t < 2 * settle; ++t) {
    Step(&out);
    if (t >= settle) sum_sq += out.cwiseAbs2();
  }
  noise_rms_ = options.noise_ratio * (sum_sq / static_cast<double>(settle)).cwiseSqrt();
}

void AmbientRig::Step(Eigen::VectorXd* out) {
  for (int k : excited_) force_(k) = options_.force_rms_n * normal_(rng_);
  simulator_->Step(force_);
  *out = options_.accelerations ? simulator_->acceleration_m_s2() : simulator_->position_m();
}

Eigen::MatrixXd AmbientRig::Next(Eigen::Index samples) {
  const Eigen::Index n = force_.size();
  Eigen::MatrixXd y(samples, n);
  Eigen::VectorXd out(n);
  for (Eigen::Index t = 0; t < samples; ++t) {
    Step(&out);
    for (Eigen::Index c = 0; c < n; ++c) y(t, c) = out(c) + noise_rms_(c) * normal_(rng_);
  }
  return y;
}

void AmbientRig::Change(const model::Model& model) {
  model::SimulationOptions sim;
  sim.method = model::Method::kExact;
  sim.dt_s = 1.0 / options_.fs_hz;
  sim.x0_m = simulator_->position_m();
  sim.v0_m_s = simulator_->velocity_m_s();
  simulator_ = std::make_unique<model::Simulator>(model, sim);
}

Eigen::MatrixXd SimulateAmbient(const model::Model& model, const AmbientOptions& options) {
  AmbientRig rig(model, options);
  return rig.Next(static_cast<Eigen::Index>(std::llround(options.seconds * options.fs_hz)));
}

}  // namespace vibid::oma::testing
