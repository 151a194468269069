#include "vibid/model/model.hpp"

#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "number_text.hpp"
#include "vibid/common/error.hpp"

namespace vibid::model {
namespace {

std::string Shape(const Eigen::MatrixXd& m) {
  return std::to_string(m.rows()) + "x" + std::to_string(m.cols());
}

// Relative to the matrix's own size so that a model in grams-and-millimetres scale is judged the
// same as one in SI.
bool IsSymmetric(const Eigen::MatrixXd& m) {
  const double scale = m.cwiseAbs().maxCoeff();
  return (m - m.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * scale;
}

void RequireVector(Eigen::Ref<const Eigen::VectorXd> v, const std::string& name, bool allow_zero) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    const double x = v[i];
    Require(std::isfinite(x) && (allow_zero ? x >= 0.0 : x > 0.0),
            name + "[" + std::to_string(i + 1) + "] = " + detail::NumberText(x) + " must be " +
                (allow_zero ? "finite and >= 0" : "finite and > 0"));
  }
}

}  // namespace

void Validate(const Model& model) {
  const Eigen::Index n = model.m_kg.rows();
  Require(n >= 1, "model has no degrees of freedom (M is empty)");
  Require(model.m_kg.cols() == n, "M must be square, got " + Shape(model.m_kg));
  Require(model.k_n_per_m.rows() == n && model.k_n_per_m.cols() == n,
          "K must be " + std::to_string(n) + "x" + std::to_string(n) + " like M, got " +
              Shape(model.k_n_per_m));
  Require(model.c_ns_per_m.rows() == n && model.c_ns_per_m.cols() == n,
          "C must be " + std::to_string(n) + "x" + std::to_string(n) + " like M, got " +
              Shape(model.c_ns_per_m));
  Require(model.m_kg.allFinite(), "M has a non-finite entry");
  Require(model.k_n_per_m.allFinite(), "K has a non-finite entry");
  Require(model.c_ns_per_m.allFinite(), "C has a non-finite entry");
  Require(IsSymmetric(model.m_kg), "M is not symmetric");
  Require(IsSymmetric(model.k_n_per_m), "K is not symmetric");
  Require(IsSymmetric(model.c_ns_per_m), "C is not symmetric");

  const Eigen::LLT<Eigen::MatrixXd> llt(model.m_kg);
  Require(llt.info() == Eigen::Success && model.m_kg.diagonal().minCoeff() > 0.0,
          "M is not positive definite");
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig_k(model.k_n_per_m,
                                                             Eigen::EigenvaluesOnly);
  const double k_scale = model.k_n_per_m.cwiseAbs().maxCoeff();
  Require(eig_k.eigenvalues().minCoeff() >= -1e-12 * k_scale,
          "K is not positive semidefinite (smallest eigenvalue " +
              std::to_string(eig_k.eigenvalues().minCoeff()) + ")");
  // M's own eigenvalues: LLT accepts matrices that are positive definite only to rounding.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig_m(model.m_kg, Eigen::EigenvaluesOnly);
  Require(eig_m.eigenvalues().minCoeff() > 1e-12 * model.m_kg.cwiseAbs().maxCoeff(),
          "M is not positive definite");
}

Model MakeChain(Eigen::Ref<const Eigen::VectorXd> masses_kg,
                Eigen::Ref<const Eigen::VectorXd> springs_n_per_m,
                Eigen::Ref<const Eigen::VectorXd> dampers_ns_per_m) {
  const Eigen::Index n = masses_kg.size();
  Require(n >= 1, "chain needs at least one mass");
  Require(springs_n_per_m.size() == n, "chain has " + std::to_string(n) + " masses but " +
                                           std::to_string(springs_n_per_m.size()) +
                                           " springs (need one per mass)");
  Require(dampers_ns_per_m.size() == 0 || dampers_ns_per_m.size() == n,
          "chain has " + std::to_string(n) + " springs but " +
              std::to_string(dampers_ns_per_m.size()) + " dampers (need none or one per spring)");
  RequireVector(masses_kg, "masses", false);
  RequireVector(springs_n_per_m, "springs", true);
  RequireVector(dampers_ns_per_m, "dampers", true);

  // Element i joins mass i−1 (ground for i = 0) to mass i.
  const auto assemble = [n](Eigen::Ref<const Eigen::VectorXd> element) {
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index i = 0; i < element.size(); ++i) {
      out(i, i) += element[i];
      if (i > 0) {
        out(i - 1, i - 1) += element[i];
        out(i - 1, i) -= element[i];
        out(i, i - 1) -= element[i];
      }
    }
    return out;
  };
  Model model;
  model.m_kg = masses_kg.asDiagonal();
  model.k_n_per_m = assemble(springs_n_per_m);
  model.c_ns_per_m = assemble(dampers_ns_per_m);
  Validate(model);
  return model;
}

Model MakeCartTrack(Eigen::Ref<const Eigen::VectorXd> masses_kg, double k_n_per_m,
                    Eigen::Ref<const Eigen::VectorXd> frictions_ns_per_m) {
  const Eigen::Index n = masses_kg.size();
  Require(n >= 1, "cart track needs at least one cart");
  Require(std::isfinite(k_n_per_m) && k_n_per_m >= 0.0,
          "cart track spring must be finite and >= 0");
  Require(frictions_ns_per_m.size() == 0 || frictions_ns_per_m.size() == n,
          "cart track has " + std::to_string(n) + " carts but " +
              std::to_string(frictions_ns_per_m.size()) + " frictions (need none or one per cart)");
  RequireVector(masses_kg, "masses", false);
  RequireVector(frictions_ns_per_m, "frictions", true);

  Model model;
  model.m_kg = masses_kg.asDiagonal();
  // n+1 equal springs: every cart sits between two of them.
  model.k_n_per_m = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    model.k_n_per_m(i, i) = 2.0 * k_n_per_m;
    if (i + 1 < n) {
      model.k_n_per_m(i, i + 1) = -k_n_per_m;
      model.k_n_per_m(i + 1, i) = -k_n_per_m;
    }
  }
  model.c_ns_per_m = Eigen::MatrixXd::Zero(n, n);
  if (frictions_ns_per_m.size() == n) model.c_ns_per_m.diagonal() = frictions_ns_per_m;
  Validate(model);
  return model;
}

double CartPositionInputForce(double k_n_per_m, double bi_ns_per_m, double xi_m, double dxi_m_s) {
  return bi_ns_per_m * dxi_m_s + 2.0 * k_n_per_m * xi_m;
}

}  // namespace vibid::model
