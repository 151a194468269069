// The validation table: the nominal model, the updated one and the tests side by side (modes,
// shapes, what each parameter moved), and its text.
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "vibid/ident/identify.hpp"
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

namespace {

// Shape scaled to 1 at the driving point; empty when it cannot be.
Eigen::VectorXd ScaledShape(const Eigen::VectorXd& shape, std::size_t driving_point) {
  const auto p = static_cast<Eigen::Index>(driving_point);
  if (p >= shape.size() || shape[p] == 0.0 || !shape.allFinite()) return {};
  return shape / shape[p];
}

}  // namespace

double ModalDeviationPercent(const model::Model& model, const std::vector<ModeEstimate>& test_modes,
                             const std::vector<Eigen::Index>& chain_modes,
                             std::size_t driving_point) {
  const model::ModalResult mr = model::Modal(model);
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < test_modes.size(); ++i) {
    const Eigen::Index cm = chain_modes.empty() ? static_cast<Eigen::Index>(i) : chain_modes[i];
    if (cm >= mr.size()) continue;
    const double dw = PercentDeviation(mr.omega_rad_s[cm], test_modes[i].omega_rad_s);
    double dphi = 0.0;
    const Eigen::VectorXd t = ScaledShape(test_modes[i].shape, driving_point);
    const Eigen::VectorXd m = ScaledShape(mr.shapes.col(cm), driving_point);
    if (t.size() == m.size() && t.size() > 0) dphi = 100.0 * (m - t).norm() / t.norm();
    sum += dw * dw + dphi * dphi;
    ++count;
  }
  return count > 0 ? std::sqrt(sum / static_cast<double>(count))
                   : std::numeric_limits<double>::quiet_NaN();
}

ValidationTable BuildValidationTable(const model::Model& nominal, const model::Model& updated,
                                     const std::vector<ModeEstimate>& test_modes,
                                     const std::vector<Eigen::Index>& chain_modes,
                                     std::size_t driving_point) {
  const model::ModalResult mn = model::Modal(nominal);
  const model::ModalResult mu = model::Modal(updated);
  const model::ComplexModes cn = model::ComplexModalDamping(nominal);
  const model::ComplexModes cu = model::ComplexModalDamping(updated);
  ValidationTable t;
  const auto count = std::min<std::size_t>(test_modes.size(), static_cast<std::size_t>(mn.size()));
  for (std::size_t i = 0; i < count; ++i) {
    const Eigen::Index ii = chain_modes.empty() ? static_cast<Eigen::Index>(i) : chain_modes[i];
    if (ii >= mn.size()) continue;
    ModeComparison r;
    r.mode = static_cast<std::size_t>(ii);
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
    r.shape_test = ScaledShape(test_modes[i].shape, driving_point);
    if (r.shape_test.size() == mn.shapes.rows()) {
      r.shape_nominal = ScaledShape(mn.shapes.col(ii), driving_point);
      r.shape_updated = ScaledShape(mu.shapes.col(ii), driving_point);
    } else {
      r.shape_test.resize(0);
    }
    t.modes.push_back(r);
  }
  const ChainParameters a = ChainOf(nominal);
  const ChainParameters b = ChainOf(updated);
  for (Eigen::Index i = 0; i < a.masses_kg.size(); ++i) {
    PositionComparison p;
    p.m_nominal = a.masses_kg[i];
    p.m_updated = b.masses_kg[i];
    p.k_nominal = a.springs_n_per_m[i];
    p.k_updated = b.springs_n_per_m[i];
    p.c_updated = b.dampers_ns_per_m[i];
    t.positions.push_back(p);
  }
  t.deviation.nominal_percent =
      ModalDeviationPercent(nominal, test_modes, chain_modes, driving_point);
  t.deviation.updated_percent =
      ModalDeviationPercent(updated, test_modes, chain_modes, driving_point);
  t.deviation.worse_than_nominal = t.deviation.updated_percent > t.deviation.nominal_percent;
  return t;
}

namespace {

void PositionRows(const std::vector<PositionComparison>& positions, const char* column,
                  std::ostringstream& out) {
  char line[512];
  bool sources = false;
  for (const PositionComparison& p : positions) sources = sources || !p.m_source.empty();
  std::snprintf(line, sizeof line, "%-5s %-12s %12s %12s %9s  %s%s\n", "pos", "quantity", "nominal",
                column, "change%", "95 % interval", sources ? "  [from]" : "");
  out << line;
  const auto from = [sources](const std::string& s) {
    return sources ? "  [" + s + "]" : std::string();
  };
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const PositionComparison& p = positions[i];
    std::snprintf(line, sizeof line, "%-5zu %-12s %12.6g %12.6g %9.2f  %s%s\n", i + 1, "m_kg",
                  p.m_nominal, p.m_updated, PercentDeviation(p.m_updated, p.m_nominal),
                  FormatInterval(p.m_ci95, p.m_updated).c_str(), from(p.m_source).c_str());
    out << line;
    std::snprintf(line, sizeof line, "%-5zu %-12s %12.6g %12.6g %9.2f  %s%s\n", i + 1, "k_n_per_m",
                  p.k_nominal, p.k_updated, PercentDeviation(p.k_updated, p.k_nominal),
                  FormatInterval(p.k_ci95, p.k_updated).c_str(), from(p.k_source).c_str());
    out << line;
    std::snprintf(line, sizeof line, "%-5zu %-12s %12s %12.6g %9s  %s%s\n", i + 1, "c_ns_per_m", "",
                  p.c_updated, "", FormatInterval(p.c_ci95, p.c_updated).c_str(),
                  from(p.c_source).c_str());
    out << line;
  }
}

}  // namespace

std::string FormatValidationTable(const ValidationTable& t) {
  std::ostringstream out;
  char line[512];
  out << "Modes (deviation of each model from the test)\n";
  std::snprintf(line, sizeof line, "%-5s %-9s %12s %12s %12s %9s %9s\n", "mode", "quantity",
                "nominal", "updated", "test", "nom dev%", "upd dev%");
  out << line;
  for (const ModeComparison& r : t.modes) {
    struct Row {
      std::string name;
      double n, u, x;
    };
    std::vector<Row> rows = {{"omega", r.omega_nominal, r.omega_updated, r.omega_test},
                             {"zeta", r.zeta_nominal, r.zeta_updated, r.zeta_test}};
    if (r.shape_test.size() > 2) {
      // Each shape entry against the driving point's.
      Eigen::Index p = 0;
      for (Eigen::Index j = 0; j < r.shape_test.size(); ++j)
        if (r.shape_test[j] == 1.0) p = j;
      for (Eigen::Index j = 0; j < r.shape_test.size(); ++j) {
        if (j == p) continue;
        rows.push_back({"a" + std::to_string(j + 1) + "/a" + std::to_string(p + 1),
                        r.shape_nominal[j], r.shape_updated[j], r.shape_test[j]});
      }
    } else {
      rows.push_back({"a1/a2", r.ratio_nominal, r.ratio_updated, r.ratio_test});
    }
    for (const Row& row : rows) {
      std::snprintf(line, sizeof line, "%-5zu %-9s %12.6g %12.6g %12.6g %9.2f %9.2f\n", r.mode + 1,
                    row.name.c_str(), row.n, row.u, row.x, PercentDeviation(row.n, row.x),
                    PercentDeviation(row.u, row.x));
      out << line;
    }
  }
  out << "Positions (change from nominal, 95 % interval of the updated value";
  if (!t.method.empty()) out << "; " << t.method;
  out << ")\n";
  PositionRows(t.positions, "updated", out);
  if (!t.beside.empty()) {
    out << "Beside: " << t.beside_method << "\n";
    PositionRows(t.beside, "beside", out);
  }
  std::snprintf(line, sizeof line,
                "Modal deviation from the test (rms of omega and shape, %%): nominal %.3g, "
                "updated %.3g",
                t.deviation.nominal_percent, t.deviation.updated_percent);
  out << line;
  if (!t.beside.empty()) {
    std::snprintf(line, sizeof line, ", beside %.3g", t.beside_deviation.updated_percent);
    out << line;
  }
  out << "\n";
  if (!t.caution.empty()) out << "CAUTION: " << t.caution << "\n";
  if (t.deviation.worse_than_nominal) {
    out << "FLAGGED: the updated model fits its own test worse than the nominal model; do not use "
           "it (longer records, more hits, or the other method)\n";
  }
  return out.str();
}

}  // namespace vibid::ident
