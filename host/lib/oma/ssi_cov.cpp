// SSI-cov: block Hankel matrix of output covariances, its SVD, the state matrix by shift
// invariance of the observability matrix, poles per order, stability, clustering, and the
// intervals from the Hankel matrix's covariance over data blocks.
#include "vibid/oma/ssi_cov.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "vibid/common/error.hpp"
#include "vibid/numerics/distributions.hpp"
#include "vibid/numerics/hessenberg_eigen.hpp"
#include "vibid/numerics/leading_eigenvectors.hpp"

namespace vibid::oma {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// A sample's pole is its mode's when its relative frequency distance plus 1 − MAC is below this.
constexpr double kMatchReach = 0.1;

struct RawPole {
  double omega_rad_s;
  double zeta;
  Eigen::VectorXcd shape;
};

// H(a, b) = R_{a+b+1}, a, b = 0 … i−1: (i l) × (i l), from covariances stacked as
// OutputCovariances returns them (lags 0 … 2i−1).
Eigen::MatrixXd Hankel(const Eigen::MatrixXd& r, int l, int i) {
  Eigen::MatrixXd h(i * l, i * l);
  for (int a = 0; a < i; ++a) {
    for (int b = 0; b < i; ++b) h.block(a * l, b * l, l, l) = r.middleCols((a + b + 1) * l, l);
  }
  return h;
}

struct ModePole {
  double omega_rad_s;
  double zeta;
};

// A discrete eigenvalue of A as a vibration pole: one of each complex pair (Im λ > 0), within the
// band and the damping limit; real poles are not vibration modes.
std::optional<ModePole> VibrationPole(std::complex<double> lambda, double fs_hz, double max_damping,
                                      double omega_max) {
  if (!(lambda.imag() > 1e-12 * std::abs(lambda))) return std::nullopt;
  const std::complex<double> mu = std::log(lambda) * fs_hz;
  const double omega = std::abs(mu);
  const double zeta = -mu.real() / omega;
  if (!(zeta > 0.0 && zeta < max_damping && omega <= omega_max)) return std::nullopt;
  return ModePole{omega, zeta};
}

void SortByFrequency(std::vector<RawPole>& poles) {
  std::sort(poles.begin(), poles.end(),
            [](const RawPole& x, const RawPole& y) { return x.omega_rad_s < y.omega_rad_s; });
}

// Poles of the order-n model from the Hankel matrix's left singular vectors and values: the
// observability matrix O = U_n S_n^½, A from O's shift invariance (least squares), C its first
// block row. One pole of each complex pair (Im λ > 0); real poles are not vibration modes.
std::vector<RawPole> PolesAtOrder(const Eigen::MatrixXd& u, const Eigen::VectorXd& s, int order,
                                  int l, double fs_hz, double max_damping, double omega_max) {
  const Eigen::Index rows = u.rows();
  const Eigen::MatrixXd o = u.leftCols(order) * s.head(order).cwiseSqrt().asDiagonal();
  const Eigen::MatrixXd a = o.topRows(rows - l).colPivHouseholderQr().solve(o.bottomRows(rows - l));
  const Eigen::MatrixXd c = o.topRows(l);
  Eigen::EigenSolver<Eigen::MatrixXd> eig(a, true);
  std::vector<RawPole> poles;
  if (eig.info() != Eigen::Success) return poles;
  for (Eigen::Index k = 0; k < order; ++k) {
    const std::complex<double> lambda = eig.eigenvalues()(k);
    const std::optional<ModePole> p = VibrationPole(lambda, fs_hz, max_damping, omega_max);
    if (!p) continue;
    const double omega = p->omega_rad_s;
    const double zeta = p->zeta;
    poles.push_back({omega, zeta, c * eig.eigenvectors().col(k)});
  }
  SortByFrequency(poles);
  return poles;
}

// The state and output matrices of the interval samples, for every order up to the largest a
// mode needs, from an orthonormal basis U of the leading left singular vectors (columns in
// descending order of their singular values). Only the span of U's first n columns matters for
// the order-n poles and shapes, so O = U_n stands for U_n S_n^½ (a similarity of A, C times the
// eigenvectors unchanged). Its columns are orthonormal, so O↑ᵀO↑ = I − WᵀW, W the last block row
// of U_n (l × n), and the least-squares A = (O↑ᵀO↑)⁻¹ O↑ᵀO↓ needs only the l × l inverse of
// I − W Wᵀ (Woodbury) beside O↑ᵀO↓, whose order-n matrix is the leading block of the largest
// order's: one product per sample in place of a QR factorisation per order.
class SampleStateMatrices {
 public:
  SampleStateMatrices(const Eigen::MatrixXd& u, int max_order, int l) : u_(u), l_(l) {
    const Eigen::Index rows = u.rows();
    shifted_.noalias() =
        u.topLeftCorner(rows - l, max_order).transpose() * u.block(l, 0, rows - l, max_order);
  }

  Eigen::MatrixXd A(int order) const {
    const Eigen::Index rows = u_.rows();
    const Eigen::MatrixXd w = u_.block(rows - l_, 0, l_, order);
    const Eigen::MatrixXd m = shifted_.topLeftCorner(order, order);
    const Eigen::MatrixXd g =
        Eigen::MatrixXd::Identity(l_, l_) - w * w.transpose();  // I − W Wᵀ, l × l
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(g);
    // Where the last block row nearly spans a direction of U_n, O↑ is nearly rank deficient and
    // the normal equations would lose digits: the QR solve instead.
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > kMinRcond)) {
      const Eigen::MatrixXd o = u_.leftCols(order);
      return o.topRows(rows - l_).householderQr().solve(o.bottomRows(rows - l_));
    }
    return m + w.transpose() * ldlt.solve(w * m);
  }
  Eigen::MatrixXd C(int order) const { return u_.topLeftCorner(l_, order); }

 private:
  static constexpr double kMinRcond = 1e-3;
  const Eigen::MatrixXd& u_;
  int l_;
  Eigen::MatrixXd shifted_;  // O↑ᵀO↓ of the largest order
};

// A pole of an interval sample near a mode: its frequency, damping and eigenvalue; its shape is
// computed only when the match needs it.
struct SamplePole {
  double omega_rad_s;
  double zeta;
  std::complex<double> lambda;
  double offset;  // relative frequency distance to the mode
};

// The pole of an interval sample taken for a mode.
struct SampleMatch {
  double omega_rad_s;
  double zeta;
  Eigen::VectorXcd shape;
};

// One interval sample's match of the modes of one order: the eigenvalues of A alone (from its
// Hessenberg form, without the Schur form), and the pole nearest each mode in frequency and shape
// (relative frequency distance plus 1 − MAC, below `reach`). A pole's distance is at least its
// frequency offset, so the poles are tried in ascending offset and the search stops once the
// offset alone exceeds the best distance: the shape (an eigenvector by inverse iteration on the
// Hessenberg form, the same vector as the full eigensolver's up to its scale, which MAC and the
// scaling to an entry ignore) is computed only for the poles that could still win — usually the
// mode's own pole alone. `matched[m]` gets the pole of each mode m in `modes` (none if no pole is
// within reach).
void MatchModesAtOrder(const SampleStateMatrices& states, int order, double fs_hz,
                       double max_damping, double omega_max, const std::vector<std::size_t>& modes,
                       const std::vector<double>& targets_rad_s,
                       const std::vector<Eigen::VectorXcd>& reference_shapes, double reach,
                       std::vector<std::optional<SampleMatch>>& matched) {
  const Eigen::MatrixXd a = states.A(order);
  if (!a.allFinite()) return;  // a degenerate sample: no pole, as a failed eigensolver
  const numerics::HessenbergEigen eig(a);
  if (!eig.ok()) return;
  const Eigen::MatrixXd c = states.C(order);
  std::vector<std::pair<std::complex<double>, Eigen::VectorXcd>> shapes;  // computed so far
  auto shape_of = [&](std::complex<double> lambda) -> const Eigen::VectorXcd& {
    for (const auto& [l, v] : shapes) {
      if (l == lambda) return v;
    }
    shapes.emplace_back(lambda, c * eig.Eigenvector(lambda));
    return shapes.back().second;
  };
  std::vector<SamplePole> poles;
  for (Eigen::Index k = 0; k < order; ++k) {
    const std::complex<double> lambda = eig.eigenvalues()(k);
    const std::optional<ModePole> p = VibrationPole(lambda, fs_hz, max_damping, omega_max);
    if (p) poles.push_back({p->omega_rad_s, p->zeta, lambda, 0.0});
  }
  for (std::size_t i = 0; i < modes.size(); ++i) {
    const double target = targets_rad_s[i];
    std::vector<SamplePole> near;
    for (SamplePole p : poles) {
      p.offset = std::fabs(p.omega_rad_s - target) / target;
      if (p.offset < reach) near.push_back(p);
    }
    std::sort(near.begin(), near.end(), [](const SamplePole& x, const SamplePole& y) {
      return x.offset < y.offset || (x.offset == y.offset && x.omega_rad_s < y.omega_rad_s);
    });
    const SamplePole* best = nullptr;
    double best_d = reach;  // beyond this the pole is another mode or noise
    for (const SamplePole& p : near) {
      if (p.offset > best_d) break;  // its distance is at least its offset
      const double dist = p.offset + 1.0 - Mac(shape_of(p.lambda), reference_shapes[i]);
      // Ties go to the lower frequency, as a scan in ascending frequency would take them.
      if (dist < best_d ||
          (best != nullptr && dist == best_d && p.omega_rad_s < best->omega_rad_s)) {
        best_d = dist;
        best = &p;
      }
    }
    if (best != nullptr) {
      matched[modes[i]] = SampleMatch{best->omega_rad_s, best->zeta, shape_of(best->lambda)};
    }
  }
}

double Mpc(const Eigen::VectorXcd& phi) {
  // Modal phase collinearity from the 2×2 covariance of the real and imaginary parts.
  const Eigen::VectorXd re = phi.real();
  const Eigen::VectorXd im = phi.imag();
  const double sxx = re.squaredNorm();
  const double syy = im.squaredNorm();
  const double sxy = re.dot(im);
  const double denom = (sxx + syy) * (sxx + syy);
  return denom > 0.0 ? ((sxx - syy) * (sxx - syy) + 4.0 * sxy * sxy) / denom : 0.0;
}

// The shape scaled so that entry `ref` is 1, real part kept (a lightly damped mode's shape is
// nearly real after this rotation).
Eigen::VectorXd RealShape(const Eigen::VectorXcd& phi, Eigen::Index ref) {
  return (phi / phi(ref)).real();
}

struct UnionFind {
  std::vector<std::size_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t Find(std::size_t x) { return parent[x] == x ? x : parent[x] = Find(parent[x]); }
  void Join(std::size_t a, std::size_t b) { parent[Find(a)] = Find(b); }
};

struct Setup {
  int decimation = 1;
  double fs_hz = 0.0;
  double fmax_hz = 0.0;
  int block_rows = 0;
  int order_max = 0;
};

Setup Plan(const SsiCovOptions& o, int channels) {
  Setup s;
  s.fmax_hz = o.fmax_hz > 0.0 ? o.fmax_hz : o.fs_hz / 2.5;
  s.decimation = std::max(1, static_cast<int>(std::floor(o.fs_hz / (2.5 * s.fmax_hz))));
  s.fs_hz = o.fs_hz / s.decimation;
  const double fmin_hz = o.fmin_hz > 0.0 ? o.fmin_hz : s.fmax_hz / 10.0;
  if (o.block_rows > 0) {
    s.block_rows = o.block_rows;
  } else {
    // One period of the lowest mode of interest in the lags (2i of them), enough rows for the
    // orders.
    s.block_rows = static_cast<int>(std::ceil(s.fs_hz / fmin_hz));
    if (o.order_max > 0) s.block_rows = std::max(s.block_rows, o.order_max / channels + 2);
    s.block_rows = std::clamp(s.block_rows, 3, 100);
  }
  const int capacity = (s.block_rows - 1) * channels;
  s.order_max = o.order_max > 0 ? o.order_max : std::min(40, capacity);
  s.order_max -= s.order_max % 2;
  Require(s.order_max >= 2,
          "ssi-cov: the Hankel matrix is too small for a model of order 2 "
          "(raise block_rows)");
  Require(s.order_max <= capacity, "ssi-cov: order_max " + std::to_string(s.order_max) +
                                       " needs block_rows of at least " +
                                       std::to_string(s.order_max / channels + 2));
  return s;
}

}  // namespace

void SsiCovOptions::Validate() const {
  Require(std::isfinite(fs_hz) && fs_hz > 0.0, "ssi-cov: fs_hz must be positive");
  Require(std::isfinite(fmax_hz) && fmax_hz >= 0.0 && fmax_hz <= fs_hz / 2.0,
          "ssi-cov: fmax_hz must lie in [0, fs/2] (0: fs/2.5)");
  Require(std::isfinite(fmin_hz) && fmin_hz >= 0.0 && (fmax_hz == 0.0 || fmin_hz < fmax_hz),
          "ssi-cov: fmin_hz must be at least 0 and below fmax_hz");
  Require(block_rows == 0 || (block_rows >= 3 && block_rows <= 400),
          "ssi-cov: block_rows must be 0 (automatic) or 3 to 400");
  Require(order_max == 0 || (order_max >= 2 && order_max <= 200),
          "ssi-cov: order_max must be 0 (automatic) or 2 to 200");
  Require(stable_freq_tol > 0.0 && stable_freq_tol < 1.0 && stable_damping_tol > 0.0 &&
              stable_mac_tol > 0.0 && stable_mac_tol < 1.0,
          "ssi-cov: the stability tolerances must lie in (0, 1)");
  Require(max_damping > 0.0 && max_damping < 1.0, "ssi-cov: max_damping must lie in (0, 1)");
  Require(min_cluster_share > 0.0 && min_cluster_share <= 1.0,
          "ssi-cov: min_cluster_share must lie in (0, 1]");
  Require(std::isfinite(max_omega_ci95_share) && max_omega_ci95_share > 0.0,
          "ssi-cov: max_omega_ci95_share must be above 0");
  Require(blocks >= 6 && blocks <= 1000, "ssi-cov: blocks must be 6 to 1000");
  Require(draws >= 50 && draws <= 100000, "ssi-cov: draws must be 50 to 100000");
}

double Mac(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b) {
  const double den = a.squaredNorm() * b.squaredNorm();
  return den > 0.0 ? std::norm(a.dot(b)) / den : 0.0;
}

SsiCovResult SsiCov(Eigen::Ref<const Eigen::MatrixXd> y, const SsiCovOptions& options) {
  options.Validate();
  const int l = static_cast<int>(y.cols());
  Require(l >= 1, "ssi-cov: at least one response channel");
  Require(y.allFinite(), "ssi-cov: the responses hold a non-finite value");
  const Setup plan = Plan(options, l);
  const Eigen::MatrixXd yd = Decimate(y, plan.decimation);
  const int i = plan.block_rows;
  const int lags = 2 * i - 1;
  const Eigen::Index block_len = yd.rows() / options.blocks;
  if (block_len < 4 * (lags + 1)) {
    const double need_s = 4.0 * (lags + 1) * options.blocks / plan.fs_hz;
    throw InputError("ssi-cov: the record is too short for " + std::to_string(options.blocks) +
                     " blocks of a Hankel matrix with " + std::to_string(i) +
                     " block rows: at least " +
                     std::to_string(static_cast<int>(std::ceil(need_s))) +
                     " s are needed at this band (or raise fmin_hz, lower blocks)");
  }

  // The Hankel matrix of each block, and their mean: the estimate and its covariance.
  std::vector<Eigen::MatrixXd> block_h;
  Eigen::MatrixXd h_mean = Eigen::MatrixXd::Zero(i * l, i * l);
  for (int j = 0; j < options.blocks; ++j) {
    block_h.push_back(
        Hankel(OutputCovariances(yd.middleRows(j * block_len, block_len), lags), l, i));
    h_mean += block_h.back();
  }
  h_mean /= options.blocks;

  SsiCovResult result;
  result.fs_hz = plan.fs_hz;
  result.decimation = plan.decimation;
  result.block_rows = i;
  result.order_max = plan.order_max;
  result.channels = l;
  result.samples = yd.rows();
  const double omega_max = kTwoPi * plan.fmax_hz;

  Eigen::BDCSVD<Eigen::MatrixXd> svd(h_mean, Eigen::ComputeThinU);
  const Eigen::VectorXd s = svd.singularValues();
  result.singular_values.assign(s.data(),
                                s.data() + std::min<Eigen::Index>(s.size(), 2 * plan.order_max));

  // Stabilization diagram: poles of every even order, stable against the order below.
  std::vector<std::vector<RawPole>> by_order;
  std::vector<int> orders;
  for (int n = 2; n <= plan.order_max; n += 2) {
    orders.push_back(n);
    by_order.push_back(
        PolesAtOrder(svd.matrixU(), s, n, l, plan.fs_hz, options.max_damping, omega_max));
  }
  std::vector<RawPole> stable_poles;
  std::vector<std::size_t> stable_index;  // index into result.diagram
  for (std::size_t k = 0; k < by_order.size(); ++k) {
    for (const RawPole& p : by_order[k]) {
      Pole pole{orders[k], p.omega_rad_s, p.zeta, false, -1};
      if (k > 0 && !by_order[k - 1].empty()) {
        const RawPole* near = &by_order[k - 1].front();
        for (const RawPole& q : by_order[k - 1]) {
          if (std::fabs(q.omega_rad_s - p.omega_rad_s) <
              std::fabs(near->omega_rad_s - p.omega_rad_s))
            near = &q;
        }
        pole.stable = std::fabs(near->omega_rad_s - p.omega_rad_s) / p.omega_rad_s <
                          options.stable_freq_tol &&
                      std::fabs(near->zeta - p.zeta) / p.zeta < options.stable_damping_tol &&
                      1.0 - Mac(near->shape, p.shape) < options.stable_mac_tol;
      }
      if (pole.stable) {
        stable_poles.push_back(p);
        stable_index.push_back(result.diagram.size());
      }
      result.diagram.push_back(pole);
    }
  }

  // Clusters of stable poles close in frequency and shape (single linkage); a cluster holding
  // poles of at least min_cluster_share of the orders is a mode.
  const std::size_t count = stable_poles.size();
  UnionFind sets(count);
  const double link = options.stable_freq_tol + options.stable_mac_tol;
  for (std::size_t a = 0; a < count; ++a) {
    for (std::size_t b = a + 1; b < count; ++b) {
      const double df = std::fabs(stable_poles[a].omega_rad_s - stable_poles[b].omega_rad_s) /
                        std::max(stable_poles[a].omega_rad_s, stable_poles[b].omega_rad_s);
      if (df > link) continue;
      if (df + 1.0 - Mac(stable_poles[a].shape, stable_poles[b].shape) <= link) sets.Join(a, b);
    }
  }
  std::vector<std::vector<std::size_t>> members(count);
  for (std::size_t a = 0; a < count; ++a) members[sets.Find(a)].push_back(a);
  // The orders that could carry a mode are those from its first stable pole up: a weakly
  // excited or weakly observed mode needs a higher order before it stands out of the noise, and
  // is no less a mode for it. Spurious poles are rarely stable twice in a row, so at least
  // kMinClusterPoles are asked for too.
  constexpr std::size_t kMinClusterPoles = 5;
  std::vector<std::vector<std::size_t>> clusters;
  for (auto& m : members) {
    if (m.size() < kMinClusterPoles) continue;
    int first_order = plan.order_max;
    for (std::size_t a : m)
      first_order = std::min(first_order, result.diagram[stable_index[a]].order);
    const double could = static_cast<double>((plan.order_max - first_order) / 2 + 1);
    if (static_cast<double>(m.size()) >= options.min_cluster_share * could) clusters.push_back(m);
  }
  auto median_member = [&](std::vector<std::size_t> m) {
    std::sort(m.begin(), m.end(), [&](std::size_t a, std::size_t b) {
      return stable_poles[a].omega_rad_s < stable_poles[b].omega_rad_s;
    });
    return m[m.size() / 2];
  };
  std::sort(clusters.begin(), clusters.end(), [&](const auto& a, const auto& b) {
    return stable_poles[median_member(a)].omega_rad_s < stable_poles[median_member(b)].omega_rad_s;
  });

  std::vector<Eigen::VectorXcd> reference_shapes;
  std::vector<Eigen::Index> reference_entry;
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    const std::size_t rep = median_member(clusters[c]);
    const RawPole& p = stable_poles[rep];
    OmaMode mode;
    mode.omega_rad_s = p.omega_rad_s;
    mode.zeta = p.zeta;
    Eigen::Index ref = 0;
    p.shape.cwiseAbs().maxCoeff(&ref);
    mode.shape = RealShape(p.shape, ref);
    mode.mpc = Mpc(p.shape);
    mode.order = result.diagram[stable_index[rep]].order;
    mode.cluster_size = static_cast<int>(clusters[c].size());
    for (std::size_t a : clusters[c]) result.diagram[stable_index[a]].cluster = static_cast<int>(c);
    result.modes.push_back(mode);
    reference_shapes.push_back(p.shape);
    reference_entry.push_back(ref);
  }
  if (result.modes.empty()) {
    result.message =
        "no mode: no cluster of stable poles spans half of the orders above its "
        "first (too little excitation in the band, or the band holds no mode)";
    return result;
  }

  // Intervals: samples of the Hankel matrix with the covariance of the block mean, each run
  // through the same order as its mode, the mode found again as the nearest pole in frequency
  // and shape.
  const std::size_t modes = result.modes.size();
  std::vector<std::vector<double>> omega_draws(modes), zeta_draws(modes);
  std::vector<std::vector<Eigen::VectorXd>> shape_draws(modes);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double scale = 1.0 / std::sqrt(static_cast<double>(options.blocks) * (options.blocks - 1));
  std::vector<int> mode_orders;
  for (const OmaMode& m : result.modes) mode_orders.push_back(m.order);
  std::sort(mode_orders.begin(), mode_orders.end());
  mode_orders.erase(std::unique(mode_orders.begin(), mode_orders.end()), mode_orders.end());
  // Each block's deviation from the mean as a column: a sample is the mean plus their
  // combination with normal weights (one matrix-vector product).
  const Eigen::Index cells = h_mean.size();
  Eigen::MatrixXd deviations(cells, options.blocks);
  for (int j = 0; j < options.blocks; ++j) {
    deviations.col(j) = (block_h[static_cast<std::size_t>(j)] - h_mean).reshaped();
  }
  Eigen::VectorXd weights(options.blocks);
  Eigen::MatrixXd h(h_mean.rows(), h_mean.cols());
  Eigen::MatrixXd gram(h_mean.rows(), h_mean.rows());
  numerics::LeadingEigenvectors leading;
  for (int d = 0; d < options.draws; ++d) {
    for (int j = 0; j < options.blocks; ++j) weights(j) = normal(rng) * scale;
    h.reshaped() = h_mean.reshaped() + deviations * weights;
    // The poles of an order depend on the span of its leading left singular vectors alone (a
    // change of basis of the observability matrix is a similarity of A, which keeps the
    // eigenvalues and C times the eigenvectors): that span is the leading eigenspace of h hᵀ,
    // whose symmetric eigensolver costs a fraction of the SVD of h. The solver reads the lower
    // triangle alone, and that is all the rank update computes.
    gram.setZero();
    gram.selfadjointView<Eigen::Lower>().rankUpdate(h);
    // Only the leading mode_orders.back() eigenvectors are used: inverse iteration on the
    // tridiagonal form gives them without rotating the others through every QR step.
    leading.Compute(gram, mode_orders.back());
    if (!leading.ok()) continue;  // a degenerate sample: no pole, as a failed eigensolver
    const SampleStateMatrices states(leading.vectors(), mode_orders.back(), l);
    std::vector<std::optional<SampleMatch>> matched(modes);
    for (int order : mode_orders) {
      std::vector<std::size_t> at_order;
      std::vector<double> targets;
      std::vector<Eigen::VectorXcd> shapes;
      for (std::size_t m = 0; m < modes; ++m) {
        if (result.modes[m].order != order) continue;
        at_order.push_back(m);
        targets.push_back(result.modes[m].omega_rad_s);
        shapes.push_back(reference_shapes[m]);
      }
      MatchModesAtOrder(states, order, plan.fs_hz, options.max_damping, omega_max * 1.2, at_order,
                        targets, shapes, kMatchReach, matched);
    }
    for (std::size_t m = 0; m < modes; ++m) {
      if (!matched[m]) continue;
      omega_draws[m].push_back(matched[m]->omega_rad_s);
      zeta_draws[m].push_back(matched[m]->zeta);
      shape_draws[m].push_back(RealShape(matched[m]->shape, reference_entry[m]));
    }
  }
  const double t95 = numerics::StudentTQuantile(0.975, options.blocks - 1);
  std::ostringstream withheld;
  std::vector<OmaMode> kept;
  std::vector<int> new_index(modes, -1);  // the diagram's cluster numbers after the drops
  for (std::size_t m = 0; m < modes; ++m) {
    OmaMode& mode = result.modes[m];
    const auto found = static_cast<double>(omega_draws[m].size());
    mode.found_share = found / options.draws;
    if (mode.found_share < 0.9) {
      // A cluster that the samples of the data's own uncertainty do not reproduce is not a mode
      // the data support (noise that lined up, or a mode too weak to tell): named, not reported.
      withheld << (withheld.tellp() > 0 ? "; " : "") << "poles near " << mode.omega_rad_s / kTwoPi
               << " Hz were found again in only " << static_cast<int>(100.0 * mode.found_share)
               << " % of the covariance samples: not reported as a mode";
      continue;
    }
    auto stddev = [found](const std::vector<double>& v) {
      const double mean = std::accumulate(v.begin(), v.end(), 0.0) / found;
      double ss = 0.0;
      for (double x : v) ss += (x - mean) * (x - mean);
      return std::sqrt(ss / (found - 1.0));
    };
    const double omega_ci95_rad_s = t95 * stddev(omega_draws[m]);
    if (omega_ci95_rad_s > options.max_omega_ci95_share * mode.omega_rad_s) {
      // The samples reproduce the cluster but scatter it over several percent: poles that
      // wander with the noise, not a resonance the data pin down.
      withheld << (withheld.tellp() > 0 ? "; " : "") << "poles near " << mode.omega_rad_s / kTwoPi
               << " Hz scatter by ± " << 100.0 * omega_ci95_rad_s / mode.omega_rad_s
               << " % of their frequency over the covariance samples (more than "
               << 100.0 * options.max_omega_ci95_share << " %): not reported as a mode";
      continue;
    }
    new_index[m] = static_cast<int>(kept.size());
    kept.push_back(mode);
    OmaMode& out = kept.back();
    out.omega_ci95_rad_s = omega_ci95_rad_s;
    out.zeta_ci95 = t95 * stddev(zeta_draws[m]);
    out.shape_ci95.resize(l);
    for (int c = 0; c < l; ++c) {
      std::vector<double> v;
      for (const Eigen::VectorXd& sh : shape_draws[m]) v.push_back(sh(c));
      out.shape_ci95(c) = t95 * stddev(v);
    }
  }
  result.modes = std::move(kept);
  for (Pole& pole : result.diagram) {
    if (pole.cluster >= 0) pole.cluster = new_index[static_cast<std::size_t>(pole.cluster)];
  }
  result.message = withheld.str();
  return result;
}

}  // namespace vibid::oma
