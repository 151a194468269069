// Closed-form references shared by the identification tests.
#pragma once

#include <cmath>
#include <complex>
#include <numbers>

#include <Eigen/Core>

#include "vibid/ident/spectral.hpp"

namespace vibid::ident::testing {

/// Receptance matrix entry (out, in) of the 2-DOF chain ground-k1-m1-k2-m2 with dampers c1, c2,
/// by the explicit 2x2 inverse of K - omega^2 M + j omega C.
inline std::complex<double> ChainReceptance(double m1, double m2, double k1, double k2, double c1,
                                            double c2, int out, int in, double omega) {
  using cd = std::complex<double>;
  const cd jw(0.0, omega);
  const cd d11 = k1 + k2 - omega * omega * m1 + jw * (c1 + c2);
  const cd d22 = k2 - omega * omega * m2 + jw * c2;
  const cd d12 = -k2 - jw * c2;
  const cd det = d11 * d22 - d12 * d12;
  if (out == 0 && in == 0) return d22 / det;
  if (out == 1 && in == 1) return d11 / det;
  return -d12 / det;
}

struct ChainModes {
  double omega[2];
  double ratio[2];  // a1/a2
};

/// Undamped modes of the chain from the characteristic quadratic; ratio from the first row.
inline ChainModes ChainModesOf(double m1, double m2, double k1, double k2) {
  const double a = m1 * m2;
  const double b = -((k1 + k2) * m2 + k2 * m1);
  const double c = k1 * k2;
  const double disc = std::sqrt(b * b - 4 * a * c);
  ChainModes r;
  const double l[2] = {(-b - disc) / (2 * a), (-b + disc) / (2 * a)};
  for (int i = 0; i < 2; ++i) {
    r.omega[i] = std::sqrt(l[i]);
    r.ratio[i] = k2 / (k1 + k2 - l[i] * m1);
  }
  return r;
}

/// A receptance FRF in closed form: `lines` uniform lines from df_hz, coherence 1, column j at
/// omega (rad/s) h(j, omega).
template <typename Receptance>
Frf ClosedFormFrf(double df_hz, Eigen::Index lines, int columns, Receptance h) {
  Frf frf;
  frf.quantity = Quantity::kDisplacement;
  frf.freq_hz = Eigen::VectorXd::LinSpaced(lines, df_hz, df_hz * static_cast<double>(lines));
  frf.h.resize(lines, columns);
  frf.coherence = Eigen::MatrixXd::Ones(lines, columns);
  for (Eigen::Index i = 0; i < lines; ++i) {
    const double w = 2.0 * std::numbers::pi * frf.freq_hz[i];
    for (int j = 0; j < columns; ++j) frf.h(i, j) = h(j, w);
  }
  return frf;
}

/// Receptance FRF of the chain, hammer on `in`, both masses as responses, at uniform lines.
inline Frf ChainFrf(double m1, double m2, double k1, double k2, double c1, double c2, int in,
                    double df_hz, Eigen::Index lines) {
  Frf frf = ClosedFormFrf(df_hz, lines, 2, [&](int out, double w) {
    return ChainReceptance(m1, m2, k1, k2, c1, c2, out, in, w);
  });
  frf.response_names = {"x1", "x2"};
  return frf;
}

}  // namespace vibid::ident::testing
