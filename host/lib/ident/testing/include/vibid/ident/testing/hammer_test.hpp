// Synthetic hammer tests on a known rig, for end-to-end checks of the identification chain: hits
// of random spacing and height (half-sine pulses), the model core's exact zero-order-hold
// simulation at `oversample` times the sample rate, the same boxcar anti-aliasing average on every
// channel before decimation (as a DAQ's identical channel filters, it cancels in every FRF), and
// white noise on the force and on every response. Simulating at the sample rate itself would let
// the zero-order hold delay the dynamic response by half a sample against the accelerometer's
// direct force term, an error of order omega T in the identified shapes.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "vibid/ident/spectral.hpp"
#include "vibid/model/model.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::ident {

struct HammerTestSpec {
  int hammer_dof = 0;              ///< 0-based DOF that is hit.
  std::vector<int> response_dofs;  ///< 0-based DOFs with a sensor; empty: all.
  Quantity sensor = Quantity::kAcceleration;
  double fs_hz = 1000.0;
  int oversample = 16;
  int hits = 5;
  double hit_peak_n = 50.0;
  double hit_peak_spread = 0.3;  ///< Peak uniform in (1 +- spread) hit_peak_n.
  double pulse_width_s = 0.002;
  double spacing_min_s = 8.0;  ///< Hit spacing uniform in [min, max].
  double spacing_max_s = 11.0;
  double lead_s = 0.5;  ///< Quiet time before the first hit.
  /// Every hit followed by a rebound (a second half-sine of the same width) this long after the
  /// hit's start, of this fraction of the hit's peak; 0: none.
  double rebound_delay_s = 0.0;
  double rebound_fraction = 0.0;
  /// Hits made unlike the others, by 0-based hit number: a double hit, an overload, a light tap.
  struct HitChange {
    int hit = 0;
    double scale = 1.0;            ///< The hit's peak multiplied by this.
    double second_delay_s = 0.0;   ///< A second pulse this long after the hit's start (0: none)
    double second_fraction = 0.0;  ///< of this fraction of the hit's peak.
  };
  std::vector<HitChange> changes;
  /// Record end this long after the last hit's start (s); 0: one more spacing after it.
  double tail_s = 0.0;
  /// Coulomb friction (model/simulate.hpp: empty none, one entry for every mass, or one per DOF):
  /// simulated by RK4 at the oversampled step instead of the exact zero-order hold.
  std::vector<model::CoulombFriction> friction;
  /// Noise standard deviations as fractions of each channel's peak value.
  double force_noise = 0.002;
  double response_noise = 0.002;
  std::uint64_t seed = 1;

  void Validate(int dofs) const;
};

struct HammerTestRecord {
  Eigen::VectorXd t_s;
  Eigen::VectorXd force_n;
  Eigen::MatrixXd response;  ///< One column per response DOF, in the sensor's SI unit.
  std::vector<double> hit_times_s;
};

HammerTestRecord SimulateHammerTest(const model::Model& rig, const HammerTestSpec& spec);

/// The identification scenario's modal test (the library's end-to-end tests and the CLI's): mass 2
/// (DOF 1) of the chain hit ten times, 4 ms pulses 16 to 20 s apart, every mass measured.
HammerTestSpec ModalTestSpec(double fs_hz, std::uint64_t seed);
/// Its mass test: the one mass of a single-DOF rig hit five times, 4 ms pulses 10 to 13 s apart.
HammerTestSpec MassTestSpec(double fs_hz, std::uint64_t seed);

/// CSV with t_s, the force column `force_name` and the response columns named `names` (one per
/// response).
std::string FormatHammerTestCsv(const HammerTestRecord& record,
                                const std::vector<std::string>& names,
                                const std::string& force_name = "force_n");

}  // namespace vibid::ident
