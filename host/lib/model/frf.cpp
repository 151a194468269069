#include "vibid/model/frf.hpp"

#include <complex>
#include <string>

#include <Eigen/LU>

#include "vibid/common/enum_names.hpp"
#include "vibid/common/error.hpp"

namespace vibid::model {
namespace {

void RequireDof(int dof, Eigen::Index n, const char* what) {
  Require(dof >= 0 && dof < n, std::string(what) + " DOF " + std::to_string(dof + 1) +
                                   " is out of range 1.." + std::to_string(n));
}

std::complex<double> KindFactor(FrfKind kind, double omega_rad_s) {
  switch (kind) {
    case FrfKind::kReceptance: return 1.0;
    case FrfKind::kMobility: return {0.0, omega_rad_s};
    case FrfKind::kAccelerance: return -omega_rad_s * omega_rad_s;
  }
  return 1.0;
}

constexpr EnumNames<FrfKind, 3> kFrfKindNames{{{FrfKind::kReceptance, "receptance"},
                                               {FrfKind::kMobility, "mobility"},
                                               {FrfKind::kAccelerance, "accelerance"}}};

}  // namespace

FrfKind ParseFrfKind(std::string_view name) { return ParseName(kFrfKindNames, name, "FRF kind"); }

std::string_view FrfKindName(FrfKind kind) { return NameOf(kFrfKindNames, kind, "receptance"); }

Eigen::VectorXcd Frf(const Model& model, int input_dof, int output_dof, FrfKind kind,
                     Eigen::Ref<const Eigen::VectorXd> omega_rad_s) {
  Validate(model);
  const Eigen::Index n = model.m_kg.rows();
  RequireDof(input_dof, n, "input");
  RequireDof(output_dof, n, "output");
  Eigen::VectorXcd out(omega_rad_s.size());
  Eigen::MatrixXcd dynamic_stiffness(n, n);
  Eigen::VectorXcd unit = Eigen::VectorXcd::Zero(n);
  unit[input_dof] = 1.0;
  Eigen::PartialPivLU<Eigen::MatrixXcd> lu(n);
  for (Eigen::Index i = 0; i < omega_rad_s.size(); ++i) {
    const double w = omega_rad_s[i];
    dynamic_stiffness.real() = model.k_n_per_m - w * w * model.m_kg;
    dynamic_stiffness.imag() = w * model.c_ns_per_m;
    lu.compute(dynamic_stiffness);
    out[i] = lu.solve(unit)[output_dof] * KindFactor(kind, w);
  }
  return out;
}

Eigen::VectorXcd FrfModal(const ModalResult& modes, int input_dof, int output_dof, FrfKind kind,
                          Eigen::Ref<const Eigen::VectorXd> omega_rad_s) {
  const Eigen::Index n = modes.shapes.rows();
  RequireDof(input_dof, n, "input");
  RequireDof(output_dof, n, "output");
  Eigen::VectorXcd out(omega_rad_s.size());
  for (Eigen::Index i = 0; i < omega_rad_s.size(); ++i) {
    const double w = omega_rad_s[i];
    std::complex<double> h = 0.0;
    for (Eigen::Index r = 0; r < modes.shapes.cols(); ++r) {
      const double wr = modes.omega_rad_s[r];
      const std::complex<double> denominator(wr * wr - w * w, w * modes.modal_damping_per_s[r]);
      h += modes.shapes(output_dof, r) * modes.shapes(input_dof, r) / denominator;
    }
    out[i] = h * KindFactor(kind, w);
  }
  return out;
}

}  // namespace vibid::model
