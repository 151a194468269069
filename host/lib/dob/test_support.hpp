// Test helpers for the DOB library: the scipy reference file and the 2-DOF chain used across tests.
#pragma once

#include <complex>

#include <nlohmann/json.hpp>

#include "vibid/common/testing/golden.hpp"

namespace vibid::dob::test {

/// host/lib/dob/testdata/dob_golden.json, written by scripts/golden/dob_golden.py (scipy).
inline const nlohmann::json& Golden() {
  return ReadGolden("host/lib/dob/testdata/dob_golden.json");
}

inline std::complex<double> AsComplex(const nlohmann::json& pair) {
  return {pair[0].get<double>(), pair[1].get<double>()};
}

}  // namespace vibid::dob::test
