// From a double-precision multi-input observer to the integer description the board runs, and
// the host's replay of that description through the shared kernel.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/dob/discretize.hpp"
#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::dob {

/// One input of the observer: what it measures, where, its full scale, and the discrete transfer
/// function from it (SI units) to its share of d_hat (N).
struct ObserverPath {
  fixed::InputKind kind = fixed::InputKind::kForce;
  int dof = 0;                  ///< 0-based mass index of the sensor or force.
  double full_scale = 1.0;      ///< SI value of Q31 full scale (N, m, m/s or m/s^2).
  std::vector<SosSection> sos;  ///< N per input unit.
};

struct QuantizeOptions {
  std::uint32_t sample_rate_hz = 0;
  int output_dof = 0;
  double output_full_scale_n = 0.0;  ///< N that d_hat's Q31 full scale stands for.
};

struct QuantizeResult {
  fixed::FilterDescription description{};
  bool ok = false;      ///< Validated and every section stable on the integers.
  std::string message;  ///< Why not, when !ok.
  /// Rounding noise predicted at d_hat from the section outputs' 1/2-LSB rounding (N rms).
  double predicted_noise_rms_n = 0.0;
  /// 10 log10(full-scale sine power / predicted noise power).
  double predicted_snr_db = 0.0;
  /// l1 norm of each path's impulse response in Q31 units: > 1 means a worst-case full-scale input
  /// on that path alone would saturate d_hat.
  std::vector<double> path_l1_gain;
};

/// Scales every section from the l1 norm of the impulse response from the path input to that
/// section's output (so no section output can leave Q31 for any input within full scale), picks
/// each section's shift from its largest coefficient and the accumulator bound, rounds to Q31 and
/// seals the description. The full scales are rounded to binary32 first, as the description
/// carries them. InputError for paths the format cannot hold (count, sections, ranges).
QuantizeResult QuantizeObserver(const std::vector<ObserverPath>& paths,
                                const QuantizeOptions& options);

/// The full scales as the description stores them (binary32), for converting signals.
double StoredFullScale(double full_scale);

/// value / full_scale as Q31, rounded to nearest and saturated.
std::int32_t ToQ31(double value, double full_scale);

struct FixedRun {
  Eigen::VectorXd d_hat_n;
  std::vector<std::int32_t> d_hat_q31;
  std::uint32_t saturations = 0;
};

/// Replays the board: converts each input to Q31 by its stored full scale and steps the shared
/// kernel (vibid::fixed::DobFilter) sample by sample. InputError if the description does not
/// validate or the input count or lengths disagree.
FixedRun RunFixed(const fixed::FilterDescription& description,
                  const std::vector<Eigen::VectorXd>& inputs_si);

/// The same observer in double precision (the designed, unquantized sections).
Eigen::VectorXd RunFloat(const std::vector<ObserverPath>& paths,
                         const std::vector<Eigen::VectorXd>& inputs_si);

}  // namespace vibid::dob
