// What the ring-down tests build their modes from: a mode as an FRF would report it, with narrow
// intervals the checks may widen or withhold.
#pragma once

#include <Eigen/Core>
#include <numbers>

#include "vibid/ident/modes.hpp"

namespace vibid::ident::testing {

inline double Omega(double f_hz) { return 2.0 * std::numbers::pi * f_hz; }

// zeta's interval +-1 %, omega's +-1e-5 relative.
inline ModeEstimate Mode(double f_hz, double zeta, const Eigen::VectorXd& phi) {
  ModeEstimate m;
  m.omega_rad_s = Omega(f_hz);
  m.freq_hz = f_hz;
  m.zeta = zeta;
  m.shape = phi;
  m.zeta_ci95 = {0.99 * zeta, 1.01 * zeta};
  m.omega_ci95_rad_s = {(1.0 - 1e-5) * m.omega_rad_s, (1.0 + 1e-5) * m.omega_rad_s};
  return m;
}

}  // namespace vibid::ident::testing
