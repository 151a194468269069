// The observer design as the front ends ask for it (`vibid dob design`, the bench's calibration
// view, the Python package): options by the CLI's words and 1-based masses, checked against the
// model, and a design that is not stable refused with the design's reason.
#pragma once

#include <string>

#include "vibid/dob/design.hpp"
#include "vibid/model/model.hpp"

namespace vibid::workflow {

struct ObserverDesignRequest {
  int order = 5;                          ///< N of Q.
  int relative_degree = 4;                ///< r of Q.
  double tau_s = 0.002;                   ///< Q's time constant (cut-off 1/tau rad/s).
  double fs_hz = 5000.0;                  ///< The board's sample rate.
  int input_dof = 2;                      ///< Mass the force and the disturbance act on, from 1.
  int output_dof = 2;                     ///< Mass whose sensor feeds the SISO form, from 1.
  std::string sensor = "disp";            ///< disp, vel, acc.
  std::string form = "siso";              ///< siso, mimo.
  std::string discretize = "tustin";      ///< tustin (pre-warped at 1/tau), zoh.
  std::string prototype = "butterworth";  ///< butterworth, binomial.
  double leak_hz = 0.05;                  ///< Corner of the leaky integrators for vel/acc sensors.
  double force_fs_n = 100.0;              ///< Force full scale, N.
  double sensor_fs = 0.0;                 ///< Sensor full scale, SI; 0: 0.05 m, 1 m/s or 50 m/s^2.
  double output_fs_n = 0.0;  ///< Full scale of d_hat, N; 0: twice the force full scale.
};

/// The library's options for `request` on `model`; InputError naming the option otherwise.
dob::DobOptions ObserverOptions(const model::Model& model, const ObserverDesignRequest& request);

/// Designs, discretizes and quantizes the observer; NumericalError when it is not stable.
dob::DobDesign DesignObserverFor(const model::Model& model, const ObserverDesignRequest& request);

/// The lines `vibid dob design -o FILE` prints: Q, the plant's relative degree and paths,
/// stability, the valid band, the fixed-point noise and checksum.
std::string DesignSummary(const dob::DobDesign& design);

}  // namespace vibid::workflow
