#include "vibid/ident/driving_point.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "vibid/common/error.hpp"

namespace vibid::ident {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Hz(double f) {
  std::ostringstream s;
  s.precision(4);
  s << f << " Hz";
  return s.str();
}

std::string ResponseLabel(const ModalConstants& c, std::size_t j) {
  const std::string name =
      j < c.names.size() && !c.names[j].empty() ? c.names[j] : "response " + std::to_string(j + 1);
  return name + " (response " + std::to_string(j + 1) + ")";
}

// The line nearest `freq_hz`.
Eigen::Index NearestLine(const Eigen::VectorXd& freq_hz, double f) {
  Eigen::Index k = 0;
  (freq_hz.array() - f).abs().minCoeff(&k);
  return k;
}

// (Phi Phi^T)^-1's largest normalised off-diagonal entry with the shapes scaled from response p.
double MassCoupling(const Eigen::MatrixXd& a, Eigen::Index p) {
  const Eigen::Index n = a.rows();
  if (a.cols() < n) return kNaN;
  Eigen::MatrixXd phi(n, a.cols());
  for (Eigen::Index r = 0; r < a.cols(); ++r) {
    if (!(a(p, r) > 0.0)) return kNaN;
    phi.col(r) = a.col(r) / std::sqrt(a(p, r));
  }
  const Eigen::MatrixXd minv = phi * phi.transpose();
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(minv);
  if (!lu.isInvertible()) return kNaN;
  const Eigen::MatrixXd m = lu.inverse();
  double worst = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(m(i, i) > 0.0)) return std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < i; ++j)
      worst = std::max(worst, std::abs(m(i, j)) / std::sqrt(m(i, i) * m(j, j)));
  }
  return worst;
}

std::string ModeList(const ModalConstants& c, const std::vector<std::size_t>& modes) {
  std::ostringstream s;
  for (std::size_t k = 0; k < modes.size(); ++k) {
    if (k > 0) s << (k + 1 == modes.size() ? " and " : ", ");
    s << "mode " << modes[k] + 1 << " (" << Hz(c.freq_hz[modes[k]]) << ")";
  }
  return s.str();
}

// Why response j cannot be the driving point, or "" when it can.
std::string Contradiction(const ModalConstants& c, const DrivingPointEvidence& e) {
  if (e.one_sign) return "";
  return "its modal constants are negative in " + ModeList(c, e.negative_modes) +
         " and positive elsewhere, as a cross point's are (a driving point's are positive in "
         "every mode)";
}

}  // namespace

ModalConstants ModalConstantsOf(const Frf& receptance, const ModeIdentification& modes) {
  ModalConstants out;
  out.names = receptance.response_names;
  out.names.resize(receptance.responses());
  std::vector<Eigen::VectorXd> cols;
  std::vector<double> strength;  // the mode's largest receptance peak, |A| / (2 zeta omega^2)
  for (const ModeEstimate& m : modes.modes) {
    if (m.unreliable) continue;
    Eigen::VectorXd a(static_cast<Eigen::Index>(receptance.responses()));
    bool from_fit = false;
    if (modes.fitted && !modes.fit.modes.empty()) {
      const auto nearest = std::min_element(
          modes.fit.modes.begin(), modes.fit.modes.end(), [&](const auto& x, const auto& y) {
            return std::abs(x.freq_hz - m.freq_hz) < std::abs(y.freq_hz - m.freq_hz);
          });
      // The fit's pole and the reported one agree to a fraction of the half-power band.
      if (std::abs(nearest->freq_hz - m.freq_hz) <= 0.02 * m.freq_hz &&
          nearest->residues.size() == a.size()) {
        a = nearest->residues.real();
        from_fit = true;
      }
    }
    if (!from_fit) {
      const Eigen::Index k = NearestLine(receptance.freq_hz, m.freq_hz);
      const double w = m.omega_rad_s;
      a = -2.0 * m.zeta * w * w * receptance.h.row(k).transpose().imag();
    }
    cols.push_back(a);
    out.freq_hz.push_back(m.freq_hz);
    strength.push_back(a.cwiseAbs().maxCoeff() / (2.0 * m.zeta * m.omega_rad_s * m.omega_rad_s));
  }
  // A pole whose resonance is a small fraction of the strongest (a pole far above the structure's
  // modes, where the force barely excites it) says nothing of the hammer point: its constants'
  // signs are noise.
  const double strongest =
      strength.empty() ? 0.0 : *std::max_element(strength.begin(), strength.end());
  std::size_t kept = 0;
  for (std::size_t r = 0; r < cols.size(); ++r) {
    if (!(strength[r] >= kWeakModeFraction * strongest)) continue;
    cols[kept] = cols[r];
    out.freq_hz[kept] = out.freq_hz[r];
    ++kept;
  }
  cols.resize(kept);
  out.freq_hz.resize(kept);
  out.a.resize(static_cast<Eigen::Index>(receptance.responses()),
               static_cast<Eigen::Index>(cols.size()));
  for (std::size_t r = 0; r < cols.size(); ++r) out.a.col(static_cast<Eigen::Index>(r)) = cols[r];
  return out;
}

DrivingPointFinding FindDrivingPoint(const ModalConstants& c) {
  const Eigen::Index n = c.a.rows();
  const Eigen::Index modes = c.a.cols();
  DrivingPointFinding out;
  out.responses.resize(static_cast<std::size_t>(n));
  std::vector<std::size_t> candidates;
  for (Eigen::Index p = 0; p < n; ++p) {
    DrivingPointEvidence& e = out.responses[static_cast<std::size_t>(p)];
    for (Eigen::Index r = 0; r < modes; ++r) {
      const double largest = c.a.col(r).cwiseAbs().maxCoeff();
      if (!(largest > 0.0) || std::abs(c.a(p, r)) < kSignFraction * largest) continue;
      ++e.signed_modes;
      if (c.a(p, r) < 0.0) e.negative_modes.push_back(static_cast<std::size_t>(r));
    }
    e.one_sign = e.negative_modes.empty() && e.signed_modes > 0;
    e.mass_coupling = MassCoupling(c.a, p);
    if (e.one_sign) candidates.push_back(static_cast<std::size_t>(p));
  }
  if (candidates.empty()) {
    out.why =
        "no response's modal constants are positive in every mode, as the driving point's "
        "are: the hammer was on a mass none of the responses measures, or a response's "
        "sign is reversed";
    return out;
  }
  if (candidates.size() == 1) {
    out.fits = candidates.front();
    out.why = "its modal constants alone are positive in every mode";
    return out;
  }
  // Several responses share one sign (too few modes to tell, or a node): the mass matrix decides
  // when every mode is there.
  std::vector<std::size_t> ranked = candidates;
  std::sort(ranked.begin(), ranked.end(), [&](std::size_t x, std::size_t y) {
    const double cx = out.responses[x].mass_coupling;
    const double cy = out.responses[y].mass_coupling;
    if (std::isnan(cx) != std::isnan(cy)) return !std::isnan(cx);
    return cx < cy;
  });
  const double best = out.responses[ranked[0]].mass_coupling;
  const double next = out.responses[ranked[1]].mass_coupling;
  std::ostringstream names;
  for (std::size_t k = 0; k < candidates.size(); ++k)
    names << (k > 0 ? (k + 1 == candidates.size() ? " and " : ", ") : "")
          << ResponseLabel(c, candidates[k]);
  if (std::isfinite(best) &&
      (std::isnan(next) || (next >= kCouplingRatio * best && next >= kCouplingFloor))) {
    out.fits = ranked[0];
    std::ostringstream s;
    s.precision(2);
    s << "of " << names.str()
      << ", whose modal constants are all positive, its shapes give the most nearly diagonal "
         "mass matrix (coupling "
      << best << " against " << next << ")";
    out.why = s.str();
    return out;
  }
  out.why = names.str() + " all have modal constants of one sign in the " + std::to_string(modes) +
            " mode(s) found, and " +
            (modes < n ? "with fewer modes than responses the mass matrix cannot tell them apart"
                       : "their shapes give mass matrices alike");
  return out;
}

DrivingPointChoice ChooseDrivingPoint(const ModalConstants& c,
                                      const std::optional<NamedDrivingPoint>& named) {
  const auto n = static_cast<std::size_t>(c.a.rows());
  DrivingPointChoice out;
  if (n <= 1) {
    out.how = named ? "named" : "found";
    out.note = "driving point: the only response";
    return out;
  }
  Require(c.a.cols() > 0, "no mode to find the driving point from");
  const DrivingPointFinding f = FindDrivingPoint(c);
  if (named) {
    Require(named->index < n, named->source + ": no such response");
    const DrivingPointEvidence& e = f.responses[named->index];
    // Contradicted: a constant of the wrong sign, or (every mode there) another response whose
    // shapes give a mass matrix far nearer diagonal than this one's.
    const bool other_fits_better =
        f.fits && *f.fits != named->index && std::isfinite(f.responses[*f.fits].mass_coupling) &&
        (std::isnan(e.mass_coupling) ||
         (e.mass_coupling >= kCouplingRatio * f.responses[*f.fits].mass_coupling &&
          e.mass_coupling >= kCouplingFloor));
    if (!e.one_sign || other_fits_better) {
      std::string why = named->source + " names " + ResponseLabel(c, named->index) +
                        " as the driving point, but ";
      if (!e.one_sign) {
        why += Contradiction(c, e);
      } else {
        std::ostringstream s;
        s.precision(2);
        s << "the shapes scaled from it give a mass matrix far from diagonal (coupling "
          << e.mass_coupling << ")";
        why += s.str();
      }
      if (f.fits) {
        why += "; the data fit " + ResponseLabel(c, *f.fits) + " (" + f.why +
               "): check which mass the hammer hit, and name response " +
               std::to_string(*f.fits + 1) + " as the driving point";
      } else {
        why += "; " + f.why;
      }
      throw InputError(why);
    }
    out.index = named->index;
    out.how = "named";
    out.note = "driving point " + ResponseLabel(c, out.index) + " from " + named->source +
               (f.fits && *f.fits == named->index ? ", as the data say (" + f.why + ")"
                                                  : ", which the data do not contradict");
  } else {
    if (!f.fits)
      throw InputError(
          "the driving point (the response on the mass the hammer hit) is not "
          "named and the data do not single it out: " +
          f.why + "; name it (--driving-point NAME or INDEX; in Python driving_point=)");
    out.index = *f.fits;
    out.how = "found";
    out.note = "driving point " + ResponseLabel(c, out.index) + ", found from the data: " + f.why;
  }
  // A node near the hammer point: phi_p^2 is small against phi_j phi_p, so the mode's scale
  // (phi_p = sqrt(A_pp)) is as uncertain as that small constant.
  const auto p = static_cast<Eigen::Index>(out.index);
  for (Eigen::Index r = 0; r < c.a.cols(); ++r) {
    if (!(c.a(p, r) > 0.0)) continue;
    const Eigen::VectorXd phi = c.a.col(r) / std::sqrt(c.a(p, r));
    Eigen::Index big = 0;
    const double largest = phi.cwiseAbs().maxCoeff(&big);
    if (big == p || std::abs(phi[p]) >= kNodeFraction * largest) continue;
    std::ostringstream w;
    w.precision(2);
    w << "mode " << r + 1 << " (" << Hz(c.freq_hz[static_cast<std::size_t>(r)])
      << ") has a node near the driving point (|phi| there " << std::abs(phi[p]) / largest
      << " of its largest, at " << ResponseLabel(c, static_cast<std::size_t>(big))
      << "): its scale from this point is poor; hit the mass "
      << ResponseLabel(c, static_cast<std::size_t>(big)) << " measures for it";
    out.warnings.push_back(w.str());
  }
  return out;
}

}  // namespace vibid::ident
