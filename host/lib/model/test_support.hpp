// Helpers for the model tests: golden data and random systems.
#pragma once

#include <random>

#include <Eigen/Core>
#include <Eigen/QR>
#include <nlohmann/json.hpp>

#include "vibid/common/testing/golden.hpp"
#include "vibid/model/model.hpp"

namespace vibid::model::testing {

/// host/lib/model/testdata/model_golden.json, written by scripts/golden/model_golden.py (scipy).
inline const nlohmann::json& Golden() {
  return ReadGolden("host/lib/model/testdata/model_golden.json");
}

inline Eigen::MatrixXd JsonMatrix(const nlohmann::json& rows) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()),
                    static_cast<Eigen::Index>(rows[0].size()));
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      m(r, c) = rows[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)].get<double>();
  }
  return m;
}

inline Eigen::VectorXd JsonVector(const nlohmann::json& values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i)
    v[i] = values[static_cast<std::size_t>(i)].get<double>();
  return v;
}

inline Model JsonModel(const nlohmann::json& j) {
  Model m;
  m.m_kg = JsonMatrix(j.at("M"));
  m.k_n_per_m = JsonMatrix(j.at("K"));
  m.c_ns_per_m =
      j.contains("C") ? JsonMatrix(j.at("C")) : Eigen::MatrixXd::Zero(m.m_kg.rows(), m.m_kg.rows());
  return m;
}

/// Largest |a − b| / |b| over the entries (b the reference).
inline double MaxRelativeError(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b) {
  return ((a - b).cwiseAbs().array() / b.cwiseAbs().array()).maxCoeff();
}

/// A random symmetric positive definite matrix with eigenvalues in [lo, hi] (Eigen-test style).
inline Eigen::MatrixXd RandomSpd(std::mt19937& rng, Eigen::Index n, double lo, double hi) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::MatrixXd g(n, n);
  for (Eigen::Index i = 0; i < g.size(); ++i) g.data()[i] = u(rng) - 0.5;
  const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(g).householderQ();
  Eigen::VectorXd d(n);
  for (Eigen::Index i = 0; i < n; ++i) d[i] = lo + (hi - lo) * u(rng);
  Eigen::MatrixXd s = q * d.asDiagonal() * q.transpose();
  return 0.5 * (s + s.transpose());
}

/// A random model of n DOFs; with `proportional`, C = αM + βK (classical damping), else a random
/// positive definite C.
inline Model RandomModel(std::mt19937& rng, Eigen::Index n, bool proportional) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Model m;
  m.m_kg = RandomSpd(rng, n, 0.5, 3.0);
  m.k_n_per_m = RandomSpd(rng, n, 500.0, 20000.0);
  if (proportional) {
    m.c_ns_per_m = (0.5 + u(rng)) * m.m_kg + (1e-4 + 1e-4 * u(rng)) * m.k_n_per_m;
  } else {
    m.c_ns_per_m = RandomSpd(rng, n, 0.5, 5.0);
  }
  return m;
}

}  // namespace vibid::model::testing
