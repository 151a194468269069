#include "vibid/ident/stabilization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <set>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "band.hpp"
#include "vibid/common/error.hpp"

namespace vibid::ident {

const char* PoleMethodName(PoleMethod method) {
  return method == PoleMethod::kLscf ? "lscf" : "lsce";
}

void StabilizationOptions::Validate() const {
  RequireBand(freq_min_hz, freq_max_hz, "stabilization");
  Require(min_order >= 2 && (max_order == 0 || max_order >= min_order) && order_step >= 1,
          "stabilization: orders must satisfy 2 <= min <= max and step >= 1");
  Require(max_order <= 400, "stabilization: orders above 400 are not supported");
  Require(freq_tolerance > 0.0 && damping_tolerance > 0.0 && mac_min > 0.0 && mac_min <= 1.0,
          "stabilization: tolerances must be > 0 and the MAC limit in (0, 1]");
  Require(min_zeta >= 0.0 && max_zeta > min_zeta && max_zeta < 1.0,
          "stabilization: need 0 <= min_zeta < max_zeta < 1");
  Require(min_cluster_fraction > 0.0 && min_cluster_fraction <= 1.0,
          "stabilization: cluster fraction must be in (0, 1]");
}

void ParseOrders(std::string_view text, StabilizationOptions& options) {
  std::vector<int> parts;
  std::size_t start = 0;
  const std::string s(text);
  while (start <= s.size()) {
    const std::size_t colon = std::min(s.find(':', start), s.size());
    const std::string item = s.substr(start, colon - start);
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(item, &used);
    } catch (...) {
      used = 0;
    }
    Require(!item.empty() && used == item.size(),
            "--orders '" + s + "' must be MIN:MAX or MIN:MAX:STEP (whole numbers)");
    parts.push_back(v);
    start = colon + 1;
  }
  Require(parts.size() == 2 || parts.size() == 3,
          "--orders '" + s + "' must be MIN:MAX or MIN:MAX:STEP");
  Require(parts[0] >= 2 && parts[1] >= parts[0] && (parts.size() == 2 || parts[2] >= 1),
          "--orders '" + s + "': need 2 <= MIN <= MAX and STEP >= 1");
  options.min_order = parts[0];
  options.max_order = parts[1];
  if (parts.size() == 3) options.order_step = parts[2];
  options.Validate();
}

int AutomaticMaxOrder(int lines, const StabilizationOptions& options) {
  constexpr int kHighestAutomaticOrder = 48;
  // A quarter of the lines (the orders where noise is not yet fitted as poles), but up to
  // min + 6 step where the fit's own limit allows: a band of coarse lines needs that many orders
  // for a mode low in it to settle (the emulated chain's 4.4 Hz mode in 1 Hz lines).
  const int fit_limit = options.method == PoleMethod::kLscf ? lines / 2 : lines / 4;
  const int comfortable = options.min_order + 6 * options.order_step;
  const int limit =
      std::min(kHighestAutomaticOrder, std::max(lines / 4, std::min(fit_limit, comfortable)));
  if (limit < options.min_order + 3 * options.order_step) return 0;
  return options.min_order + (limit - options.min_order) / options.order_step * options.order_step;
}

int LinesNeeded(const StabilizationOptions& options) {
  const int top =
      options.max_order > 0 ? options.max_order : options.min_order + 3 * options.order_step;
  return options.method == PoleMethod::kLscf ? 2 * top : 4 * top;
}

namespace {

struct Band {
  std::vector<Eigen::Index> rows;
  double lo = 0.0;
  double hi = 0.0;
};

Band BandOf(const Frf& frf, double freq_min_hz, double freq_max_hz) {
  Band b;
  b.hi = freq_max_hz > 0.0 ? freq_max_hz : frf.freq_hz[frf.freq_hz.size() - 1];
  b.lo = freq_min_hz;
  for (Eigen::Index k = 0; k < frf.freq_hz.size(); ++k) {
    const double f = frf.freq_hz[k];
    if (f > 0.0 && f >= b.lo && f <= b.hi) b.rows.push_back(k);
  }
  Require(!b.rows.empty(), "stabilization: no frequency line in the band");
  b.lo = frf.freq_hz[b.rows.front()];
  return b;
}

// Roots of sum_r alpha_r z^r with alpha_n = 1 (companion matrix eigenvalues).
Eigen::VectorXcd Roots(const Eigen::VectorXd& alpha) {
  const Eigen::Index n = alpha.size() - 1;
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 1; i < n; ++i) c(i, i - 1) = 1.0;
  for (Eigen::Index i = 0; i < n; ++i) c(i, n - 1) = -alpha[i] / alpha[n];
  Eigen::EigenSolver<Eigen::MatrixXd> es(c, false);
  return es.eigenvalues();
}

std::complex<double> Polyval(const Eigen::VectorXd& coef, std::complex<double> z) {
  std::complex<double> v = 0.0;
  for (Eigen::Index r = coef.size(); r-- > 0;) v = v * z + coef[r];
  return v;
}

// Reduced normal equations of the pLSCF model for every order up to `max_order`: the Toeplitz
// sequences of R_o, S_o, T_o (their leading blocks are the matrices of every lower order, since the
// polynomial bases are nested).
struct LscfNormals {
  double dt_s = 0.0;
  int max_order = 0;
  std::vector<Eigen::VectorXd> r, t;  // d = 0..max
  std::vector<Eigen::VectorXd> s;     // d = -max..max at index d + max

  LscfNormals(const Frf& frf, const Band& band, int max_order_in) : max_order(max_order_in) {
    dt_s = 1.0 / (2.0 * band.hi);
    const Eigen::Index no = frf.h.cols();
    const int n = max_order;
    for (Eigen::Index o = 0; o < no; ++o) {
      double top = 0.0;
      for (const Eigen::Index k : band.rows) top = std::max(top, std::abs(frf.h(k, o)));
      Eigen::VectorXd ro = Eigen::VectorXd::Zero(n + 1);
      Eigen::VectorXd to = Eigen::VectorXd::Zero(n + 1);
      Eigen::VectorXd so = Eigen::VectorXd::Zero(2 * n + 1);
      for (const Eigen::Index k : band.rows) {
        const std::complex<double> h = frf.h(k, o);
        if (!(top > 0.0)) continue;
        const double coh = std::max(frf.coherence(k, o), 0.0);
        const double w2 = coh / (top * top);
        const double theta = 2.0 * std::numbers::pi * frf.freq_hz[k] * dt_s;
        for (int d = 0; d <= n; ++d) {
          const std::complex<double> e = std::polar(1.0, theta * d);
          ro[d] += w2 * e.real();
          to[d] += w2 * std::norm(h) * e.real();
          // -Re(w2 H e^{j theta d}) for +d and -d.
          so[d + n] += -w2 * (h * e).real();
          so[n - d] += -w2 * (h * std::conj(e)).real();
        }
        so[n] -= -w2 * h.real();  // d = 0 was added twice
      }
      r.push_back(ro);
      t.push_back(to);
      s.push_back(so);
    }
  }

  PoleSet Solve(int order) const {
    const int n = order;
    const auto size = static_cast<Eigen::Index>(n + 1);
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(size, size);
    std::vector<Eigen::MatrixXd> rinv_s;
    for (std::size_t o = 0; o < r.size(); ++o) {
      Eigen::MatrixXd ro(size, size);
      Eigen::MatrixXd to(size, size);
      Eigen::MatrixXd so(size, size);
      for (Eigen::Index a = 0; a < size; ++a) {
        for (Eigen::Index b = 0; b < size; ++b) {
          ro(a, b) = r[o][std::abs(a - b)];
          to(a, b) = t[o][std::abs(a - b)];
          so(a, b) = s[o][b - a + max_order];
        }
      }
      Eigen::MatrixXd x = ro.ldlt().solve(so);
      m += 2.0 * (to - so.transpose() * x);
      rinv_s.push_back(std::move(x));
    }
    Eigen::VectorXd alpha(size);
    alpha[n] = 1.0;
    alpha.head(n) = -m.topLeftCorner(n, n).partialPivLu().solve(m.col(n).head(n));
    PoleSet out;
    const Eigen::VectorXcd z = Roots(alpha);
    out.lambda.resize(z.size());
    out.shapes.resize(static_cast<Eigen::Index>(r.size()), z.size());
    for (Eigen::Index i = 0; i < z.size(); ++i) {
      out.lambda[i] = std::log(z[i]) / dt_s;
      for (std::size_t o = 0; o < r.size(); ++o) {
        const Eigen::VectorXd beta = -rinv_s[o] * alpha;
        out.shapes(static_cast<Eigen::Index>(o), i) = Polyval(beta, z[i]);
      }
    }
    return out;
  }
};

// Impulse responses (first half of the period) of the accelerance, and the LSCE normal matrix of
// the highest order: rows [g[k], ..., g[k + n]] over k and responses.
struct LsceNormals {
  double dt_s = 0.0;
  Eigen::MatrixXd normal;  // (max + 1) x (max + 1)

  LsceNormals(const Frf& frf, int max_order, double freq_max_hz) {
    Frf acc = ConvertFrf(frf, Quantity::kAcceleration);
    if (freq_max_hz > 0.0) {
      Eigen::Index keep = 0;
      while (keep < acc.freq_hz.size() && acc.freq_hz[keep] <= freq_max_hz * (1.0 + 1e-12)) ++keep;
      acc.freq_hz.conservativeResize(keep);
      acc.h.conservativeResize(keep, Eigen::NoChange);
    }
    const Eigen::Index lines = acc.freq_hz.size();
    Require(lines >= 4, "lsce: too few frequency lines");
    const double df = acc.freq_hz[lines - 1] - acc.freq_hz[lines - 2];
    Require(df > 0.0, "lsce: frequency lines must increase");
    const auto last = static_cast<Eigen::Index>(std::llround(acc.freq_hz[lines - 1] / df));
    const auto first = static_cast<Eigen::Index>(std::llround(acc.freq_hz[0] / df));
    Require(first <= 1 && last == first + lines - 1,
            "lsce needs every line from the first to the Nyquist line (an FRF from one record per "
            "hit, or a Welch FRF)");
    const Eigen::Index n = 2 * last;  // period of the impulse response
    dt_s = 1.0 / (static_cast<double>(n) * df);
    // Spectrum X_k, k = 0..last (DC taken as 0). x[m] = (1/N)(Re FFT(u)[m] + Im FFT(v)[m]) with u,
    // v the even and odd extensions of Re X and Im X.
    RealFft fft(static_cast<std::size_t>(n));
    const Eigen::Index half = n / 2;
    const Eigen::Index k0 = 2;  // skip the direct (impulsive) part of the accelerance
    const Eigen::Index rows = half - max_order - k0;
    Require(rows > 2 * max_order, "lsce: the impulse response is too short for the highest order");
    normal = Eigen::MatrixXd::Zero(max_order + 1, max_order + 1);
    Eigen::VectorXd u(n);
    Eigen::VectorXd v(n);
    Eigen::VectorXcd fu;
    Eigen::VectorXcd fv;
    for (Eigen::Index o = 0; o < acc.h.cols(); ++o) {
      u.setZero();
      v.setZero();
      for (Eigen::Index i = 0; i < lines; ++i) {
        const Eigen::Index k = first + i;
        const std::complex<double> x = acc.h(i, o);
        if (k == 0) {
          u[0] = x.real();
          continue;
        }
        u[k] = x.real();
        v[k] = x.imag();
        if (k != half) {
          u[n - k] = x.real();
          v[n - k] = -x.imag();
        } else {
          v[k] = 0.0;  // the Nyquist line of a real signal is real
        }
      }
      fft.Transform(u.data(), fu);
      fft.Transform(v.data(), fv);
      Eigen::VectorXd g(half + 1);
      for (Eigen::Index m = 0; m <= half; ++m)
        g[m] = (fu[m].real() + fv[m].imag()) / static_cast<double>(n);
      Eigen::MatrixXd hank(rows, max_order + 1);
      for (Eigen::Index k = 0; k < rows; ++k)
        hank.row(k) = g.segment(k0 + k, max_order + 1).transpose();
      normal += hank.transpose() * hank;
    }
  }

  PoleSet Solve(int order) const {
    const int n = order;
    Eigen::VectorXd a(n + 1);
    a[n] = 1.0;
    a.head(n) = -normal.topLeftCorner(n, n).ldlt().solve(normal.col(n).head(n));
    const Eigen::VectorXcd z = Roots(a);
    PoleSet out;
    out.lambda.resize(z.size());
    out.shapes = Eigen::MatrixXcd::Ones(1, z.size());  // shapes are not resolved by the recursion
    for (Eigen::Index i = 0; i < z.size(); ++i) out.lambda[i] = std::log(z[i]) / dt_s;
    return out;
  }
};

double Mac(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b) {
  const double den = a.squaredNorm() * b.squaredNorm();
  return den > 0.0 ? std::norm(a.dot(b)) / den : 0.0;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

double RelativeSpread(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  double mean = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return mean != 0.0 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) / std::abs(mean) : 0.0;
}

}  // namespace

PoleSet LscfPoles(const Frf& frf, double freq_min_hz, double freq_max_hz, int order) {
  Require(order >= 1, "lscf: order must be >= 1");
  const Band band = BandOf(frf, freq_min_hz, freq_max_hz);
  return LscfNormals(frf, band, order).Solve(order);
}

PoleSet LscePoles(const Frf& frf, int order, double freq_max_hz) {
  Require(order >= 1, "lsce: order must be >= 1");
  return LsceNormals(frf, order, freq_max_hz).Solve(order);
}

namespace {

// The poles of one order that can be modes of the structure: a positive frequency in the band and
// a damping between 0 and the maximum. `keep_shape`: the method resolves shapes.
void ModalPolesOfOrder(const PoleSet& set, int order, const Band& band,
                       const StabilizationOptions& options, double exp_window_tau_s,
                       bool keep_shape, std::vector<DiagramPole>& now,
                       std::vector<Eigen::VectorXcd>& now_shapes) {
  for (Eigen::Index i = 0; i < set.lambda.size(); ++i) {
    const std::complex<double> l = set.lambda[i];
    if (!std::isfinite(l.real()) || !std::isfinite(l.imag()) || l.imag() <= 0.0 || l.real() >= 0.0)
      continue;
    DiagramPole p;
    p.order = order;
    const double omega = std::abs(l);
    p.freq_hz = omega / (2.0 * std::numbers::pi);
    p.zeta = CorrectExponentialWindowDamping(-l.real() / omega, omega, exp_window_tau_s);
    if (p.freq_hz < band.lo || p.freq_hz > band.hi || !(p.zeta > 0.0) || p.zeta >= options.max_zeta)
      continue;
    if (keep_shape) p.shape = set.shapes.col(i);
    now.push_back(p);
    now_shapes.push_back(set.shapes.col(i));
  }
}

// Each pole against the nearest pole of the previous order.
// The damping rule is relative to the larger of the pole's damping and the damping of a
// resonance one line wide (spacing / (2 f)): a mode narrower than a line (a wing at 167.8 Hz,
// zeta 0.0003, in lines 0.31 Hz apart: 0.00093) has a damping the lines do not resolve to 5 % of
// itself, and was stable in frequency and shape at 22 of 23 orders but never in damping.
void MarkStability(const std::vector<DiagramPole>& prev,
                   const std::vector<Eigen::VectorXcd>& prev_shapes,
                   const std::vector<Eigen::VectorXcd>& now_shapes,
                   const StabilizationOptions& options, double spacing_hz,
                   std::vector<DiagramPole>& now) {
  for (std::size_t i = 0; i < now.size(); ++i) {
    DiagramPole& p = now[i];
    std::size_t best = prev.size();
    double best_df = 0.0;
    for (std::size_t q = 0; q < prev.size(); ++q) {
      const double df = std::abs(prev[q].freq_hz - p.freq_hz);
      if (best == prev.size() || df < best_df) {
        best = q;
        best_df = df;
      }
    }
    if (best == prev.size()) continue;
    p.stable_freq = best_df <= options.freq_tolerance * p.freq_hz;
    const double zeta_line = p.freq_hz > 0.0 ? spacing_hz / (2.0 * p.freq_hz) : 0.0;
    p.stable_damping = std::abs(prev[best].zeta - p.zeta) <=
                       options.damping_tolerance * std::max(p.zeta, zeta_line);
    p.stable_shape = Mac(now_shapes[i], prev_shapes[best]) >= options.mac_min;
  }
}

// Clusters of the fully stable poles: sorted by frequency, split where neighbours are further
// apart than the frequency tolerance. A cluster seen at enough orders, with a resolved damping,
// becomes a selected pole.
void SelectClusters(const StabilizationOptions& options, StabilizationDiagram& d) {
  std::vector<std::size_t> stable;
  for (std::size_t i = 0; i < d.poles.size(); ++i) {
    if (d.poles[i].Stable()) stable.push_back(i);
  }
  std::sort(stable.begin(), stable.end(),
            [&](std::size_t a, std::size_t b) { return d.poles[a].freq_hz < d.poles[b].freq_hz; });
  const auto needed = static_cast<std::size_t>(std::max(
      3.0, std::ceil(options.min_cluster_fraction * static_cast<double>(d.orders.size()))));
  std::size_t begin = 0;
  while (begin < stable.size()) {
    std::size_t end = begin + 1;
    while (end < stable.size() && d.poles[stable[end]].freq_hz - d.poles[stable[end - 1]].freq_hz <=
                                      options.freq_tolerance * d.poles[stable[end]].freq_hz) {
      ++end;
    }
    std::set<int> orders;
    std::vector<double> fs;
    std::vector<double> zs;
    for (std::size_t k = begin; k < end; ++k) {
      const DiagramPole& p = d.poles[stable[k]];
      orders.insert(p.order);
      fs.push_back(p.freq_hz);
      zs.push_back(p.zeta);
    }
    const double zeta = Median(zs);
    if (orders.size() >= needed && zeta > options.min_zeta) {
      SelectedPole s;
      s.freq_hz = Median(fs);
      s.omega_rad_s = 2.0 * std::numbers::pi * s.freq_hz;
      s.zeta = zeta;
      s.orders = static_cast<int>(orders.size());
      s.freq_spread = RelativeSpread(fs);
      s.zeta_spread = RelativeSpread(zs);
      for (std::size_t k = begin; k < end; ++k)
        d.poles[stable[k]].cluster = static_cast<int>(d.selected.size());
      d.selected.push_back(s);
    }
    begin = end;
  }
}

// Lines of the band as the method counts them: pLSCF fits the band's lines, LSCE's impulse
// responses take every line from DC to the band's top.
int MethodLines(const Frf& frf, const Band& band, PoleMethod method) {
  if (method == PoleMethod::kLscf) return static_cast<int>(band.rows.size());
  int lines = 0;
  for (Eigen::Index k = 0; k < frf.freq_hz.size(); ++k)
    lines += frf.freq_hz[k] > 0.0 && frf.freq_hz[k] <= band.hi;
  return lines;
}

// The highest order of the diagram: the options' when given (and carried by the band), else
// from the band's lines. The refusal names the band, its lines and what gives more of them.
int OrdersForBand(const Frf& frf, const Band& band, const StabilizationOptions& options) {
  const int lines = MethodLines(frf, band, options.method);
  const bool lscf = options.method == PoleMethod::kLscf;
  const bool given = options.max_order > 0;
  const int max_order = given ? options.max_order : AutomaticMaxOrder(lines, options);
  // Given orders need what the fit itself needs: more lines than the order (pLSCF), impulse
  // responses with more rows than twice the order (LSCE).
  const int needed = !given ? LinesNeeded(options) : lscf ? max_order + 1 : 3 * max_order + 3;
  if (given ? lines >= needed : max_order > 0) return max_order;
  const double df = frf.freq_hz.size() >= 2 ? frf.freq_hz[1] - frf.freq_hz[0] : 0.0;
  char text[480];
  std::snprintf(text, sizeof text,
                "%s: the band %.4g..%.4g Hz holds %d frequency lines (%.3g Hz apart), too few for "
                "orders %d..%d (%d lines needed): give longer records per hit (hits further apart, "
                "or --record-s), a wider band (--fmax-hz)%s",
                PoleMethodName(options.method), band.lo, band.hi, lines, df, options.min_order,
                given ? max_order : options.min_order + 3 * options.order_step, needed,
                given ? " or lower orders (--orders)" : ", or --method fit");
  throw InputError(text);
}

}  // namespace

StabilizationDiagram BuildStabilizationDiagram(const Frf& frf,
                                               const StabilizationOptions& options) {
  options.Validate();
  Require(frf.lines() >= 4 && frf.responses() >= 1, "stabilization: the FRF is empty");
  const Band band = BandOf(frf, options.freq_min_hz, options.freq_max_hz);
  StabilizationDiagram d;
  d.method = options.method;
  d.freq_min_hz = band.lo;
  d.freq_max_hz = band.hi;
  const int max_order = OrdersForBand(frf, band, options);
  const Eigen::Index lines = frf.freq_hz.size();
  const double spacing_hz =
      (frf.freq_hz[lines - 1] - frf.freq_hz[0]) / static_cast<double>(lines - 1);
  std::unique_ptr<LscfNormals> lscf;
  std::unique_ptr<LsceNormals> lsce;
  if (options.method == PoleMethod::kLscf) {
    // Fitted as accelerance: what accelerometers measure, so a truncated record's DFT ratio is
    // rational in W (see the header), and resonances over decades of frequency weigh alike.
    lscf = std::make_unique<LscfNormals>(ConvertFrf(frf, Quantity::kAcceleration), band, max_order);
  } else {
    lsce = std::make_unique<LsceNormals>(frf, max_order, band.hi);
  }
  std::vector<Eigen::VectorXcd> prev_shapes;
  std::vector<DiagramPole> prev;
  for (int order = options.min_order; order <= max_order; order += options.order_step) {
    const PoleSet set = lscf ? lscf->Solve(order) : lsce->Solve(order);
    d.orders.push_back(order);
    std::vector<DiagramPole> now;
    std::vector<Eigen::VectorXcd> now_shapes;
    ModalPolesOfOrder(set, order, band, options, frf.exp_window_tau_s, lscf != nullptr, now,
                      now_shapes);
    MarkStability(prev, prev_shapes, now_shapes, options, spacing_hz, now);
    for (const DiagramPole& p : now) d.poles.push_back(p);
    prev = std::move(now);
    prev_shapes = std::move(now_shapes);
  }
  SelectClusters(options, d);
  return d;
}

}  // namespace vibid::ident

namespace vibid::ident {

std::vector<std::pair<double, double>> AutomaticBands(std::vector<double> resonances_hz,
                                                      double last_line_hz, double max_span) {
  std::sort(resonances_hz.begin(), resonances_hz.end());
  std::vector<std::pair<double, double>> bands;
  std::size_t i = 0;
  while (i < resonances_hz.size()) {
    std::size_t j = i + 1;
    while (j < resonances_hz.size() && resonances_hz[j] <= max_span * resonances_hz[i]) ++j;
    const double lo = bands.empty() ? 0.0 : 0.6 * resonances_hz[i];
    const double hi = std::min(last_line_hz, 1.6 * resonances_hz[j - 1]);
    if (hi > lo) bands.emplace_back(lo, hi);
    i = j;
  }
  if (bands.empty()) bands.emplace_back(0.0, last_line_hz);
  return bands;
}

StabilizationDiagram BuildStabilizationDiagram(
    const Frf& frf, const StabilizationOptions& options,
    const std::vector<std::pair<double, double>>& bands) {
  Require(!bands.empty(), "stabilization: no band");
  if (bands.size() == 1 && bands.front().second <= 0.0)
    return BuildStabilizationDiagram(frf, options);
  StabilizationDiagram all;
  struct Candidate {
    SelectedPole pole;
    std::size_t band = 0;
    int index = 0;
  };
  std::vector<Candidate> candidates;
  std::vector<StabilizationDiagram> parts;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    StabilizationOptions o = options;
    o.freq_min_hz = bands[b].first;
    o.freq_max_hz = bands[b].second;
    // A narrow band is widened upwards until it holds the lines its orders need; when they are
    // left open, lines for orders min..min + 6 step: at the fewest orders (min + 3 step) a mode
    // low in a band of coarse lines is not seen stable (the 4.4 Hz mode of the emulated chain
    // in 1 Hz lines).
    StabilizationOptions wide = o;
    if (wide.max_order == 0) wide.max_order = o.min_order + 6 * o.order_step;
    const int needed = LinesNeeded(wide);
    int lines = 0;
    for (Eigen::Index k = 0; k < frf.freq_hz.size(); ++k) {
      const double f = frf.freq_hz[k];
      if (!(f > 0.0) || (o.method == PoleMethod::kLscf && f < o.freq_min_hz)) continue;
      ++lines;
      if (f > o.freq_max_hz && lines <= needed) o.freq_max_hz = f;
    }
    parts.push_back(BuildStabilizationDiagram(frf, o));
    for (std::size_t k = 0; k < parts.back().selected.size(); ++k)
      candidates.push_back({parts.back().selected[k], parts.size() - 1, static_cast<int>(k)});
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& c) { return a.pole.freq_hz < c.pole.freq_hz; });
  std::vector<Candidate> kept;
  for (const Candidate& c : candidates) {
    if (!kept.empty() &&
        c.pole.freq_hz - kept.back().pole.freq_hz <= options.freq_tolerance * c.pole.freq_hz) {
      if (c.pole.orders > kept.back().pole.orders) kept.back() = c;
      continue;
    }
    kept.push_back(c);
  }
  all.method = options.method;
  all.freq_min_hz = parts.front().freq_min_hz;
  all.freq_max_hz = parts.front().freq_max_hz;
  for (const StabilizationDiagram& part : parts) {
    if (part.orders.size() > all.orders.size()) all.orders = part.orders;
  }
  for (std::size_t b = 0; b < parts.size(); ++b) {
    all.freq_min_hz = std::min(all.freq_min_hz, parts[b].freq_min_hz);
    all.freq_max_hz = std::max(all.freq_max_hz, parts[b].freq_max_hz);
    for (DiagramPole p : parts[b].poles) {
      const int old = p.cluster;
      p.cluster = -1;
      for (std::size_t k = 0; k < kept.size(); ++k) {
        if (old >= 0 && kept[k].band == b && kept[k].index == old) p.cluster = static_cast<int>(k);
      }
      all.poles.push_back(p);
    }
  }
  for (const Candidate& c : kept) all.selected.push_back(c.pole);
  return all;
}

}  // namespace vibid::ident
