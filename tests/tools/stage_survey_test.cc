// The stage commands, report and export-gcp refuse another survey's stage
// files (issue 48), on the real binary: a results folder of survey A given
// with survey B, or with A's exposures renumbered, is exit 1 naming the
// file, and the folder is left as it was. Stage files of an older version
// (no survey identity) are still read, with a warning.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// Every file of `folder` with its contents.
std::map<std::string, std::string> Contents(const std::string& folder) {
  std::map<std::string, std::string> contents;
  for (const std::string& file : FilesUnder(folder)) {
    contents[file] = ReadWholeFile(folder + "/" + file);
  }
  return contents;
}

class StageSurvey : public ::testing::Test {
 protected:
  // Surveys A (seed 1) and B (seed 2), and A's stage commands into
  // results/ (reconstruct, match, adjust), once for the suite.
  static void SetUpTestSuite() {
    tmp_ = new TemporaryFolder();
    for (const char* seed : {"1", "2"}) {
      const std::string survey = tmp_->Path(std::string("survey") + seed);
      std::string arguments = SmallSurveyArguments();
      arguments.replace(arguments.find("--seed 1"), 8,
                        std::string("--seed ") + seed);
      ASSERT_EQ(Run("simulate " + arguments + " -o " + Quote(survey)), 0);
    }
    const std::string a = Quote(tmp_->Path("survey1"));
    const std::string results = Quote(tmp_->Path("results"));
    ASSERT_EQ(Run("reconstruct " + a + " -o " + results), 0);
    ASSERT_EQ(Run("match " + a + " -o " + results), 0);
    chain_stderr_ = Stderr();
    ASSERT_EQ(Run("adjust " + a + " -o " + results + " --no-tie-points"), 0);
    chain_stderr_ += Stderr();
  }
  static void TearDownTestSuite() {
    delete tmp_;
    tmp_ = nullptr;
  }

  static int Run(const std::string& arguments) {
    return RunZebrageo(arguments, tmp_->Path("stdout"), tmp_->Path("stderr"));
  }
  static std::string Stderr() { return ReadWholeFile(tmp_->Path("stderr")); }

  // `arguments` exits 1 naming `file` as another survey's, and results/
  // is left byte for byte as it was.
  void ExpectRefusedUntouched(const std::string& arguments,
                              const std::string& file) {
    const auto before = Contents(tmp_->Path("results"));
    EXPECT_EQ(Run(arguments), 1) << arguments << "\n" << Stderr();
    const std::string err = Stderr();
    // The file in full (the results folder is what is wrong), its line.
    const std::string named =
        tmp_->Path("results/" + file) + ":1: belongs to another survey";
    EXPECT_NE(err.find(named), std::string::npos)
        << arguments << "\nlacks '" << named << "':\n"
        << err;
    const auto after = Contents(tmp_->Path("results"));
    EXPECT_EQ(before.size(), after.size()) << arguments;
    for (const auto& [name, text] : before) {
      const auto it = after.find(name);
      if (name == ".zebrageo.lock") continue;  // the owner's pid
      EXPECT_TRUE(it != after.end() && it->second == text)
          << arguments << ": " << name << " changed";
    }
  }

  static TemporaryFolder* tmp_;
  static std::string chain_stderr_;  // of match and adjust on survey A
};

TemporaryFolder* StageSurvey::tmp_ = nullptr;
std::string StageSurvey::chain_stderr_;

TEST_F(StageSurvey, StageFilesNameTheirSurvey) {
  for (const char* file :
       {"reconstructed_bands.csv", "matches.csv", "crossing_decisions.csv"}) {
    const std::string text = ReadWholeFile(tmp_->Path("results/") + file);
    EXPECT_TRUE(
        std::regex_search(text, std::regex("^# survey: [0-9a-f]{16}\n")))
        << file << " lacks its survey:\n"
        << text.substr(0, 300);
  }
}

TEST_F(StageSurvey, AnotherSurveysStageFilesAreRefused) {
  const std::string b = Quote(tmp_->Path("survey2"));
  const std::string results = Quote(tmp_->Path("results"));
  ExpectRefusedUntouched("match " + b + " -o " + results,
                         "reconstructed_bands.csv");
  ExpectRefusedUntouched("match " + b + " -o " + results + " --second-pass",
                         "reconstructed_bands.csv");
  ExpectRefusedUntouched("adjust " + b + " -o " + results + " --no-tie-points",
                         "reconstructed_bands.csv");
  ExpectRefusedUntouched("report " + b + " -o " + results,
                         "reconstructed_bands.csv");
  fs::create_directories(tmp_->Path("out"));
  ExpectRefusedUntouched("export-gcp " + b + " " + results +
                             " --format odm -o " +
                             Quote(tmp_->Path("out/gcp_list.txt")),
                         "matches.csv");
  EXPECT_TRUE(FilesUnder(tmp_->Path("out")).empty());
}

TEST_F(StageSurvey, ExportFromAnEmptyResultsFolderNamesTheMissingFile) {
  fs::create_directories(tmp_->Path("empty"));
  fs::create_directories(tmp_->Path("out"));
  EXPECT_EQ(Run("export-gcp " + Quote(tmp_->Path("survey1")) + " " +
                Quote(tmp_->Path("empty")) + " --format odm -o " +
                Quote(tmp_->Path("out/gcp_list.txt"))),
            1);
  const std::string named =
      tmp_->Path("empty/matches.csv") + ": not found: run";
  EXPECT_NE(Stderr().find(named), std::string::npos) << Stderr();
  EXPECT_TRUE(FilesUnder(tmp_->Path("out")).empty());
  EXPECT_TRUE(FilesUnder(tmp_->Path("empty")).empty());
}

TEST_F(StageSurvey, RenumberedExposuresAreAnotherSurvey) {
  // Survey A with every exposure id moved by 1000: the same images and
  // times, but the stage files' ids now name no exposure, or another one.
  const std::string renumbered = tmp_->Path("renumbered");
  fs::copy(tmp_->Path("survey1"), renumbered, fs::copy_options::recursive);
  std::istringstream in(ReadWholeFile(renumbered + "/exposures.csv"));
  std::string text;
  bool header = true;
  for (std::string line; std::getline(in, line);) {
    if (!header && !line.empty() && line[0] != '#') {
      const size_t comma = line.find(',');
      line = std::to_string(std::stoll(line.substr(0, comma)) + 1000) +
             line.substr(comma);
    }
    if (!line.empty() && line[0] != '#') header = false;
    text += line + "\n";
  }
  tmp_->Write("renumbered/exposures.csv", text);
  ExpectRefusedUntouched("adjust " + Quote(renumbered) + " -o " +
                             Quote(tmp_->Path("results")) + " --no-tie-points",
                         "reconstructed_bands.csv");
}

TEST_F(StageSurvey, FilesOfAnOlderVersionAreReadWithAWarning) {
  const std::string old = tmp_->Path("old");
  fs::copy(tmp_->Path("results"), old, fs::copy_options::recursive);
  for (const char* file :
       {"reconstructed_bands.csv", "matches.csv", "crossing_decisions.csv"}) {
    const std::string path = old + "/" + file;
    const std::string text = std::regex_replace(
        ReadWholeFile(path), std::regex("# survey: [0-9a-f]+\n"), "");
    tmp_->Write(std::string("old/") + file, text);
  }
  const std::string a = Quote(tmp_->Path("survey1"));
  EXPECT_EQ(Run("adjust " + a + " -o " + Quote(old) + " --no-tie-points"), 0)
      << Stderr();
  EXPECT_NE(Stderr().find("reconstructed_bands.csv: names no survey"),
            std::string::npos)
      << Stderr();
  // The survey's own files pass without a warning: the stage commands
  // chain.
  EXPECT_EQ(chain_stderr_.find("names no survey"), std::string::npos)
      << chain_stderr_;
  EXPECT_EQ(chain_stderr_.find("another survey"), std::string::npos)
      << chain_stderr_;
}

}  // namespace
}  // namespace zebrageo
