// Disturbance-observer design (methods section 9): Q-filter, nominal-model inverse, one
// multi-input discrete system, stability check, quantization for the board.
//
//   SISO  d_hat = Q G_A^-1 y - Q u              (Eq. 13; inputs: sensor y, force u)
//   MIMO  d_hat = Q [M x'' + C x' + K x - F]_j  (row j = the force's mass; inputs: the sensors of
//                                                 every mass in that row, and F_j)
//
// Velocity and acceleration sensors put integrators into G_A^-1 (1/s per order). They are
// realized as leaky integrators 1/(s + 2 pi leak_hz), so d_hat is valid from 10 leak_hz upwards
// (phase error below 6 degrees there); displacement sensing is valid down to DC. The upper band
// edge is where |Q(j omega) - 1| reaches 0.1.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "vibid/dob/discretize.hpp"
#include "vibid/dob/q_filter.hpp"
#include "vibid/dob/quantize.hpp"

namespace vibid::dob {

enum class SensorKind { kDisplacement = 0, kVelocity = 1, kAcceleration = 2 };
enum class ObserverForm { kSiso, kMimo };
enum class Discretization { kTustin, kZeroOrderHold };

/// What the design needs from the nominal model.
struct NominalPlant {
  /// SISO: receptance from the force at input_dof to the displacement at output_dof (m/N),
  /// powers of s highest first.
  Eigen::VectorXd receptance_num;
  Eigen::VectorXd receptance_den;
  /// MIMO: row input_dof of M (kg), C (N s/m), K (N/m).
  Eigen::VectorXd m_row;
  Eigen::VectorXd c_row;
  Eigen::VectorXd k_row;
};

struct DobOptions {
  int order = 5;            ///< N
  int relative_degree = 4;  ///< r
  double tau_s = 0.002;     ///< 1/tau is Q's cut-off, rad/s.
  double fs_hz = 5000.0;    ///< Board sample rate.
  QPrototype prototype = QPrototype::kButterworth;
  SensorKind sensor = SensorKind::kDisplacement;
  ObserverForm form = ObserverForm::kSiso;
  Discretization discretization = Discretization::kTustin;
  int input_dof = 1;      ///< 0-based mass the force (and d) acts on.
  int output_dof = 1;     ///< 0-based mass of the sensor (SISO).
  double leak_hz = 0.05;  ///< Corner of the leaky integrators for velocity/acceleration sensors.
  double force_full_scale_n = 100.0;
  double sensor_full_scale = 0.0;    ///< 0: 0.05 m, 1 m/s or 50 m/s^2 by sensor kind.
  double output_full_scale_n = 0.0;  ///< 0: twice the force full scale.
};

struct DobDesign {
  DobOptions options;
  QFilter q;
  int plant_relative_degree = 0;    ///< of G_A (SISO) or of the row operator (MIMO), in s.
  std::vector<Zpk> continuous;      ///< Per input, the analog path (N per input unit).
  std::vector<ObserverPath> paths;  ///< Per input, the discrete sections (double).
  bool stable = false;
  std::string message;           ///< Why the filter was refused, when !stable.
  double max_pole_radius = 0.0;  ///< Discrete, over all paths.
  double valid_band_lo_hz = 0.0;
  double valid_band_hi_hz = 0.0;
  QuantizeResult fixed;  ///< Filled only when stable.
};

/// Validates options (InputError naming the problem, e.g. r below the plant's relative degree),
/// builds and discretizes the observer, checks stability (an unstable filter is a value: stable =
/// false with the reason) and quantizes it.
DobDesign DesignObserver(const NominalPlant& plant, const DobOptions& options);

/// Frequency (Hz) where |Q(j 2 pi f) - 1| first reaches `tolerance`.
double QBandEdgeHz(const QFilter& q, double tolerance);

/// "disp", "vel" or "acc".
const char* SensorName(SensorKind kind);
/// The kind SensorName names; InputError otherwise.
SensorKind ParseSensorKind(std::string_view name);

}  // namespace vibid::dob
