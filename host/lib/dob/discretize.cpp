#include "vibid/dob/discretize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include "vibid/common/error.hpp"

namespace vibid::dob {
namespace {

constexpr double kImagTol = 1e-9;

bool IsReal(const Complex& c) {
  return std::abs(c.imag()) <= kImagTol * std::max(1.0, std::abs(c));
}

// A conjugate pair or one or two real roots: the roots of one real factor of degree <= 2.
using Group = std::vector<Complex>;

// Splits roots into conjugate pairs, real pairs (neighbours in value) and at most one lone real.
std::vector<Group> GroupRoots(const std::vector<Complex>& roots) {
  std::vector<Group> groups;
  std::vector<double> reals;
  for (const Complex& r : roots) {
    if (IsReal(r)) {
      reals.push_back(r.real());
    } else if (r.imag() > 0.0) {
      groups.push_back({r, std::conj(r)});
    }
  }
  // Pair reals nearest the unit circle together; a lone one is the smallest in magnitude.
  std::sort(reals.begin(), reals.end(),
            [](double a, double b) { return std::abs(a) > std::abs(b); });
  std::size_t i = 0;
  for (; i + 1 < reals.size(); i += 2) groups.push_back({reals[i], reals[i + 1]});
  if (i < reals.size()) groups.push_back({reals[i]});
  return groups;
}

double Radius(const Group& g) {
  double r = 0.0;
  for (const Complex& c : g) r = std::max(r, std::abs(c));
  return r;
}

double Distance(const Group& poles, const Group& zeros) {
  double d = std::numeric_limits<double>::infinity();
  for (const Complex& p : poles) {
    for (const Complex& z : zeros) d = std::min(d, std::abs(p - z));
  }
  return d;
}

// Coefficients of prod(z - r) for up to two roots, as 1 + c1 z^-1 + c2 z^-2 aligned to `degree`.
void Factor(const Group& roots, int degree, double& c0, double& c1, double& c2) {
  // The polynomial in z of degree len(roots), shifted down by (degree - len(roots)) delays.
  double p[3] = {0.0, 0.0, 0.0};
  if (roots.empty()) {
    p[0] = 1.0;
  } else if (roots.size() == 1) {
    p[0] = 1.0;
    p[1] = -roots[0].real();
  } else {
    p[0] = 1.0;
    p[1] = -(roots[0] + roots[1]).real();
    p[2] = (roots[0] * roots[1]).real();
  }
  const int shift = degree - static_cast<int>(roots.size());
  double out[3] = {0.0, 0.0, 0.0};
  for (int k = 0; k + shift < 3 && k < 3; ++k) out[k + shift] = p[k];
  c0 = out[0];
  c1 = out[1];
  c2 = out[2];
}

struct RealBlock {
  Eigen::MatrixXd a, b, c, d;
};

// Block of n(s)/d(s), deg n <= deg d <= 2, both given by roots, in a modal form whose entries
// stay of the order of the poles (a companion form would carry omega^2 and lose accuracy in the
// matrix exponential): a complex pair sigma +- j omega as [[sigma, omega], [-omega, sigma]], two
// real poles as a chain [[p1, 0], [1, p2]].
RealBlock Block(const Group& poles, const Group& zeros, double gain) {
  const Eigen::VectorXd den = numerics::PolynomialFromRoots(poles);
  const Eigen::VectorXd num = numerics::PolynomialFromRoots(zeros) * gain;
  const Eigen::Index n = den.size() - 1;
  Eigen::VectorXd padded = Eigen::VectorXd::Zero(n + 1);
  padded.tail(num.size()) = num;
  RealBlock blk;
  blk.d = Eigen::MatrixXd::Constant(1, 1, padded[0]);
  blk.a = Eigen::MatrixXd::Zero(n, n);
  blk.b = Eigen::MatrixXd::Zero(n, 1);
  blk.c = Eigen::MatrixXd::Zero(1, n);
  // Strictly proper remainder r(s) = n(s) - n_n d(s), degree < n.
  const Eigen::VectorXd rem = padded - padded[0] * den;
  if (n == 1) {
    blk.a(0, 0) = poles[0].real();
    blk.b(0, 0) = 1.0;
    blk.c(0, 0) = rem[1];
    return blk;
  }
  const double r1 = rem[1];
  const double r0 = rem[2];
  if (!IsReal(poles[0])) {
    const double sigma = poles[0].real();
    const double omega = std::abs(poles[0].imag());
    blk.a << sigma, omega, -omega, sigma;
    blk.b << 0.0, 1.0;
    // C (sI - A)^-1 B = (c1 omega + c2 (s - sigma)) / ((s - sigma)^2 + omega^2)
    blk.c << (r0 + r1 * sigma) / omega, r1;
  } else {
    const double p1 = poles[0].real();
    const double p2 = poles[1].real();
    blk.a << p1, 0.0, 1.0, p2;
    blk.b << 1.0, 0.0;
    // C (sI - A)^-1 B = (c1 (s - p2) + c2) / ((s - p1)(s - p2))
    blk.c << r1, r0 + r1 * p2;
  }
  return blk;
}

RealBlock Series(const RealBlock& first, const RealBlock& second) {
  const Eigen::Index n1 = first.a.rows();
  const Eigen::Index n2 = second.a.rows();
  RealBlock s;
  s.a = Eigen::MatrixXd::Zero(n1 + n2, n1 + n2);
  s.a.topLeftCorner(n1, n1) = first.a;
  s.a.bottomRightCorner(n2, n2) = second.a;
  s.a.bottomLeftCorner(n2, n1) = second.b * first.c;
  s.b.resize(n1 + n2, 1);
  s.b << first.b, second.b * first.d;
  s.c.resize(1, n1 + n2);
  s.c << second.d * first.c, second.c;
  s.d = second.d * first.d;
  return s;
}

}  // namespace

Complex EvaluateZpk(const Zpk& zpk, Complex x) {
  Complex h = zpk.gain;
  for (const Complex& z : zpk.zeros) h *= x - z;
  for (const Complex& p : zpk.poles) h /= x - p;
  return h;
}

Zpk TustinZpk(const Zpk& analog, double fs_hz, double omega_warp_rad_s) {
  Require(fs_hz > 0.0, "sample rate must be > 0");
  Require(analog.zeros.size() <= analog.poles.size(),
          "Tustin needs a proper system (zeros <= poles)");
  const double k = omega_warp_rad_s > 0.0
                       ? omega_warp_rad_s / std::tan(omega_warp_rad_s / (2.0 * fs_hz))
                       : 2.0 * fs_hz;
  Require(omega_warp_rad_s < std::numbers::pi * fs_hz,
          "pre-warping frequency must lie below the Nyquist frequency");
  Zpk d;
  Complex gain = analog.gain;
  for (const Complex& z : analog.zeros) {
    d.zeros.push_back((k + z) / (k - z));
    gain *= (k - z);
  }
  for (const Complex& p : analog.poles) {
    d.poles.push_back((k + p) / (k - p));
    gain /= (k - p);
  }
  while (d.zeros.size() < d.poles.size()) d.zeros.push_back(-1.0);
  d.gain = gain.real();
  return d;
}

namespace {

// A real state space as a cascade of first/second-order blocks (well conditioned even when the
// poles span decades), each block taking zeros from the remaining groups.
// Each block is normalised to unit gain at its own pole frequency; the overall gain is applied
// to the output only. A large gain inside the chain would enter A through the couplings between
// blocks and ruin the matrix exponential.
RealBlock BlockCascade(const Zpk& analog) {
  const auto pole_groups = GroupRoots(analog.poles);
  auto zero_groups = GroupRoots(analog.zeros);
  RealBlock sys;
  bool first = true;
  double output_gain = analog.gain;
  std::size_t zi = 0;
  for (const Group& pg : pole_groups) {
    Group zeros;
    while (zi < zero_groups.size() && zeros.size() + zero_groups[zi].size() <= pg.size()) {
      for (const Complex& z : zero_groups[zi]) zeros.push_back(z);
      ++zi;
      if (zeros.size() == pg.size()) break;
    }
    const Complex probe(0.0, std::max(1e-9, Radius(pg)));
    const double scale =
        std::abs(numerics::EvaluatePolynomial(numerics::PolynomialFromRoots(pg), probe) /
                 numerics::EvaluatePolynomial(numerics::PolynomialFromRoots(zeros), probe));
    output_gain /= scale;
    const RealBlock blk = Block(pg, zeros, scale);
    sys = first ? blk : Series(sys, blk);
    first = false;
  }
  sys.c *= output_gain;
  sys.d *= output_gain;
  Require(zi == zero_groups.size(), "zero-order hold: could not place every zero");
  return sys;
}

// Zeros of the discrete SISO system (ad, bd, sys.c, sys.d). With a feedthrough they are
// eig(Ad - Bd C / D). Without one, the zero dynamics: inputs that keep y = 0 must keep x in ker C,
// which takes u = -(C Bd)^-1 C Ad x, so the zeros are the eigenvalues of P Ad
// (P = I - Bd (C Bd)^-1 C) on ker C. (A ZOH-sampled strictly proper system has C Bd != 0.)
std::vector<Complex> DiscreteZeros(const RealBlock& sys, const Eigen::MatrixXd& ad,
                                   const Eigen::MatrixXd& bd) {
  const Eigen::Index n = sys.a.rows();
  const double dd = sys.d(0, 0);
  const double cb = (sys.c * bd)(0, 0);
  Eigen::MatrixXd zero_dynamics;
  if (std::abs(dd) > 1e-12 * std::max(1.0, std::abs(cb))) {
    zero_dynamics = ad - bd * sys.c / dd;
  } else {
    Require(std::abs(cb) > 0.0, "zero-order hold: the sampled system has relative degree above 1");
    const Eigen::MatrixXd proj = Eigen::MatrixXd::Identity(n, n) - bd * sys.c / cb;
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(sys.c.transpose());
    const Eigen::MatrixXd q = qr.householderQ();
    const Eigen::MatrixXd kernel = q.rightCols(n - 1);
    zero_dynamics = kernel.transpose() * proj * ad * kernel;
  }
  std::vector<Complex> zeros;
  if (zero_dynamics.size() > 0) {
    const Eigen::EigenSolver<Eigen::MatrixXd> zs(zero_dynamics, false);
    for (Eigen::Index i = 0; i < zs.eigenvalues().size(); ++i) zeros.push_back(zs.eigenvalues()[i]);
  }
  // Clean conjugate symmetry: tiny imaginary parts of real zeros are rounding.
  for (Complex& z : zeros) {
    if (IsReal(z)) z = z.real();
  }
  return zeros;
}

}  // namespace

Zpk ZeroOrderHoldZpk(const Zpk& analog, double fs_hz) {
  Require(fs_hz > 0.0, "sample rate must be > 0");
  Require(analog.zeros.size() <= analog.poles.size(), "zero-order hold needs a proper system");
  const double t_s = 1.0 / fs_hz;
  const RealBlock sys = BlockCascade(analog);
  const Eigen::Index n = sys.a.rows();
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(n + 1, n + 1);
  aug.topLeftCorner(n, n) = sys.a * t_s;
  aug.topRightCorner(n, 1) = sys.b * t_s;
  const Eigen::MatrixXd e = aug.exp();
  const Eigen::MatrixXd ad = e.topLeftCorner(n, n);
  const Eigen::MatrixXd bd = e.topRightCorner(n, 1);

  Zpk d;
  for (const Complex& p : analog.poles) d.poles.push_back(std::exp(p * t_s));
  d.zeros = DiscreteZeros(sys, ad, bd);
  // Gain from the state space at z0 = 1 (DC), or another real point if a pole sits there.
  Complex z0 = 1.0;
  for (const Complex& p : d.poles) {
    if (std::abs(p - z0) < 1e-6) z0 = -1.0;
  }
  const Eigen::MatrixXcd resolvent =
      (z0 * Eigen::MatrixXcd::Identity(n, n) - ad.cast<Complex>()).inverse();
  const Complex h = (sys.c.cast<Complex>() * resolvent * bd.cast<Complex>())(0, 0) + sys.d(0, 0);
  d.gain = 1.0;
  d.gain = (h / EvaluateZpk(d, z0)).real();
  return d;
}

std::vector<SosSection> ZpkToSos(const Zpk& digital) {
  Require(digital.zeros.size() <= digital.poles.size(), "more zeros than poles");
  const auto pole_groups = GroupRoots(digital.poles);
  const auto zero_groups = GroupRoots(digital.zeros);
  std::vector<Group> pairs;    // two-zero groups
  std::vector<Group> singles;  // lone real zeros
  for (const Group& g : zero_groups) (g.size() == 2 ? pairs : singles).push_back(g);

  // Assign zeros to pole groups, nearest first, starting with the poles closest to the unit circle.
  std::vector<std::size_t> order(pole_groups.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return Radius(pole_groups[a]) > Radius(pole_groups[b]);
  });
  std::vector<Group> assigned(pole_groups.size());
  // A lone pole takes a lone zero if there is one.
  for (std::size_t i : order) {
    if (pole_groups[i].size() == 1 && !singles.empty()) {
      assigned[i] = singles.back();
      singles.pop_back();
    }
  }
  for (std::size_t i : order) {
    if (pole_groups[i].size() != 2 || pairs.empty()) continue;
    std::size_t best = 0;
    for (std::size_t j = 1; j < pairs.size(); ++j) {
      if (Distance(pole_groups[i], pairs[j]) < Distance(pole_groups[i], pairs[best])) best = j;
    }
    assigned[i] = pairs[best];
    pairs.erase(pairs.begin() + static_cast<std::ptrdiff_t>(best));
  }
  for (std::size_t i : order) {
    if (pole_groups[i].size() == 2 && assigned[i].empty() && !singles.empty()) {
      assigned[i] = singles.back();
      singles.pop_back();
    }
  }
  Require(pairs.empty() && singles.empty(), "could not pair every zero with a pole section");

  // Output order: increasing pole radius.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return Radius(pole_groups[a]) < Radius(pole_groups[b]);
  });
  std::vector<SosSection> sos;
  for (std::size_t i : order) {
    SosSection s;
    const int degree = static_cast<int>(pole_groups[i].size());
    double a0 = 0.0;
    Factor(pole_groups[i], degree, a0, s.a1, s.a2);
    Factor(assigned[i], degree, s.b0, s.b1, s.b2);
    sos.push_back(s);
  }
  if (sos.empty()) sos.push_back(SosSection{.b0 = 1.0});
  sos.front().b0 *= digital.gain;
  sos.front().b1 *= digital.gain;
  sos.front().b2 *= digital.gain;
  return sos;
}

Complex EvaluateSos(const std::vector<SosSection>& sos, Complex z) {
  const Complex zi = 1.0 / z;
  Complex h = 1.0;
  for (const SosSection& s : sos) {
    h *= (s.b0 + zi * (s.b1 + zi * s.b2)) / (1.0 + zi * (s.a1 + zi * s.a2));
  }
  return h;
}

Eigen::VectorXd FilterSos(const std::vector<SosSection>& sos,
                          const Eigen::Ref<const Eigen::VectorXd>& x, SosStart start) {
  Eigen::VectorXd y = x;
  // Input level each section settles on; only read for the steady start, where a section with a
  // pole at z = 1 would give an infinite DC gain.
  double level = start == SosStart::kSteadyState && x.size() > 0 ? x[0] : 0.0;
  for (const SosSection& s : sos) {
    double x1 = 0.0, x2 = 0.0, y1 = 0.0, y2 = 0.0;
    if (start == SosStart::kSteadyState) {
      const double gain = (s.b0 + s.b1 + s.b2) / (1.0 + s.a1 + s.a2);
      x1 = x2 = level;
      y1 = y2 = gain * level;
      level *= gain;
    }
    for (Eigen::Index n = 0; n < y.size(); ++n) {
      const double xn = y[n];
      const double yn = s.b0 * xn + s.b1 * x1 + s.b2 * x2 - s.a1 * y1 - s.a2 * y2;
      x2 = x1;
      x1 = xn;
      y2 = y1;
      y1 = yn;
      y[n] = yn;
    }
  }
  return y;
}

double MaxPoleRadius(const std::vector<SosSection>& sos) {
  double r = 0.0;
  for (const SosSection& s : sos) {
    Eigen::Vector3d den(1.0, s.a1, s.a2);
    for (const Complex& p : numerics::PolynomialRoots(den)) r = std::max(r, std::abs(p));
  }
  return r;
}

}  // namespace vibid::dob
