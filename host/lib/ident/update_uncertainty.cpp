// Uncertainty of the stiffness update (methods §7) by the delta method: the update map's Jacobian
// applied to the modes' intervals and the masses' uncertainties, the modal tests as repeats.
#include <cmath>
#include <string>
#include <vector>

#include "vibid/common/error.hpp"
#include "vibid/ident/updates.hpp"

namespace vibid::ident {

Uncertainty ModeIntervalUncertainty(const std::array<double, 2>& ci95) {
  if (!std::isfinite(ci95[0]) || !std::isfinite(ci95[1])) {
    return Uncertainty::Missing(
        "the modes carry no intervals (--method fit or peaks, or no modal model)");
  }
  Uncertainty u;
  const double sd = 0.5 * (ci95[1] - ci95[0]) / kZ95;
  u.variance = sd * sd;
  u.basis = "modal covariance";
  if (!(u.variance > 0.0)) u.missing = "a mode's interval has zero width";
  return u;
}

namespace {

// One test's springs and dampers, each with its uncertainty from the test's modes alone (masses
// held), and the Jacobian's mass columns for the masses' share.
struct TestSensitivity {
  std::vector<double> values;      // springs (n), then dampers (n)
  std::vector<Uncertainty> modal;  // per value
  Eigen::MatrixXd d_masses;        // 2n x n
};

TestSensitivity SensitivityOfTest(const Eigen::VectorXd& masses,
                                  const std::vector<ModeEstimate>& modes,
                                  const StiffnessUpdateResult& update) {
  const Eigen::Index n = masses.size();
  Require(static_cast<Eigen::Index>(modes.size()) == n, "stiffness uncertainty: one mode per mass");
  Eigen::VectorXd omega(n), zeta(n);
  Eigen::MatrixXd shapes(n, n);
  std::vector<Eigen::Index> columns;
  std::vector<Uncertainty> parts;
  for (Eigen::Index i = 0; i < n; ++i) {
    const ModeEstimate& m = modes[static_cast<std::size_t>(i)];
    omega[i] = m.omega_rad_s;
    zeta[i] = m.zeta;
    columns.push_back(n + i);
    parts.push_back(ModeIntervalUncertainty(m.omega_ci95_rad_s));
    columns.push_back(2 * n + i);
    parts.push_back(ModeIntervalUncertainty(m.zeta_ci95));
    if (n == 1) {
      shapes(0, 0) = 1.0;  // a single mode's shape is its normalisation alone
      continue;
    }
    columns.push_back(3 * n + i * n);
    if (n != 2) {
      Require(m.shape.size() == n, "stiffness uncertainty: a shape entry per mass");
      shapes.col(i) = m.shape;
      parts.push_back(Uncertainty::Missing("shapes of more than two responses carry no intervals"));
      continue;
    }
    // The update normalises each shape, so only its direction a1/a2 counts: shape [a1/a2, 1],
    // and a1/a2's uncertainty is the first entry's.
    if (std::isfinite(m.ratio)) {
      shapes.col(i) << m.ratio, 1.0;
    } else {
      Require(m.shape.size() == 2, "stiffness uncertainty: a shape or a ratio per mode");
      shapes.col(i) = m.shape;
    }
    parts.push_back(ModeIntervalUncertainty(m.ratio_ci95));
  }
  const Eigen::MatrixXd jac = StiffnessJacobian(masses, omega, zeta, shapes);
  TestSensitivity out;
  out.d_masses = jac.leftCols(n);
  for (Eigen::Index o = 0; o < 2 * n; ++o) {
    out.values.push_back(o < n ? update.springs[o] : update.dampers[o - n]);
    std::vector<double> g;
    for (Eigen::Index c : columns) g.push_back(jac(o, c));
    out.modal.push_back(Propagate(g, parts, "modal covariance"));
  }
  return out;
}

}  // namespace

ChainUncertainty StiffnessUncertainty(const Eigen::VectorXd& masses_kg,
                                      const std::vector<Uncertainty>& masses_u,
                                      const std::vector<std::vector<ModeEstimate>>& modes,
                                      const std::vector<StiffnessUpdateResult>& updates) {
  const Eigen::Index n = masses_kg.size();
  Require(static_cast<Eigen::Index>(masses_u.size()) == n,
          "stiffness uncertainty: one mass uncertainty per mass");
  Require(!updates.empty() && modes.size() == updates.size(),
          "stiffness uncertainty: the modes of every test");
  std::vector<TestSensitivity> tests;
  for (std::size_t t = 0; t < updates.size(); ++t)
    tests.push_back(SensitivityOfTest(masses_kg, modes[t], updates[t]));
  ChainUncertainty out;
  for (Eigen::Index o = 0; o < 2 * n; ++o) {
    const auto uo = static_cast<std::size_t>(o);
    std::vector<double> values;
    std::vector<Uncertainty> each;
    Eigen::VectorXd d_masses = Eigen::VectorXd::Zero(n);
    for (const TestSensitivity& t : tests) {
      values.push_back(t.values[uo]);
      each.push_back(t.modal[uo]);
      d_masses += t.d_masses.row(o).transpose() / static_cast<double>(tests.size());
    }
    const MeanOfTests modal = MeanOfRepeats(values, each, "modal tests");
    std::vector<double> g{1.0};
    std::vector<Uncertainty> parts{modal.uncertainty};
    std::string mass_basis;
    for (Eigen::Index p = 0; p < n; ++p) {
      g.push_back(d_masses[p]);
      parts.push_back(masses_u[static_cast<std::size_t>(p)]);
      if (mass_basis.empty() && (masses_u[static_cast<std::size_t>(p)].Known() ||
                                 masses_u[static_cast<std::size_t>(p)].Exact()))
        mass_basis = masses_u[static_cast<std::size_t>(p)].basis;
    }
    const Uncertainty u = Propagate(g, parts, modal.uncertainty.basis + "; masses: " + mass_basis);
    (o < n ? out.springs : out.dampers).push_back(u);
  }
  return out;
}

}  // namespace vibid::ident
