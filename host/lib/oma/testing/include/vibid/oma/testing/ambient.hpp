// Responses of a linear model under operating excitation: independent white forces on the chosen
// masses, exact (zero-order-hold) simulation, accelerations (or positions) with white measurement
// noise. The reference values of the output-only tests are the model's own modes.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "vibid/model/model.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::oma::testing {

struct AmbientOptions {
  double fs_hz = 1000.0;
  double seconds = 600.0;     ///< For SimulateAmbient.
  double force_rms_n = 1.0;   ///< Of each white force (held over each sample).
  std::vector<int> excited;   ///< 0-based masses driven; empty: every mass.
  bool accelerations = true;  ///< false: positions.
  double noise_ratio = 0.01;  ///< Measurement noise rms relative to each channel's rms.
  std::uint64_t seed = 1;
};

/// A running rig: records drawn one after another continue the same motion; the model can be
/// changed between two records (a mass added) without a jump in the state.
class AmbientRig {
 public:
  /// Settles for 20 s and measures each channel's rms (the noise is relative to it).
  AmbientRig(const model::Model& model, const AmbientOptions& options);
  /// The next `samples` rows, one column per mass.
  Eigen::MatrixXd Next(Eigen::Index samples);
  /// From now on the rig is `model` (same number of masses), the motion continuing.
  void Change(const model::Model& model);

 private:
  void Step(Eigen::VectorXd* out);

  AmbientOptions options_;
  std::vector<int> excited_;
  std::unique_ptr<model::Simulator> simulator_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Eigen::VectorXd force_;
  Eigen::VectorXd noise_rms_;
};

/// options.seconds of a fresh rig: one row per sample, one column per mass.
Eigen::MatrixXd SimulateAmbient(const model::Model& model, const AmbientOptions& options);

}  // namespace vibid::oma::testing
