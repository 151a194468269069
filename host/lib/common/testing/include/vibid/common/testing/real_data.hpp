// Where the tests find the real measured records.
//
// The licensed ones (ladisk_impact_hammer, MIT; daisy_robot_arm, BSD-3) ship in the project's
// testdata/ (VIBID_TESTDATA_DIR), so every clone runs their tests. The ECP cart records have no
// license and are never copied: they live in ../shared/data beside the project (VIBID_DATA_DIR,
// or the folder $VIBID_SHARED_DATA names). A test of those skips, naming the source, when its
// folder is absent, and fails instead when VIBID_REQUIRE_REAL_DATA=1 (.ci/run sets it), so CI
// never passes by skipping them.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace vibid::testing {

/// A shipped record's path: testdata/FOLDER/FILE.
inline std::string TestData(const std::string& folder_and_file) {
  return std::string(VIBID_TESTDATA_DIR) + "/" + folder_and_file;
}

/// The lookup of an unlicensed record folder: its path when present, else why it is missing.
struct SharedData {
  std::string dir;      ///< empty when the folder is absent
  std::string missing;  ///< the skip (or failure) message when absent
  bool required = false;
};

inline SharedData FindSharedData(const std::string& folder, const std::string& source) {
  const char* override_dir = std::getenv("VIBID_SHARED_DATA");
  const std::string root =
      override_dir != nullptr && *override_dir != '\0' ? override_dir : VIBID_DATA_DIR;
  const char* require = std::getenv("VIBID_REQUIRE_REAL_DATA");
  SharedData found;
  found.required = require != nullptr && std::string(require) == "1";
  const std::string dir = root + "/" + folder;
  if (std::filesystem::is_directory(dir)) {
    found.dir = dir;
  } else {
    found.missing = "no " + dir + ": the " + folder + " records (" + source +
                    ", no license, so not in the project) are read from the shared data folder "
                    "beside it (../shared/data, or $VIBID_SHARED_DATA)";
  }
  return found;
}

inline const char* const kEcpSource =
    "ECP Model 210 cart, github rssalessio/Control-Linear-Vibrations @ 4e7749bc";

}  // namespace vibid::testing

/// Declares `const std::string VAR`, the folder FOLDER of the shared data, or ends the test:
/// skipped when the folder is absent, failed when VIBID_REQUIRE_REAL_DATA=1 asks for the records.
#define VIBID_SHARED_DATA_OR_SKIP(VAR, FOLDER)                                       \
  const ::vibid::testing::SharedData VAR##_lookup =                                  \
      ::vibid::testing::FindSharedData(FOLDER, ::vibid::testing::kEcpSource);        \
  if (VAR##_lookup.dir.empty()) {                                                    \
    if (VAR##_lookup.required) {                                                     \
      FAIL() << VAR##_lookup.missing << "; VIBID_REQUIRE_REAL_DATA=1 asks for them"; \
    }                                                                                \
    GTEST_SKIP() << VAR##_lookup.missing;                                            \
  }                                                                                  \
  const std::string VAR = VAR##_lookup.dir
