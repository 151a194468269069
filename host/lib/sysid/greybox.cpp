#include "vibid/sysid/greybox.hpp"

#include <algorithm>
#include <cmath>

#include "vibid/common/error.hpp"
#include "vibid/sysid/fit.hpp"

namespace vibid::sysid {

std::vector<std::string> CartParameterNames(const CartConfig& config) {
  std::vector<std::string> names = config.carts == 1
                                       ? std::vector<std::string>{"M", "B", "k"}
                                       : std::vector<std::string>{"M1", "M2", "B1", "B2", "k"};
  if (config.input == CartInput::kPosition) names.emplace_back("Bi");
  return names;
}

TransferFunction CartTf(const CartConfig& config, Eigen::Ref<const Eigen::VectorXd> v) {
  Require(config.carts == 1 || config.carts == 2, "cart model: 1 or 2 carts");
  Require(static_cast<std::size_t>(v.size()) == CartParameterNames(config).size(),
          "cart model: wrong parameter count");
  const bool position = config.input == CartInput::kPosition;
  const Eigen::Index n = config.carts;
  const Eigen::VectorXd masses = n == 1 ? Eigen::VectorXd(v.head(1)) : Eigen::VectorXd(v.head(2));
  const Eigen::VectorXd frictions =
      n == 1 ? Eigen::VectorXd(v.segment(1, 1)) : Eigen::VectorXd(v.segment(2, 2));
  const double k = v[2 * n];
  const model::TransferFunction tf =
      model::CartTrackTf(masses, k, frictions, config.input, position ? v[2 * n + 1] : 0.0);
  return TransferFunction{tf.num, tf.den};
}

void GreyboxOptions::Validate() const {
  Require(config.carts == 1 || config.carts == 2, "greybox: the cart model has 1 or 2 carts");
  const auto names = CartParameterNames(config);
  for (const auto& [name, value] : fixed) {
    bool known = false;
    for (const auto& n : names) known = known || n == name;
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    Require(known, "greybox: unknown parameter '" + name +
                       "' for this cart model (parameters: " + list + ")");
    Require(std::isfinite(value) && value >= 0.0,
            "greybox: fixed value of " + name + " must be a number >= 0");
  }
  Require(fixed.size() < names.size(), "greybox: every parameter is fixed, nothing to estimate");
  if (config.input == CartInput::kPosition) {
    bool scale = false;
    for (const char* n : {"M", "M1", "M2", "k"}) scale = scale || fixed.count(n) > 0;
    Require(scale,
            "greybox: with a position input the data fix only ratios to the mass; fix M (or M1/M2) "
            "or k");
  }
  solver.Validate();
}

namespace {

/// Start values from a free continuous-time fit of the same orders (see the header's formulas).
Eigen::VectorXd StartValues(const CartConfig& c, const TransferFunction& free_tf,
                            const std::map<std::string, double>& fixed) {
  const TransferFunction t = Normalized(free_tf);
  const Eigen::VectorXd& a = t.den;  // a[0] = 1
  const Eigen::VectorXd& b = t.num;
  auto fixed_or = [&](const std::string& name, double fallback) {
    const auto it = fixed.find(name);
    return it != fixed.end() ? it->second : fallback;
  };
  const bool position = c.input == CartInput::kPosition;
  if (c.carts == 1) {
    // a = [1, B/M, 2k/M]; force: b = [1/M]; position: b = [Bi/M, 2k/M].
    const double two_k_over_m = a[2];
    double m = position ? 1.0 : 1.0 / b[b.size() - 1];
    if (fixed.count("k") > 0 && fixed.count("M") == 0) m = 2.0 * fixed.at("k") / two_k_over_m;
    m = fixed_or("M", m);
    Eigen::VectorXd v(position ? 4 : 3);
    v[0] = m;
    v[1] = fixed_or("B", std::max(a[1] * m, 1e-6));
    v[2] = fixed_or("k", two_k_over_m * m / 2.0);
    if (position) v[3] = fixed_or("Bi", std::max(b.size() > 1 ? b[0] * m : 0.0, 1e-6));
    return v;
  }
  // Two carts, symmetric guess M1 = M2 = M, B1 = B2 = B: a3 = 2B/M, a2 ≈ 4k/M.
  const double k_over_m = a[2] / 4.0;
  double m = position ? 1.0 : 1.0 / std::abs(b[0]);
  if (fixed.count("k") > 0) m = fixed.at("k") / k_over_m;
  if (fixed.count("M1") > 0) m = fixed.at("M1");
  if (fixed.count("M2") > 0) m = fixed.at("M2");
  Eigen::VectorXd v(position ? 6 : 5);
  v[0] = fixed_or("M1", m);
  v[1] = fixed_or("M2", m);
  v[2] = fixed_or("B1", std::max(a[1] * m / 2.0, 1e-6));
  v[3] = fixed_or("B2", std::max(a[1] * m / 2.0, 1e-6));
  v[4] = fixed_or("k", k_over_m * m);
  if (position) v[5] = fixed_or("Bi", std::max(b[0] * v[0], 1e-6));
  return v;
}

Eigen::VectorXd MonicCoefficients(const CartConfig& c, const Eigen::VectorXd& values) {
  const TransferFunction t = CartTf(c, values);
  const Eigen::Index n = t.den.size() - 1;
  Eigen::VectorXd coef(n + t.num.size());
  coef << t.den.tail(n) / t.den[0], t.num / t.den[0];
  return coef;
}

}  // namespace

GreyboxResult EstimateCart(const IoData& data, const GreyboxOptions& options) {
  options.Validate();
  const CartConfig& c = options.config;
  const auto names = CartParameterNames(c);
  const int np = 2 * c.carts;
  const int nz = c.carts == 1 ? (c.input == CartInput::kPosition ? 1 : 0)
                              : (c.input == CartInput::kPosition ? 3 : 2);

  TfestOptions free_options;
  free_options.np = np;
  free_options.nz = nz;
  free_options.solver = options.solver;
  const TfestResult free_fit = EstimateTf(data, free_options);
  GreyboxResult res;
  Require(free_fit.tf.den.size() == np + 1,
          "greybox: the free continuous-time fit found no starting model");
  const Eigen::VectorXd start = StartValues(c, free_fit.tf, options.fixed);
  res.initialization =
      "tfest(np=" + std::to_string(np) + ", nz=" + std::to_string(nz) + ") mapped to parameters";

  std::vector<Eigen::Index> free_index;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (options.fixed.count(names[i]) == 0) free_index.push_back(static_cast<Eigen::Index>(i));
  }
  const auto q = static_cast<Eigen::Index>(free_index.size());
  auto full = [&](const Eigen::VectorXd& theta) {
    Eigen::VectorXd v = start;
    for (Eigen::Index i = 0; i < q; ++i) v[free_index[static_cast<std::size_t>(i)]] = theta[i];
    return v;
  };
  CtParameterization param;
  param.np = np;
  param.nz = nz;
  param.map = [&](const Eigen::VectorXd& theta, Eigen::VectorXd& coef, Eigen::MatrixXd* jac) {
    if ((theta.array() <= 0.0).any()) return false;  // masses, frictions and springs are positive
    coef = MonicCoefficients(c, full(theta));
    if (jac != nullptr) {
      // The map is a few products and one division: central differences are accurate to ~1e-10.
      jac->resize(coef.size(), q);
      for (Eigen::Index i = 0; i < q; ++i) {
        const double h = 1e-6 * std::max(std::abs(theta[i]), 1e-8);
        Eigen::VectorXd up = theta, down = theta;
        up[i] += h;
        down[i] -= h;
        jac->col(i) =
            (MonicCoefficients(c, full(up)) - MonicCoefficients(c, full(down))) / (2.0 * h);
      }
    }
    return true;
  };
  Eigen::VectorXd theta0(q);
  for (Eigen::Index i = 0; i < q; ++i) theta0[i] = start[free_index[static_cast<std::size_t>(i)]];
  const CtOeResult oe = FitContinuousOe(data, param, theta0, options.ic, options.solver);
  res.summary = oe.summary;
  const Eigen::VectorXd values = full(oe.theta);
  // Residuals that fail their tests (friction the linear model cannot follow, runs of hundreds of
  // samples) make sigma^2 (J^T J)^-1 too small: the stds then take the correlated form.
  if (data.samples() > 100 && oe.residual.size() == data.samples() &&
      oe.residual.squaredNorm() > 0.0)
    res.residual_tests = TestResiduals(oe.residual, data.u);
  const bool correlated = res.residual_tests &&
                          (!res.residual_tests->white || !res.residual_tests->independent) &&
                          oe.covariance_correlated.rows() == oe.covariance.rows();
  if (correlated) {
    res.std_basis =
        "residuals correlated over " + std::to_string(oe.correlation_lags) + " lags (Newey-West)";
  }
  for (std::size_t i = 0, j = 0; i < names.size(); ++i) {
    GreyboxParameter p{names[i], values[static_cast<Eigen::Index>(i)], 0.0, 0.0,
                       options.fixed.count(names[i]) > 0};
    if (!p.fixed) {
      const auto jj = static_cast<Eigen::Index>(j++);
      if (oe.covariance.rows() > jj) p.std_white = std::sqrt(oe.covariance(jj, jj));
      p.std = p.std_white;
      if (correlated) p.std = std::max(p.std, std::sqrt(oe.covariance_correlated(jj, jj)));
    }
    res.parameters.push_back(p);
  }
  res.tf = Normalized(CartTf(c, values));
  res.fit_percent = FitPercent(data.y, data.y - oe.residual);
  return res;
}

}  // namespace vibid::sysid
