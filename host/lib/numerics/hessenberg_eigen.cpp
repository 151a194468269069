// Eigenvalues from the Hessenberg form by the Francis double-shift QR iteration restricted to the
// active block (the eigenvalues-only variant of the iteration: no transformation is applied
// outside the block still being reduced), and eigenvectors by inverse iteration on the Hessenberg
// form. Eigen's EigenSolver computes the full real Schur form, twice the work when the
// eigenvalues are all that is needed.
#include "vibid/numerics/hessenberg_eigen.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "vibid/common/error.hpp"

namespace vibid::numerics {
namespace {

using Complex = std::complex<double>;

// Iterations allowed per eigenvalue, and those after which an exceptional shift breaks a cycle
// (the Handbook's values).
constexpr int kMaxIterations = 30;
constexpr int kExceptionalEvery = 10;

// The eigenvalues of the upper Hessenberg matrix `h` (overwritten) into `out`; false when an
// eigenvalue did not converge within kMaxIterations.
bool HessenbergQr(Eigen::MatrixXd& h, Eigen::VectorXcd& out) {
  const int n = static_cast<int>(h.rows());
  out.resize(n);
  double norm = 0.0;  // scale for the deflation test where both diagonal entries vanish
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i <= std::min(j + 1, n - 1); ++i) norm += std::fabs(h(i, j));
  }
  double shift_sum = 0.0;  // exceptional shifts applied to the diagonal so far
  int its = 0;
  int nn = n - 1;  // last row of the active block
  while (nn >= 0) {
    // The active block [l, nn]: the last negligible subdiagonal entry bounds it.
    int l = nn;
    for (; l >= 1; --l) {
      double s = std::fabs(h(l - 1, l - 1)) + std::fabs(h(l, l));
      if (s == 0.0) s = norm;
      if (std::fabs(h(l, l - 1)) + s == s) {
        h(l, l - 1) = 0.0;
        break;
      }
    }
    double x = h(nn, nn);
    if (l == nn) {  // a 1×1 block: a real eigenvalue
      out(nn) = Complex(x + shift_sum, 0.0);
      --nn;
      its = 0;
      continue;
    }
    double y = h(nn - 1, nn - 1);
    double w = h(nn, nn - 1) * h(nn - 1, nn);
    if (l == nn - 1) {  // a 2×2 block: a real pair or a complex conjugate pair
      const double p = 0.5 * (y - x);
      const double q = p * p + w;
      const double root = std::sqrt(std::fabs(q));
      x += shift_sum;
      if (q >= 0.0) {
        const double z = p + std::copysign(root, p);
        out(nn - 1) = Complex(x + z, 0.0);
        out(nn) = Complex(z != 0.0 ? x - w / z : x + z, 0.0);
      } else {
        out(nn - 1) = Complex(x + p, root);
        out(nn) = Complex(x + p, -root);
      }
      nn -= 2;
      its = 0;
      continue;
    }
    if (its == kMaxIterations) return false;
    if (its > 0 && its % kExceptionalEvery == 0) {
      shift_sum += x;
      for (int i = 0; i <= nn; ++i) h(i, i) -= x;
      const double s = std::fabs(h(nn, nn - 1)) + std::fabs(h(nn - 1, nn - 2));
      x = y = 0.75 * s;
      w = -0.4375 * s * s;
    }
    ++its;
    // The double shift's first column (p, q, r), started at the lowest row m ≥ l where two
    // consecutive small subdiagonal entries let the bulge start without disturbing the rows
    // above.
    int m = nn - 2;
    double p = 0.0, q = 0.0, r = 0.0;
    for (;; --m) {
      const double z = h(m, m);
      const double rr = x - z;
      const double ss = y - z;
      p = (rr * ss - w) / h(m + 1, m) + h(m, m + 1);
      q = h(m + 1, m + 1) - z - rr - ss;
      r = h(m + 2, m + 1);
      const double s = std::fabs(p) + std::fabs(q) + std::fabs(r);
      if (!(s > 0.0)) return false;
      p /= s;
      q /= s;
      r /= s;
      if (m == l) break;
      const double u = std::fabs(h(m, m - 1)) * (std::fabs(q) + std::fabs(r));
      const double v =
          std::fabs(p) * (std::fabs(h(m - 1, m - 1)) + std::fabs(z) + std::fabs(h(m + 1, m + 1)));
      if (u + v == v) break;
    }
    for (int i = m + 2; i <= nn; ++i) {
      h(i, i - 2) = 0.0;
      if (i != m + 2) h(i, i - 3) = 0.0;
    }
    // Chase the bulge down the block with 3×3 (last: 2×2) reflectors.
    for (int k = m; k <= nn - 1; ++k) {
      const bool last = k == nn - 1;
      double scale = 0.0;
      if (k != m) {
        p = h(k, k - 1);
        q = h(k + 1, k - 1);
        r = last ? 0.0 : h(k + 2, k - 1);
        scale = std::fabs(p) + std::fabs(q) + std::fabs(r);
        if (scale == 0.0) continue;
        p /= scale;
        q /= scale;
        r /= scale;
      }
      const double s = std::copysign(std::sqrt(p * p + q * q + r * r), p);
      if (k == m) {
        if (l != m) h(k, k - 1) = -h(k, k - 1);
      } else {
        h(k, k - 1) = -s * scale;
      }
      p += s;
      const double rx = p / s;
      const double ry = q / s;
      const double rz = r / s;
      q /= p;
      r /= p;
      for (int j = k; j <= nn; ++j) {  // rows k … k+2, within the block
        double t = h(k, j) + q * h(k + 1, j);
        if (!last) {
          t += r * h(k + 2, j);
          h(k + 2, j) -= t * rz;
        }
        h(k + 1, j) -= t * ry;
        h(k, j) -= t * rx;
      }
      const int bottom = std::min(nn, k + 3);
      for (int i = l; i <= bottom; ++i) {  // columns k … k+2, within the block
        double t = rx * h(i, k) + ry * h(i, k + 1);
        if (!last) {
          t += rz * h(i, k + 2);
          h(i, k + 2) -= t * r;
        }
        h(i, k + 1) -= t * q;
        h(i, k) -= t;
      }
    }
  }
  return true;
}

}  // namespace

HessenbergEigen::HessenbergEigen(const Eigen::MatrixXd& a) {
  Require(a.rows() == a.cols(), "eigenvalues: the matrix must be square");
  Require(a.allFinite(), "eigenvalues: the matrix holds a non-finite value");
  if (a.rows() == 0) {
    ok_ = true;
    return;
  }
  hessenberg_.compute(a);
  h_ = hessenberg_.matrixH();
  Eigen::MatrixXd work = h_;
  ok_ = HessenbergQr(work, eigenvalues_) && eigenvalues_.allFinite();
  if (!ok_) {
    // The Handbook's iteration limit is tighter than Eigen's; its Schur iteration gets a second
    // chance before the matrix is given up.
    const Eigen::EigenSolver<Eigen::MatrixXd> fallback(h_, false);
    ok_ = fallback.info() == Eigen::Success;
    eigenvalues_ = ok_ ? fallback.eigenvalues() : Eigen::VectorXcd();
  }
}

Eigen::VectorXcd HessenbergEigen::Eigenvector(Complex lambda) const {
  const Eigen::Index n = h_.rows();
  if (n == 0) return Eigen::VectorXcd();
  // LU of H − σI with partial pivoting: a Hessenberg matrix has one entry below the diagonal per
  // column, so each step pivots between two rows and eliminates one.
  Eigen::MatrixXcd u = h_.cast<Complex>();
  const Complex shift = lambda * (1.0 + 1e-10);
  u.diagonal().array() -= shift;
  std::vector<Complex> multiplier(static_cast<std::size_t>(n));
  std::vector<bool> swapped(static_cast<std::size_t>(n), false);
  const double tiny = std::numeric_limits<double>::epsilon() * std::max(h_.norm(), 1e-300);
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    if (std::abs(u(k + 1, k)) > std::abs(u(k, k))) {
      u.row(k).tail(n - k).swap(u.row(k + 1).tail(n - k));
      swapped[static_cast<std::size_t>(k)] = true;
    }
    if (u(k, k) == Complex(0.0, 0.0)) u(k, k) = tiny;
    const Complex f = u(k + 1, k) / u(k, k);
    multiplier[static_cast<std::size_t>(k)] = f;
    u.row(k + 1).tail(n - k - 1) -= f * u.row(k).tail(n - k - 1);
    u(k + 1, k) = 0.0;
  }
  if (u(n - 1, n - 1) == Complex(0.0, 0.0)) u(n - 1, n - 1) = tiny;
  // The first step solves U v = (1, …, 1) alone: its start vector is then P L (1, …, 1), which
  // has a component along the wanted eigenvector even when (1, …, 1) is another eigenvector
  // (Wilkinson's choice, as LAPACK's dlaein). Two full steps follow.
  Eigen::VectorXcd v = Eigen::VectorXcd::Ones(n);
  for (int step = 0; step < 3; ++step) {
    for (Eigen::Index k = 0; step > 0 && k + 1 < n; ++k) {
      if (swapped[static_cast<std::size_t>(k)]) std::swap(v(k), v(k + 1));
      v(k + 1) -= multiplier[static_cast<std::size_t>(k)] * v(k);
    }
    u.triangularView<Eigen::Upper>().solveInPlace(v);
    v.normalize();
  }
  // Back from the Hessenberg basis: the real Householder product on each part.
  const Eigen::VectorXd re = hessenberg_.matrixQ() * v.real();
  const Eigen::VectorXd im = hessenberg_.matrixQ() * v.imag();
  return Eigen::VectorXcd(re.cast<Complex>() + Complex(0.0, 1.0) * im.cast<Complex>());
}

}  // namespace vibid::numerics
