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

int EntriesIn(const fs::path& dir) {
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  return entries;
}

TEST(AtomicOutputFile, RefusesAnUnwritableDestinationBeforeAnyContentExists) {
  const fs::path dir = fs::temp_directory_path() / "vibid_atomic_claim_test";
  fs::remove_all(dir);
  fs::create_directories(dir / "sub");
  const auto message = [](const std::string& path) {
    try {
      AtomicOutputFile claimed(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("claimed");
  };
  EXPECT_EQ(message((dir / "nodir" / "x.csv").string()),
            "cannot write '" + (dir / "nodir" / "x.csv").string() + "': No such file or directory");
  EXPECT_EQ(message((dir / "sub").string()),
            "cannot write '" + (dir / "sub").string() + "': it is a directory");
  fs::remove_all(dir);
}

TEST(AtomicOutputFile, CommitReplacesAndAnAbandonedClaimLeavesNothing) {
  const fs::path dir = fs::temp_directory_path() / "vibid_atomic_claim_test2";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "rec.csv").string();
  WriteFileAtomic(path, "old");
  {
    AtomicOutputFile claimed(path);
    EXPECT_EQ(EntriesIn(dir), 2);  // the destination and the claimed temporary file
    EXPECT_EQ(ReadFileText(path), "old");
  }
  // Abandoned (the work failed): the old file stays, the temporary file is gone.
  EXPECT_EQ(ReadFileText(path), "old");
  EXPECT_EQ(EntriesIn(dir), 1);
  AtomicOutputFile claimed(path);
  claimed.Commit("new");
  EXPECT_EQ(ReadFileText(path), "new");
  EXPECT_EQ(EntriesIn(dir), 1);
  EXPECT_THROW(claimed.Commit("again"), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace vibid
