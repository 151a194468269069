// Test helpers for the DOB library: the scipy reference file and the 2-DOF chain used across tests.
#pragma once

#include <complex>
#include <string>

#include <nlohmann/json.hpp>

#include "vibid/common/json_file.hpp"

namespace vibid::dob::test {

/// host/lib/dob/testdata/dob_golden.json, written by scripts/golden/dob_golden.py (scipy).
inline const nlohmann::json& Golden() {
  static const nlohmann::json golden =
      ReadJsonFile(std::string(VIBID_SOURCE_DIR) + "/host/lib/dob/testdata/dob_golden.json");
  return golden;
}

inline std::complex<double> AsComplex(const nlohmann::json& pair) {
  return {pair[0].get<double>(), pair[1].get<double>()};
}

}  // namespace vibid::dob::test
