#include "vibid/common/atomic_file.hpp"

#include <filesystem>

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"

namespace vibid {
namespace {

namespace fs = std::filesystem;

TEST(AtomicFile, WritesAndReplaces) {
  const fs::path dir = fs::temp_directory_path() / "vibid_atomic_test";
  fs::create_directories(dir);
  const std::string path = (dir / "out.txt").string();
  WriteFileAtomic(path, "first");
  WriteFileAtomic(path, "second");
  EXPECT_EQ(ReadFileText(path), "second");
  // No temporary file is left beside the output.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, MissingDirectoryIsAnInputError) {
  EXPECT_THROW(WriteFileAtomic("/nonexistent-dir-vibid/x.csv", "x"), InputError);
  EXPECT_THROW(ReadFileText("/nonexistent-dir-vibid/x.csv"), InputError);
}

}  // namespace
}  // namespace vibid
