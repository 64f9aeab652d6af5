#include "survey/survey_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>

#include "survey/input_error.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

// A survey folder and, beside it, files it must not reach.
class SurveyPathsTest : public ::testing::Test {
 protected:
  SurveyPathsTest() {
    folder_.Write("survey/images/a.png", "png");
    folder_.Write("survey/trajectory.csv", "time\n");
    folder_.Write("outside.png", "png");
    // A sibling whose name starts like the survey's.
    folder_.Write("survey2/b.png", "png");
  }
  std::string Survey() const { return folder_.Path("survey"); }
  SurveyFile Resolve(const std::string& name, bool allow = false) const {
    SurveyPathOptions options;
    options.allow_outside_paths = allow;
    return SurveyPaths(Survey(), options).Resolve(name);
  }

  TemporaryFolder folder_;
};

TEST_F(SurveyPathsTest, AFileInsideTheFolderResolves) {
  const SurveyFile file = Resolve("images/a.png");
  EXPECT_TRUE(file.ok());
  EXPECT_EQ(file.path, (fs::path(Survey()) / "images/a.png").string());
  EXPECT_EQ(file.Problem(), "");
  // Round about, but inside.
  EXPECT_TRUE(Resolve("images/../trajectory.csv").ok());
}

TEST_F(SurveyPathsTest, AnAbsolutePathIsRefused) {
  const SurveyFile file = Resolve("/etc/passwd");
  EXPECT_EQ(file.state, SurveyFileState::kAbsolute);
  EXPECT_TRUE(file.escapes());
  EXPECT_THAT(file.Problem(),
              AllOf(HasSubstr("is an absolute path: a survey names its files "
                              "relative to its folder"),
                    HasSubstr("--allow-outside-paths")));
}

TEST_F(SurveyPathsTest, APathLeavingTheFolderIsRefusedWithWhereItGoes) {
  for (const std::string name :
       {"../outside.png", "images/../../outside.png",
        "../../../../../../../../etc/passwd", "../survey2/b.png"}) {
    const SurveyFile file = Resolve(name);
    EXPECT_EQ(file.state, SurveyFileState::kOutside) << name;
    EXPECT_THAT(file.Problem(), HasSubstr(", outside the survey folder"))
        << name;
  }
  EXPECT_THAT(Resolve("../outside.png").Problem(),
              HasSubstr("resolves to " +
                        fs::canonical(folder_.Path("outside.png")).string()));
  // Also when it does not exist: no probing outside.
  EXPECT_EQ(Resolve("../missing.png").state, SurveyFileState::kOutside);
}

TEST_F(SurveyPathsTest, ASymbolicLinkOutOfTheFolderIsRefused) {
  fs::create_symlink(folder_.Path("outside.png"),
                     folder_.Path("survey/images/link.png"));
  fs::create_directory_symlink(folder_.Path("survey2"),
                               folder_.Path("survey/images/pool"));
  EXPECT_EQ(Resolve("images/link.png").state, SurveyFileState::kOutside);
  EXPECT_EQ(Resolve("images/pool/b.png").state, SurveyFileState::kOutside);
  // A link that stays inside is fine.
  fs::create_symlink("a.png", folder_.Path("survey/images/same.png"));
  EXPECT_TRUE(Resolve("images/same.png").ok());
}

TEST_F(SurveyPathsTest, TheOptOutReadsOutsideFiles) {
  EXPECT_TRUE(Resolve("../outside.png", true).ok());
  EXPECT_TRUE(Resolve(folder_.Path("outside.png"), true).ok());
  EXPECT_EQ(Resolve(folder_.Path("outside.png"), true).path,
            folder_.Path("outside.png"));
}

TEST_F(SurveyPathsTest, FoldersLoopsAndDevicesHaveTheirOwnProblem) {
  const SurveyFile folder = Resolve("images");
  EXPECT_EQ(folder.state, SurveyFileState::kFolder);
  EXPECT_EQ(folder.Problem(), "is a folder, not a file");

  fs::create_symlink("loop.png", folder_.Path("survey/images/loop.png"));
  fs::create_symlink("b.png", folder_.Path("survey/images/c.png"));
  fs::create_symlink("c.png", folder_.Path("survey/images/b.png"));
  for (const std::string name : {"images/loop.png", "images/b.png"}) {
    const SurveyFile loop = Resolve(name);
    EXPECT_EQ(loop.state, SurveyFileState::kSymlinkLoop) << name;
    EXPECT_THAT(loop.Problem(), HasSubstr("is a loop of symbolic links"));
    EXPECT_FALSE(loop.escapes());
  }

  // A FIFO would block a reader forever.
  ASSERT_EQ(::mkfifo(folder_.Path("survey/fifo.csv").c_str(), 0600), 0);
  EXPECT_EQ(Resolve("fifo.csv").state, SurveyFileState::kNotAFile);
  EXPECT_THAT(Resolve("fifo.csv").Problem(),
              HasSubstr("is not a regular file"));

  EXPECT_EQ(Resolve("images/none.png").state, SurveyFileState::kMissing);
  EXPECT_EQ(Resolve("images/none.png").Problem(), "does not exist");
}

TEST_F(SurveyPathsTest, ASurveyFolderReachedThroughALinkWorks) {
  fs::create_directory_symlink(Survey(), folder_.Path("alias"));
  EXPECT_TRUE(SurveyPaths(folder_.Path("alias"), SurveyPathOptions())
                  .Resolve("images/a.png")
                  .ok());
}

TEST_F(SurveyPathsTest, AMissingSurveyFolderIsAnInputError) {
  EXPECT_THROW(SurveyPaths(folder_.Path("nope"), SurveyPathOptions()),
               InputError);
  EXPECT_THROW(SurveyPaths(folder_.Path("outside.png"), SurveyPathOptions()),
               InputError);
}

}  // namespace
}  // namespace zebrageo
