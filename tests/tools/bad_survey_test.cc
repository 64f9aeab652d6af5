// The broken-survey suite: `zebrageo simulate --bad KIND` writes a small
// survey with one fault, the real `zebrageo run` binary processes it, and
// the exit status, the message, and the results folder are checked against
// what truth/meta.json expects (SURVEY_FORMAT.md: a survey that cannot be
// processed exits 1-123 with a message naming the file and the problem and
// leaves no output; a usable one exits 0 with every output and a warning).
// Then ../shared/tools/score_results.py badinput, the independent checker,
// judges the same folder when it is present.
#include "simulator/bad_survey.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {

// Test names in ctest's list: the kind, not its bytes.
void PrintTo(const BadSurveyKind& kind, std::ostream* out) {
  *out << kind.name;
}

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// What the results folder of SURVEY_FORMAT.md holds (score_results.py's
// OUTPUTS).
const std::vector<std::string> kOutputs = {"trajectory_corrected.csv",
                                           "poses.csv", "bands.geojson",
                                           "gcp_residuals.csv", "report.json"};

// Per kind: what stderr's last line must say (file, line where the fault has
// one, problem) or, for a usable survey, what a warning of report.json must
// say.
const std::map<std::string, std::string>& ExpectedMessages() {
  static const std::map<std::string, std::string> messages = {
      {"truncated_trajectory",
       R"(trajectory\.csv:[0-9]+: truncated row: 5 fields, the header has 13)"},
      {"nan_trajectory",
       R"(trajectory\.csv:[0-9]+: column 'h': "nan" is not finite)"},
      {"garbage_images",
       R"(exposures\.csv: [0-9]+ of [0-9]+ exposures have an unreadable image.*images/[0-9]+_left\.png: cannot decode)"},
      {"missing_images",
       R"(images are missing.*exposures\.csv:[0-9]+: image images/[0-9]+_left\.png does not exist)"},
      {"missing_rig",
       R"(survey\.yaml:[0-9]+: 'rig' names rig\.yaml, which does not exist)"},
      {"exposures_outside",
       R"(exposures\.csv:[0-9]+: exposure [0-9]+ at time [0-9.]+ is outside the trajectory's span)"},
      {"bad_focal",
       R"(rig\.yaml:[0-9]+: camera 'left' K: fx and fy must be > 0)"},
      {"bad_rotation",
       R"(rig\.yaml:[0-9]+: camera 'left' T_body_cam: rotation is not orthonormal)"},
      {"bad_matrix",
       R"(rig\.yaml:[0-9]+: camera 'left' K must be a list of exactly 9 numbers)"},
      {"malformed_geojson", R"(roadmarks\.geojson:[0-9]+: malformed JSON)"},
      {"empty_database", R"(roadmarks\.geojson\) holds no zebra band)"},
      {"no_zebra", R"(no zebra band was reconstructed)"},
      {"unreadable_images",
       R"(images/[0-9]+_(left|right)\.png: cannot decode image)"},
      {"no_control_stretch", R"(no control over [0-9]+ m of trajectory)"},
  };
  return messages;
}

bool Contains(const std::string& text, const std::string& pattern) {
  return std::regex_search(text, std::regex(pattern));
}

std::string LastLine(const std::string& text) {
  std::string trimmed = text;
  while (!trimmed.empty() && trimmed.back() == '\n') trimmed.pop_back();
  return trimmed.substr(trimmed.rfind('\n') + 1);
}

// Every CSV row has the header's number of fields; JSON and GeoJSON parse;
// no file is empty or temporary; no NaN or infinity is written anywhere.
void ExpectNothingPartial(const std::string& results) {
  for (const std::string& file : FilesUnder(results)) {
    SCOPED_TRACE(file);
    EXPECT_EQ(file.find(".tmp"), std::string::npos) << "temporary file left";
    const std::string text = ReadWholeFile(results + "/" + file);
    EXPECT_FALSE(text.empty()) << "empty file left";
    EXPECT_FALSE(Contains(text, R"((^|[,:\[ ])-?(nan|inf)([,\]\n ]|$))"))
        << "NaN or infinity written";
    const std::string ext = fs::path(file).extension().string();
    if (ext == ".json" || ext == ".geojson") {
      EXPECT_TRUE(json::accept(text)) << "not parsable JSON";
    }
    if (ext == ".csv") {
      std::istringstream in(text);
      int header_fields = -1, line_number = 0;
      for (std::string line; std::getline(in, line);) {
        ++line_number;
        if (line.empty() || line[0] == '#') continue;
        const int fields =
            1 + static_cast<int>(std::count(line.begin(), line.end(), ','));
        if (header_fields < 0) header_fields = fields;
        ASSERT_EQ(fields, header_fields) << "line " << line_number;
      }
      EXPECT_EQ(text.back(), '\n') << "last line cut";
    }
  }
}

bool ScorerAvailable(std::string* why) {
  const std::string scorer =
      std::string(ZEBRAGEO_SHARED_DIR) + "/tools/score_results.py";
  if (!fs::exists("/usr/bin/python3")) {
    *why = "/usr/bin/python3 is absent";
    return false;
  }
  if (!fs::exists(scorer)) {
    *why = scorer + " is absent";
    return false;
  }
  return true;
}

class BadSurvey : public ::testing::TestWithParam<BadSurveyKind> {};

TEST_P(BadSurvey, RunEndsCleanlyAsExpected) {
  const BadSurveyKind& kind = GetParam();
  ASSERT_TRUE(ExpectedMessages().count(kind.name))
      << "add the expected message of " << kind.name;
  TemporaryFolder folder;
  const std::string survey = folder.Path("survey");
  const std::string results = folder.Path("results");
  ASSERT_EQ(RunZebrageo("--log-level error simulate --bad " + kind.name +
                            " -o " + Quote(survey),
                        folder.Path("sim.out"), folder.Path("sim.err")),
            0)
      << ReadWholeFile(folder.Path("sim.err"));
  const json meta = json::parse(ReadWholeFile(survey + "/truth/meta.json"));
  EXPECT_EQ(meta.value("bad", ""), kind.name);
  EXPECT_EQ(meta.value("expect", ""), kind.expect);
  EXPECT_TRUE(meta.contains("options") && meta.contains("crossings"))
      << "the simulator's fields are kept";

  const std::string err_path = folder.Path("run.err");
  const int code = RunZebrageo("--log-level warning run " + Quote(survey) +
                                   " -o " + Quote(results) + " --threads 2",
                               folder.Path("run.out"), err_path);
  const std::string err = ReadWholeFile(err_path);
  SCOPED_TRACE("stderr:\n" + err);
  // A message may quote the bad value ("nan"), never print a computed one.
  EXPECT_FALSE(Contains(std::regex_replace(err, std::regex(R"("nan")"), ""),
                        R"(\b(nan|NaN|inf)\b)"))
      << "NaN in a message";
  const std::string& expected = ExpectedMessages().at(kind.name);
  if (kind.expect == "error") {
    // 1: invalid input (docs/cli.md, "Exit status").
    EXPECT_EQ(code, 1);
    const std::string last = LastLine(err);
    EXPECT_TRUE(Contains(last, "^zebrageo: error: ")) << last;
    EXPECT_TRUE(Contains(last, expected)) << last << "\n  !~ " << expected;
    for (const std::string& output : kOutputs) {
      EXPECT_FALSE(fs::exists(results + "/" + output)) << output << " left";
    }
    EXPECT_FALSE(fs::exists(results + "/report.html"));
  } else {
    EXPECT_EQ(code, 0);
    for (const std::string& output : kOutputs) {
      EXPECT_TRUE(fs::is_regular_file(results + "/" + output)) << output;
    }
    const json report = json::parse(ReadWholeFile(results + "/report.json"));
    bool found = false;
    for (const json& warning : report.at("warnings")) {
      found = found || Contains(warning.get<std::string>(), expected);
    }
    EXPECT_TRUE(found) << report["warnings"].dump(1) << "\n  !~ " << expected;
    // The exposures have their poses, even without control.
    const std::string poses = ReadWholeFile(results + "/poses.csv");
    EXPECT_GT(std::count(poses.begin(), poses.end(), '\n'), 10);
  }
  ExpectNothingPartial(results);

  std::string why;
  if (!ScorerAvailable(&why)) {
    std::cout << "[  NOTE    ] score_results.py badinput not run: " << why
              << "\n";
    return;
  }
  const std::string command =
      "/usr/bin/python3 " +
      Quote(std::string(ZEBRAGEO_SHARED_DIR) + "/tools/score_results.py") +
      " badinput " + Quote(survey) + " " + Quote(results) + " --exit-code " +
      std::to_string(code) + " --stderr " + Quote(err_path) + " > " +
      Quote(folder.Path("score.out")) + " 2>&1";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << "score_results.py badinput: "
      << ReadWholeFile(folder.Path("score.out"));
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, BadSurvey, ::testing::ValuesIn(BadSurveyKinds()),
    [](const ::testing::TestParamInfo<BadSurveyKind>& param) {
      return param.param.name;
    });

// The independent checker the BadSurvey cases rely on must itself tell a
// bad outcome from a good one: on hand-made outcomes of an "error" survey
// and a "warning" survey (truth/meta.json as `simulate --bad` writes it), it
// accepts the honest ones and rejects exit 0 where an error is due, outputs
// left behind an error, a crash, a silent exit, a missing output, and a
// finished run without a warning.
struct ScorerCase {
  std::string name;
  std::string expect;                // meta.json's "expect": error or warning
  int exit_code;                     // what the run is said to have returned
  std::string stderr_text;           // what it is said to have printed
  std::vector<std::string> outputs;  // contract outputs in the results
  bool report_warns;                 // report.json holds a warning
  bool accepted;                     // the scorer's expected verdict
  std::string says;                  // in the scorer's one-line verdict
};

TEST(BadSurveyScorer, AcceptsHonestOutcomesAndRejectsDishonestOnes) {
  std::string why;
  if (!ScorerAvailable(&why)) {
    GTEST_SKIP() << "score_results.py badinput is not run by the BadSurvey "
                    "cases: "
                 << why;
  }
  const std::string message =
      "zebrageo: error: rig.yaml:7: camera 'left' K: fx and fy must be > 0\n";
  std::vector<std::string> all_but_report(kOutputs.begin(), kOutputs.end() - 1);
  const std::vector<ScorerCase> cases = {
      {"clear_error", "error", 1, message, {}, false, true, "clear error"},
      {"error_exit_zero", "error", 0, "", kOutputs, true, false,
       "exit 0 where an error was expected"},
      {"error_leaves_outputs",
       "error",
       1,
       message,
       {"poses.csv"},
       false,
       false,
       "outputs left behind: poses.csv"},
      {"error_without_message",
       "error",
       1,
       "",
       {},
       false,
       false,
       "without a message"},
      {"crash",
       "error",
       134,
       "terminate called after throwing\n",
       {},
       false,
       false,
       "crashed (exit 134)"},
      {"abort_message",
       "error",
       1,
       "Aborted (core dumped)\n",
       {},
       false,
       false,
       "crashed"},
      {"warned_result", "warning", 0, "", kOutputs, true, true,
       "finished with warnings"},
      {"warning_survey_fails",
       "warning",
       1,
       message,
       {},
       false,
       false,
       "still usable"},
      {"warning_output_missing", "warning", 0, "", all_but_report, true, false,
       "outputs missing: report.json"},
      {"finished_without_warning", "warning", 0, "", kOutputs, false, false,
       "without a warning"},
  };
  for (const ScorerCase& c : cases) {
    SCOPED_TRACE(c.name);
    TemporaryFolder folder;
    const std::string survey = folder.Path("survey");
    const std::string results = folder.Path("results");
    const json meta = {{"bad", "bad_focal"}, {"expect", c.expect}};
    folder.Write("survey/truth/meta.json", meta.dump(2));
    fs::create_directories(results);
    for (const std::string& output : c.outputs) {
      std::string text = "x\n";
      if (output == "report.json") {
        text = json{{"warnings", c.report_warns ? json::array({"a warning"})
                                                : json::array()}}
                   .dump();
      }
      folder.Write("results/" + output, text);
    }
    const std::string err_path = folder.Write("run.err", c.stderr_text);
    const std::string command =
        "/usr/bin/python3 " +
        Quote(std::string(ZEBRAGEO_SHARED_DIR) + "/tools/score_results.py") +
        " badinput " + Quote(survey) + " " + Quote(results) + " --exit-code " +
        std::to_string(c.exit_code) + " --stderr " + Quote(err_path) + " > " +
        Quote(folder.Path("score.out")) + " 2>&1";
    const int status = std::system(command.c_str());
    const std::string verdict = ReadWholeFile(folder.Path("score.out"));
    ASSERT_TRUE(WIFEXITED(status)) << verdict;
    EXPECT_EQ(WEXITSTATUS(status), c.accepted ? 0 : 1) << verdict;
    EXPECT_NE(verdict.find(c.says), std::string::npos)
        << verdict << "\n  lacks: " << c.says;
  }
}

TEST(BadSurveyKinds, UnknownKindIsAUsageError) {
  TemporaryFolder folder;
  EXPECT_EQ(RunZebrageo("simulate --bad nope -o " + Quote(folder.Path("s")),
                        folder.Path("out"), folder.Path("err")),
            2);
  EXPECT_TRUE(
      Contains(ReadWholeFile(folder.Path("err")),
               "--bad nope: not a kind \\(kinds: truncated_trajectory"));
  EXPECT_FALSE(fs::exists(folder.Path("s")));
}

}  // namespace
}  // namespace zebrageo
