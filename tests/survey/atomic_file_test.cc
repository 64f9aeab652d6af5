#include "survey/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(AtomicFile, CommitLeavesOnlyTheFinalFile) {
  TemporaryFolder folder;
  WriteFileAtomically(folder.Path("out.csv"),
                      [](std::ostream& out) { out << "a,b\n"; });
  EXPECT_EQ(ReadAll(folder.Path("out.csv")), "a,b\n");
  EXPECT_EQ(folder.CountEntries(), 1);
}

TEST(AtomicFile, FailureBeforeCommitLeavesNothing) {
  TemporaryFolder folder;
  EXPECT_THROW(WriteFileAtomically(folder.Path("out.csv"),
                                   [](std::ostream& out) {
                                     out << "half";
                                     throw std::runtime_error("stage failed");
                                   }),
               std::runtime_error);
  EXPECT_EQ(folder.CountEntries(), 0);
}

TEST(AtomicFile, FailureKeepsThePreviousCompleteFile) {
  TemporaryFolder folder;
  folder.Write("out.csv", "old\n");
  EXPECT_THROW(WriteFileAtomically(folder.Path("out.csv"),
                                   [](std::ostream& out) {
                                     out << "new";
                                     throw std::runtime_error("killed");
                                   }),
               std::runtime_error);
  EXPECT_EQ(ReadAll(folder.Path("out.csv")), "old\n");
  EXPECT_EQ(folder.CountEntries(), 1);
}

TEST(AtomicFile, MissingFolderThrows) {
  EXPECT_THROW(AtomicFile("/nonexistent-zebrageo/out.csv"), std::runtime_error);
}

TEST(AtomicFile, RemoveStaleTemporariesCleansKilledWrites) {
  TemporaryFolder folder;
  folder.Write("poses.csv.tmp-12345", "partial");
  folder.Write("poses.csv", "complete");
  RemoveStaleTemporaries(folder.Path());
  EXPECT_EQ(folder.CountEntries(), 1);
  EXPECT_TRUE(std::filesystem::exists(folder.Path("poses.csv")));
}

}  // namespace
}  // namespace zebrageo
