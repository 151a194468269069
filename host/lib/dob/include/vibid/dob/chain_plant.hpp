// The nominal plant of a 2-DOF series chain (ground -k1- m1 -k2- m2, dashpots in parallel) in
// closed form, for tools and tests that must not depend on a model file.
#pragma once

#include "vibid/dob/design.hpp"

namespace vibid::dob {

struct ChainParameters {
  double m1_kg = 2.5, m2_kg = 2.0;
  double k1_n_per_m = 4000.0, k2_n_per_m = 3000.0;
  double c1_ns_per_m = 3.0, c2_ns_per_m = 3.0;
};

/// Receptance from a force on m2 to the displacement of m2, (m1 s^2 + (c1+c2) s + k1+k2) / det,
/// and row 2 of M, C, K.
NominalPlant ChainPlantForceOnM2(const ChainParameters& p);

}  // namespace vibid::dob
