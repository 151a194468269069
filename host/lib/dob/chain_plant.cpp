#include "vibid/dob/chain_plant.hpp"

#include "vibid/numerics/polynomial.hpp"

namespace vibid::dob {

NominalPlant ChainPlantForceOnM2(const ChainParameters& p) {
  const Eigen::Vector3d d11(p.m1_kg, p.c1_ns_per_m + p.c2_ns_per_m, p.k1_n_per_m + p.k2_n_per_m);
  const Eigen::Vector3d d22(p.m2_kg, p.c2_ns_per_m, p.k2_n_per_m);
  const Eigen::Vector2d d12(-p.c2_ns_per_m, -p.k2_n_per_m);
  NominalPlant plant;
  const Eigen::VectorXd off = numerics::MultiplyPolynomials(d12, d12);
  Eigen::VectorXd det = numerics::MultiplyPolynomials(d11, d22);
  det.tail(off.size()) -= off;
  plant.receptance_num = d11;
  plant.receptance_den = det;
  plant.m_row = Eigen::Vector2d(0.0, p.m2_kg);
  plant.c_row = Eigen::Vector2d(-p.c2_ns_per_m, p.c2_ns_per_m);
  plant.k_row = Eigen::Vector2d(-p.k2_n_per_m, p.k2_n_per_m);
  return plant;
}

}  // namespace vibid::dob
