#include "vibid/sysid/instrumental.hpp"

#include <Eigen/QR>

namespace vibid::sysid {

bool SolveInstrumental(Eigen::Ref<const Eigen::MatrixXd> zeta,
                       Eigen::Ref<const Eigen::MatrixXd> phi,
                       Eigen::Ref<const Eigen::VectorXd> target, Eigen::VectorXd& theta) {
  const Eigen::Index p = phi.cols();
  Eigen::VectorXd phi_scale = phi.colwise().norm().transpose();
  Eigen::VectorXd zeta_scale = zeta.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < p; ++j) {
    if (!(phi_scale[j] > 0.0) || !(zeta_scale[j] > 0.0)) return false;
  }
  const Eigen::MatrixXd zp = zeta_scale.cwiseInverse().asDiagonal() * (zeta.transpose() * phi) *
                             phi_scale.cwiseInverse().asDiagonal();
  const Eigen::VectorXd zy = zeta_scale.cwiseInverse().asDiagonal() * (zeta.transpose() * target);
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(zp);
  qr.setThreshold(1e-13);
  if (qr.rank() < p) return false;
  theta = phi_scale.cwiseInverse().asDiagonal() * qr.solve(zy);
  return theta.allFinite();
}

}  // namespace vibid::sysid
