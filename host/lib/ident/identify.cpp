#include "vibid/ident/identify.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>

#include "vibid/common/error.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::ident {

ChainParameters ChainOf(const model::Model& m) {
  const Eigen::Index n = m.m_kg.rows();
  ChainParameters c;
  c.masses_kg = m.m_kg.diagonal();
  c.springs_n_per_m.resize(n);
  c.dampers_ns_per_m.resize(n);
  c.springs_n_per_m[n - 1] = m.k_n_per_m(n - 1, n - 1);
  c.dampers_ns_per_m[n - 1] = m.c_ns_per_m(n - 1, n - 1);
  for (Eigen::Index i = n - 2; i >= 0; --i) {
    c.springs_n_per_m[i] = m.k_n_per_m(i, i) - c.springs_n_per_m[i + 1];
    c.dampers_ns_per_m[i] = m.c_ns_per_m(i, i) - c.dampers_ns_per_m[i + 1];
  }
  return c;
}

double PercentDeviation(double value, double reference) {
  if (reference == 0.0 || !std::isfinite(reference) || !std::isfinite(value))
    return std::numeric_limits<double>::quiet_NaN();
  return 100.0 * (value - reference) / reference;
}

ValidationTable BuildValidationTable(const model::Model& nominal, const model::Model& updated,
                                     const std::vector<ModeEstimate>& test_modes) {
  const model::ModalResult mn = model::Modal(nominal);
  const model::ModalResult mu = model::Modal(updated);
  const model::ComplexModes cn = model::ComplexModalDamping(nominal);
  const model::ComplexModes cu = model::ComplexModalDamping(updated);
  ValidationTable t;
  const auto count = std::min<std::size_t>(test_modes.size(), static_cast<std::size_t>(mn.size()));
  for (std::size_t i = 0; i < count; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    ModeComparison r;
    r.omega_nominal = mn.omega_rad_s[ii];
    r.omega_updated = mu.omega_rad_s[ii];
    r.omega_test = test_modes[i].omega_rad_s;
    // General damping: take zeta from the state matrix's eigenvalues (equal to the modal value for
    // proportional damping).
    r.zeta_nominal = ii < cn.zeta.size() ? cn.zeta[ii] : mn.zeta[ii];
    r.zeta_updated = ii < cu.zeta.size() ? cu.zeta[ii] : mu.zeta[ii];
    r.zeta_test = test_modes[i].zeta;
    r.ratio_nominal =
        mn.ratio.size() > ii ? mn.ratio[ii] : std::numeric_limits<double>::quiet_NaN();
    r.ratio_updated =
        mu.ratio.size() > ii ? mu.ratio[ii] : std::numeric_limits<double>::quiet_NaN();
    r.ratio_test = test_modes[i].ratio;
    t.modes.push_back(r);
  }
  const ChainParameters a = ChainOf(nominal);
  const ChainParameters b = ChainOf(updated);
  for (Eigen::Index i = 0; i < a.masses_kg.size(); ++i) {
    t.positions.push_back({a.masses_kg[i], b.masses_kg[i], a.springs_n_per_m[i],
                           b.springs_n_per_m[i], b.dampers_ns_per_m[i]});
  }
  return t;
}

std::string FormatValidationTable(const ValidationTable& t) {
  std::ostringstream out;
  char line[512];
  out << "Modes (deviation of each model from the test)\n";
  std::snprintf(line, sizeof line, "%-5s %-9s %12s %12s %12s %9s %9s\n", "mode", "quantity",
                "nominal", "updated", "test", "nom dev%", "upd dev%");
  out << line;
  for (std::size_t i = 0; i < t.modes.size(); ++i) {
    const ModeComparison& r = t.modes[i];
    const struct {
      const char* name;
      double n, u, x;
    } rows[] = {{"omega", r.omega_nominal, r.omega_updated, r.omega_test},
                {"zeta", r.zeta_nominal, r.zeta_updated, r.zeta_test},
                {"a1/a2", r.ratio_nominal, r.ratio_updated, r.ratio_test}};
    for (const auto& row : rows) {
      std::snprintf(line, sizeof line, "%-5zu %-9s %12.6g %12.6g %12.6g %9.2f %9.2f\n", i + 1,
                    row.name, row.n, row.u, row.x, PercentDeviation(row.n, row.x),
                    PercentDeviation(row.u, row.x));
      out << line;
    }
  }
  out << "Positions (change from nominal, 95 % interval of the updated value)\n";
  std::snprintf(line, sizeof line, "%-5s %-12s %12s %12s %9s  %s\n", "pos", "quantity", "nominal",
                "updated", "change%", "95 % interval");
  out << line;
  for (std::size_t i = 0; i < t.positions.size(); ++i) {
    const PositionComparison& p = t.positions[i];
    std::snprintf(line, sizeof line, "%-5zu %-12s %12.6g %12.6g %9.2f  %s\n", i + 1, "m_kg",
                  p.m_nominal, p.m_updated, PercentDeviation(p.m_updated, p.m_nominal),
                  FormatInterval(p.m_ci95, p.m_updated).c_str());
    out << line;
    std::snprintf(line, sizeof line, "%-5zu %-12s %12.6g %12.6g %9.2f  %s\n", i + 1, "k_n_per_m",
                  p.k_nominal, p.k_updated, PercentDeviation(p.k_updated, p.k_nominal),
                  FormatInterval(p.k_ci95, p.k_updated).c_str());
    out << line;
    std::snprintf(line, sizeof line, "%-5zu %-12s %12s %12.6g %9s  %s\n", i + 1, "c_ns_per_m", "",
                  p.c_updated, "", FormatInterval(p.c_ci95, p.c_updated).c_str());
    out << line;
  }
  return out.str();
}

namespace {

// A given spring fixes m = k / omega^2; the FRF's level (1/k below the resonance) says what k
// the test saw. When that disagrees with the given k beyond its interval, the mass is off by the
// same factor: say so, with the way out.
void CheckGivenSpring(const MassTestInput& mt, const MassUpdateOptions& given,
                      const MassUpdateResult& held, IdentifyResult& res) {
  MassUpdateOptions free = given;
  free.k_n_per_m = 0.0;
  MassUpdateResult fitted;
  try {
    fitted = UpdateMass(mt.receptance, 0, free);
  } catch (const InputError&) {
    return;
  }
  const Interval95 k = IntervalOf(fitted.k_n_per_m, fitted.k_u);
  if (!fitted.summary.Converged() || !k.Known()) return;
  if (given.k_n_per_m >= k.lo && given.k_n_per_m <= k.hi) return;
  char text[320];
  std::snprintf(text, sizeof text,
                "mass test %zu: its FRF's level says the spring is %.6g N/m (95 %%: %.4g to "
                "%.4g), not the %.6g N/m given; the mass %.6g kg is off by as much (--mass-spring "
                "%zu=fit fits the spring with the mass: %.6g kg)",
                mt.position + 1, fitted.k_n_per_m, k.lo, k.hi, given.k_n_per_m, held.mass_kg,
                mt.position + 1, fitted.mass_kg);
  res.warnings.push_back(text);
}

// Each mass test's fitted mass replaces the nominal one in `res.chain`.
void UpdateMasses(const ChainParameters& nominal_chain,
                  const std::vector<MassTestInput>& mass_tests, const IdentifyOptions& options,
                  IdentifyResult& res) {
  const Eigen::Index n = nominal_chain.masses_kg.size();
  const auto un = static_cast<std::size_t>(n);
  std::vector<std::vector<double>> masses(un);
  std::vector<std::vector<Uncertainty>> each(un);
  for (const MassTestInput& mt : mass_tests) {
    Require(mt.position < un, "identify: mass test for position " +
                                  std::to_string(mt.position + 1) + ", the model has " +
                                  std::to_string(n));
    MassUpdateOptions mo = options.mass;
    const auto pos = static_cast<Eigen::Index>(mt.position);
    mo.k_n_per_m = mt.fit_spring        ? 0.0
                   : mt.k_n_per_m > 0.0 ? mt.k_n_per_m
                                        : nominal_chain.springs_n_per_m[pos];
    mo.nominal_kg = nominal_chain.masses_kg[pos];
    MassTestResult r{mt.position, UpdateMass(mt.receptance, 0, mo)};
    if (!r.update.summary.Converged()) {
      throw InputError("identify: mass test " + std::to_string(mt.position + 1) +
                       ": fit did not converge (" + r.update.summary.message + ")");
    }
    for (const auto& w : r.update.warnings)
      res.warnings.push_back("mass test " + std::to_string(mt.position + 1) + ": " + w);
    if (!r.update.stiffness_fitted) CheckGivenSpring(mt, mo, r.update, res);
    masses[mt.position].push_back(r.update.mass_kg);
    each[mt.position].push_back(r.update.mass_u);
    res.mass_tests.push_back(r);
  }
  for (std::size_t p = 0; p < un; ++p) {
    if (masses[p].empty()) {
      res.uncertainty[p].m_kg = Uncertainty::Missing("no mass test: the nominal mass");
      continue;
    }
    const MeanOfTests mean = MeanOfRepeats(masses[p], each[p], "mass tests");
    res.chain.masses_kg[static_cast<Eigen::Index>(p)] = mean.mean;
    res.uncertainty[p].m_kg = mean.uncertainty;
  }
}

// The modes of every modal test, kept in `res.modal_tests`, and the stiffness update of each.
std::vector<StiffnessUpdateResult> UpdateStiffnessPerTest(const std::vector<Frf>& modal_tests,
                                                          const IdentifyOptions& options,
                                                          Eigen::Index n, IdentifyResult& res) {
  std::vector<StiffnessUpdateResult> updates;
  for (std::size_t t = 0; t < modal_tests.size(); ++t) {
    const std::string name = "modal test " + std::to_string(t + 1);
    // A chain of n masses has n modes: keep the n clearest resonances unless told otherwise.
    ModeIdentificationOptions mo = options.modes;
    if (mo.peaks.max_peaks == 0) mo.peaks.max_peaks = static_cast<std::size_t>(n);
    ModeIdentification mi = IdentifyModes(modal_tests[t], options.driving_point, mo);
    for (const auto& w : mi.warnings) res.warnings.push_back(name + ": " + w);
    Require(static_cast<Eigen::Index>(mi.modes.size()) == n,
            "identify: " + name + " shows " + std::to_string(mi.modes.size()) +
                " modes, the model has " + std::to_string(n) + " (set the band or --max-modes)");
    Require(static_cast<Eigen::Index>(modal_tests[t].responses()) == n,
            "identify: " + name + " needs one response per mass (" + std::to_string(n) + ")");
    Eigen::VectorXd omega(n), zeta(n);
    Eigen::MatrixXd shapes(n, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const ModeEstimate& m = mi.modes[static_cast<std::size_t>(i)];
      omega[i] = m.omega_rad_s;
      zeta[i] = m.zeta;
      shapes.col(i) = m.shape;
    }
    updates.push_back(UpdateStiffness(res.chain.masses_kg, omega, zeta, shapes));
    res.modal_tests.push_back(std::move(mi));
  }
  return updates;
}

// Interval of the mean over the tests, the tests taken as repeats (intervals.hpp). `out` is left
// as it is (no interval) when none can be estimated.
template <typename ValueOf, typename CiOf>
void MeanInterval(const std::vector<ModeIdentification>& tests, std::size_t i, ValueOf value_of,
                  CiOf ci_of, double mean, std::array<double, 2>& out) {
  std::vector<double> values;
  std::vector<Uncertainty> each;
  for (const auto& mt : tests) {
    values.push_back(value_of(mt.modes[i]));
    each.push_back(ModeIntervalUncertainty(ci_of(mt.modes[i])));
  }
  const Interval95 ci = IntervalOf(mean, MeanOfRepeats(values, each, "modal tests").uncertainty);
  if (ci.Known()) out = {ci.lo, ci.hi};
}

// Mode i of every test is the same physical mode.
std::vector<ModeEstimate> AverageTestModes(const std::vector<ModeIdentification>& tests) {
  std::vector<ModeEstimate> modes = tests.front().modes;
  for (std::size_t i = 0; i < modes.size(); ++i) {
    ModeEstimate& avg = modes[i];
    avg.omega_rad_s = avg.zeta = 0.0;
    avg.shape.setZero();
    for (const auto& mt : tests) {
      avg.omega_rad_s += mt.modes[i].omega_rad_s;
      avg.zeta += mt.modes[i].zeta;
      avg.shape += mt.modes[i].shape;
    }
    const auto count = static_cast<double>(tests.size());
    avg.omega_rad_s /= count;
    avg.zeta /= count;
    avg.shape /= count;
    avg.freq_hz = avg.omega_rad_s / (2.0 * std::numbers::pi);
    avg.ratio = avg.shape.size() == 2 && avg.shape[1] != 0.0
                    ? avg.shape[0] / avg.shape[1]
                    : std::numeric_limits<double>::quiet_NaN();
    MeanInterval(
        tests, i, [](const ModeEstimate& m) { return m.omega_rad_s; },
        [](const ModeEstimate& m) -> const std::array<double, 2>& { return m.omega_ci95_rad_s; },
        avg.omega_rad_s, avg.omega_ci95_rad_s);
    MeanInterval(
        tests, i, [](const ModeEstimate& m) { return m.zeta; },
        [](const ModeEstimate& m) -> const std::array<double, 2>& { return m.zeta_ci95; }, avg.zeta,
        avg.zeta_ci95);
    MeanInterval(
        tests, i, [](const ModeEstimate& m) { return m.ratio; },
        [](const ModeEstimate& m) -> const std::array<double, 2>& { return m.ratio_ci95; },
        avg.ratio, avg.ratio_ci95);
  }
  return modes;
}

}  // namespace

IdentifyResult Identify(const model::Model& nominal, const std::vector<MassTestInput>& mass_tests,
                        const std::vector<Frf>& modal_tests, const IdentifyOptions& options) {
  model::Validate(nominal);
  const Eigen::Index n = nominal.m_kg.rows();
  Require(n >= 2, "identify: the nominal model must have at least 2 masses");
  Require(nominal.m_kg.isDiagonal(),
          "identify: the nominal model needs a diagonal mass matrix (a chain)");
  Require(!modal_tests.empty(), "identify: at least one modal test is needed");
  const ChainParameters nominal_chain = ChainOf(nominal);
  IdentifyResult res;
  res.chain = nominal_chain;
  res.uncertainty.resize(static_cast<std::size_t>(n));
  UpdateMasses(nominal_chain, mass_tests, options, res);
  const std::vector<StiffnessUpdateResult> updates =
      UpdateStiffnessPerTest(modal_tests, options, n, res);
  res.stiffness = AverageStiffness(updates);
  res.chain.springs_n_per_m = res.stiffness.springs;
  res.chain.dampers_ns_per_m = res.stiffness.dampers;
  res.test_modes = AverageTestModes(res.modal_tests);
  Require((res.chain.springs_n_per_m.array() > 0.0).all(),
          "identify: the test data give a non-positive chain spring; the chain topology does not "
          "explain the tests");
  Eigen::VectorXd dampers = res.chain.dampers_ns_per_m.cwiseMax(0.0);
  if ((res.chain.dampers_ns_per_m.array() < 0.0).any()) {
    res.warnings.push_back("a negative chain damper from the test damping was set to zero");
  }
  std::vector<Uncertainty> mass_u;
  for (const PositionUncertainty& u : res.uncertainty) mass_u.push_back(u.m_kg);
  std::vector<std::vector<ModeEstimate>> modes;
  for (const ModeIdentification& mi : res.modal_tests) modes.push_back(mi.modes);
  const ChainUncertainty chain_u =
      StiffnessUncertainty(res.chain.masses_kg, mass_u, modes, updates);
  for (std::size_t i = 0; i < res.uncertainty.size(); ++i) {
    res.uncertainty[i].k_n_per_m = chain_u.springs[i];
    res.uncertainty[i].c_ns_per_m = chain_u.dampers[i];
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (res.chain.dampers_ns_per_m[i] < 0.0) {
      res.uncertainty[static_cast<std::size_t>(i)].c_ns_per_m =
          Uncertainty::Missing("a negative estimate, set to zero");
    }
  }
  res.chain.dampers_ns_per_m = dampers;
  res.updated =
      model::MakeChain(res.chain.masses_kg, res.chain.springs_n_per_m, res.chain.dampers_ns_per_m);
  res.table = BuildValidationTable(nominal, res.updated, res.test_modes);
  for (std::size_t i = 0; i < res.table.positions.size(); ++i) {
    PositionComparison& p = res.table.positions[i];
    p.m_ci95 = IntervalOf(p.m_updated, res.uncertainty[i].m_kg);
    p.k_ci95 = IntervalOf(p.k_updated, res.uncertainty[i].k_n_per_m);
    p.c_ci95 = IntervalOf(p.c_updated, res.uncertainty[i].c_ns_per_m);
  }
  return res;
}

}  // namespace vibid::ident
