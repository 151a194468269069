// The interval samples of SSI-cov, one SVD and one full eigensolver per sample and order.
#include "vibid/oma/testing/textbook_intervals.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <numeric>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "vibid/numerics/distributions.hpp"

namespace vibid::oma::testing {
namespace {

struct Pole {
  double omega_rad_s;
  double zeta;
  Eigen::VectorXcd shape;
};

Eigen::MatrixXd HankelOf(const Eigen::MatrixXd& y, int l, int i) {
  const Eigen::MatrixXd r = OutputCovariances(y, 2 * i - 1);
  Eigen::MatrixXd h(i * l, i * l);
  for (int a = 0; a < i; ++a) {
    for (int b = 0; b < i; ++b) h.block(a * l, b * l, l, l) = r.middleCols((a + b + 1) * l, l);
  }
  return h;
}

// Every vibration pole (one of each complex pair) of the order-n model of h, with its shape.
std::vector<Pole> Poles(const Eigen::MatrixXd& h, int order, int l, double fs_hz,
                        double max_damping, double omega_max) {
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(h, Eigen::ComputeThinU);
  const Eigen::Index rows = h.rows();
  const Eigen::MatrixXd o =
      svd.matrixU().leftCols(order) * svd.singularValues().head(order).cwiseSqrt().asDiagonal();
  const Eigen::MatrixXd a = o.topRows(rows - l).colPivHouseholderQr().solve(o.bottomRows(rows - l));
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(a, true);
  std::vector<Pole> poles;
  for (Eigen::Index k = 0; k < order; ++k) {
    const std::complex<double> lambda = eig.eigenvalues()(k);
    if (!(lambda.imag() > 1e-12 * std::abs(lambda))) continue;
    const std::complex<double> mu = std::log(lambda) * fs_hz;
    const double omega = std::abs(mu);
    const double zeta = -mu.real() / omega;
    if (!(zeta > 0.0 && zeta < max_damping && omega <= omega_max)) continue;
    poles.push_back({omega, zeta, o.topRows(l) * eig.eigenvectors().col(k)});
  }
  return poles;
}

double StdDev(const std::vector<double>& v) {
  const auto n = static_cast<double>(v.size());
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
  double ss = 0.0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / (n - 1.0));
}

}  // namespace

std::vector<TextbookInterval> TextbookIntervals(Eigen::Ref<const Eigen::MatrixXd> y,
                                                const SsiCovOptions& options,
                                                const SsiCovResult& result) {
  constexpr double kMatchReach = 0.1;  // SsiCov's: beyond it a pole is another mode or noise
  const int l = result.channels;
  const int i = result.block_rows;
  const double fmax_hz = options.fmax_hz > 0.0 ? options.fmax_hz : options.fs_hz / 2.5;
  const double omega_max = 2.0 * std::numbers::pi * fmax_hz;
  const Eigen::MatrixXd yd = Decimate(y, result.decimation);
  const Eigen::Index block_len = yd.rows() / options.blocks;
  std::vector<Eigen::MatrixXd> block_h;
  Eigen::MatrixXd h_mean = Eigen::MatrixXd::Zero(i * l, i * l);
  for (int j = 0; j < options.blocks; ++j) {
    block_h.push_back(HankelOf(yd.middleRows(j * block_len, block_len), l, i));
    h_mean += block_h.back();
  }
  h_mean /= options.blocks;

  // Each mode's complex shape in the mean fit: the pole of its order at its frequency.
  const std::size_t modes = result.modes.size();
  std::vector<Eigen::VectorXcd> reference(modes);
  std::vector<Eigen::Index> entry(modes);
  for (std::size_t m = 0; m < modes; ++m) {
    const OmaMode& mode = result.modes[m];
    double best = 1e300;
    for (const Pole& p :
         Poles(h_mean, mode.order, l, result.fs_hz, options.max_damping, omega_max)) {
      if (std::fabs(p.omega_rad_s - mode.omega_rad_s) < best) {
        best = std::fabs(p.omega_rad_s - mode.omega_rad_s);
        reference[m] = p.shape;
      }
    }
    reference[m].cwiseAbs().maxCoeff(&entry[m]);
  }

  std::vector<std::vector<double>> omega(modes), zeta(modes);
  std::vector<std::vector<Eigen::VectorXd>> shape(modes);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double scale = 1.0 / std::sqrt(static_cast<double>(options.blocks) * (options.blocks - 1));
  Eigen::VectorXd weights(options.blocks);
  for (int d = 0; d < options.draws; ++d) {
    for (int j = 0; j < options.blocks; ++j) weights(j) = normal(rng) * scale;
    Eigen::MatrixXd h = h_mean;
    for (int j = 0; j < options.blocks; ++j)
      h += weights(j) * (block_h[static_cast<std::size_t>(j)] - h_mean);
    for (std::size_t m = 0; m < modes; ++m) {
      const OmaMode& mode = result.modes[m];
      const Pole* best = nullptr;
      double best_d = kMatchReach;
      const std::vector<Pole> poles =
          Poles(h, mode.order, l, result.fs_hz, options.max_damping, omega_max * 1.2);
      for (const Pole& p : poles) {
        const double dist = std::fabs(p.omega_rad_s - mode.omega_rad_s) / mode.omega_rad_s + 1.0 -
                            Mac(p.shape, reference[m]);
        if (dist < best_d) {
          best_d = dist;
          best = &p;
        }
      }
      if (best == nullptr) continue;
      omega[m].push_back(best->omega_rad_s);
      zeta[m].push_back(best->zeta);
      shape[m].push_back((best->shape / best->shape(entry[m])).real());
    }
  }
  const double t95 = numerics::StudentTQuantile(0.975, options.blocks - 1);
  std::vector<TextbookInterval> out(modes);
  for (std::size_t m = 0; m < modes; ++m) {
    out[m].found_share = static_cast<double>(omega[m].size()) / options.draws;
    if (omega[m].size() < 2) continue;
    out[m].omega_ci95_rad_s = t95 * StdDev(omega[m]);
    out[m].zeta_ci95 = t95 * StdDev(zeta[m]);
    out[m].shape_ci95.resize(l);
    for (int c = 0; c < l; ++c) {
      std::vector<double> v;
      for (const Eigen::VectorXd& s : shape[m]) v.push_back(s(c));
      out[m].shape_ci95(c) = t95 * StdDev(v);
    }
  }
  return out;
}

}  // namespace vibid::oma::testing
