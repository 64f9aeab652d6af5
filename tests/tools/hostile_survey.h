// The fixture of the tests of issue 18 (hostile_survey_test.cc,
// hostile_survey_unclear_test.cc): surveys that are valid but wrong, and
// surveys that reach outside their folder. Each case starts from `zebrageo
// simulate --preset demo --seed 5`, makes the issue's edit in a copy and
// drives the real binary: exit status, stderr's last line (file, line,
// problem), report.json's warnings (each warning stderr shows is listed
// there), no output of the contract left on error, and, where the survey is
// usable, a result no worse than the input by ../shared/tools/score_results.py.
//
// The demo survey takes about 60 s of CPU to render: it is made once per
// build of zebrageo, with a reference run, and kept in the build tree for
// every process of both test binaries (ctest runs each test in its own). A
// case copies it (images hard-linked) and runs only the command it needs.
#ifndef ZEBRAGEO_TESTS_TOOLS_HOSTILE_SURVEY_H_
#define ZEBRAGEO_TESTS_TOOLS_HOSTILE_SURVEY_H_

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {

inline const std::vector<std::string> kContractOutputs = {
    "trajectory_corrected.csv", "poses.csv", "bands.geojson",
    "gcp_residuals.csv", "report.json"};

inline bool Contains(const std::string& text, const std::string& pattern) {
  return std::regex_search(text, std::regex(pattern));
}

inline std::string LastLine(const std::string& text) {
  std::string trimmed = text;
  while (!trimmed.empty() && trimmed.back() == '\n') trimmed.pop_back();
  return trimmed.substr(trimmed.rfind('\n') + 1);
}

inline void WriteFile(const std::string& path, const std::string& text) {
  // Remove first: the images of a copy are hard links to the cached survey.
  std::filesystem::remove(path);
  std::ofstream(path, std::ios::binary) << text;
}

// ------------------------------------------------------------ the demo

// "size:mtime" of the zebrageo binary: a rebuilt simulator makes a new demo.
inline std::string BinaryStamp() {
  const auto size = std::filesystem::file_size(ZEBRAGEO_BINARY);
  const auto time = std::filesystem::last_write_time(ZEBRAGEO_BINARY);
  return std::to_string(size) + "-" +
         std::to_string(time.time_since_epoch().count());
}

// The cached demo survey and its reference run (folders and stderr).
struct Demo {
  std::string survey;
  std::string reference;
  std::string reference_err;
};

// Makes the cache once, under a lock so that parallel ctest processes wait
// for the first; removes the caches of older builds. It lives in the build
// tree (build/test-cache), not in /tmp: another build's tests (a second
// checkout on the same machine) would remove it while this one reads it.
inline const Demo& CachedDemo() {
  static Demo* demo = nullptr;
  if (demo != nullptr) return *demo;
  const std::filesystem::path temp =
      std::filesystem::path(ZEBRAGEO_BINARY).parent_path().parent_path() /
      "test-cache";
  std::filesystem::create_directories(temp);
  const std::string prefix = "zebrageo-issue18-";
  const std::filesystem::path folder = temp / (prefix + BinaryStamp());
  demo = new Demo{(folder / "demo5").string(), (folder / "reference").string(),
                  (folder / "reference.err").string()};
  const int lock = ::open((temp / "zebrageo-issue18.lock").c_str(),
                          O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  EXPECT_GE(lock, 0);
  EXPECT_EQ(::flock(lock, LOCK_EX), 0);
  if (!std::filesystem::exists(folder / "complete")) {
    for (const auto& entry : std::filesystem::directory_iterator(temp)) {
      if (entry.path().filename().string().rfind(prefix, 0) == 0) {
        std::filesystem::remove_all(entry.path());
      }
    }
    std::filesystem::create_directories(folder);
    const std::string log = (folder / "simulate.err").string();
    EXPECT_EQ(RunZebrageo("--log-level error simulate --preset demo --seed 5 "
                          "-o " +
                              Quote(demo->survey),
                          (folder / "simulate.out").string(), log),
              0)
        << ReadWholeFile(log);
    EXPECT_EQ(
        RunZebrageo("--log-level warning run " + Quote(demo->survey) + " -o " +
                        Quote(demo->reference) + " --threads 2",
                    (folder / "reference.out").string(), demo->reference_err),
        0)
        << ReadWholeFile(demo->reference_err);
    std::ofstream(folder / "complete") << "ok\n";
  }
  ::close(lock);
  return *demo;
}

// ------------------------------------------------------------ CSV edits

struct Csv {
  std::string header;
  std::vector<std::vector<std::string>> rows;

  // `#` comment lines are dropped (rewritten files have none).
  static Csv Read(const std::string& path) {
    Csv csv;
    std::istringstream in(ReadWholeFile(path));
    while (std::getline(in, csv.header) && csv.header.rfind('#', 0) == 0) {
    }
    for (std::string line; std::getline(in, line);) {
      if (line.rfind('#', 0) == 0) continue;
      std::vector<std::string> fields;
      std::istringstream fields_in(line);
      for (std::string f; std::getline(fields_in, f, ',');) {
        fields.push_back(f);
      }
      csv.rows.push_back(fields);
    }
    return csv;
  }
  void Write(const std::string& path) const {
    std::string text = header + "\n";
    for (const auto& row : rows) {
      for (size_t i = 0; i < row.size(); ++i) {
        text += (i ? "," : "") + row[i];
      }
      text += "\n";
    }
    WriteFile(path, text);
  }
  // Keeps the rows for which `keep` is true.
  void Filter(
      const std::function<bool(const std::vector<std::string>&)>& keep) {
    rows.erase(std::remove_if(rows.begin(), rows.end(),
                              [&](const auto& row) { return !keep(row); }),
               rows.end());
  }
};

inline std::string Number(double value) {
  std::ostringstream text;
  text.precision(17);
  text << value;
  return text.str();
}

// ------------------------------------------------------------ the fixture

struct Outcome {
  int code = -1;
  std::string err;
  std::string last;  // stderr's last line
};

class HostileSurvey : public ::testing::Test {
 protected:
  // A copy of the demo survey as `name` (the images hard-linked: edit them
  // with WriteFile, which replaces the link).
  std::string CopyOfDemo(const std::string& name = "survey") {
    const std::string from = CachedDemo().survey;
    const std::string to = folder_.Path(name);
    std::filesystem::create_directories(to);
    for (const auto& entry :
         std::filesystem::recursive_directory_iterator(from)) {
      const std::filesystem::path target =
          to / std::filesystem::relative(entry.path(), from);
      if (entry.is_directory()) {
        std::filesystem::create_directories(target);
        continue;
      }
      std::error_code error;
      if (entry.path().extension() == ".png") {
        std::filesystem::create_hard_link(entry.path(), target, error);
      }
      if (error || entry.path().extension() != ".png") {
        std::filesystem::copy_file(entry.path(), target);
      }
    }
    t0_ = std::stod(Csv::Read(to + "/trajectory.csv").rows.front()[0]);
    return to;
  }
  // A copy of the reference run's results folder.
  std::string CopyOfReference(const std::string& name = "results") {
    const std::string to = folder_.Path(name);
    std::filesystem::copy(CachedDemo().reference, to,
                          std::filesystem::copy_options::recursive);
    return to;
  }
  Outcome Zebrageo(const std::string& args, const std::string& name = "run") {
    Outcome outcome;
    const std::string err = folder_.Path(name + ".err");
    outcome.code = RunZebrageo("--log-level warning " + args,
                               folder_.Path(name + ".out"), err);
    outcome.err = ReadWholeFile(err);
    outcome.last = LastLine(outcome.err);
    return outcome;
  }
  Outcome Run(const std::string& survey, const std::string& results,
              const std::string& extra = "") {
    return Zebrageo("run " + Quote(survey) + " -o " + Quote(results) +
                    " --threads 2 " + extra);
  }

  // An error exit: invalid input, its message, and no output of the
  // contract (none at all when the survey is refused at loading).
  void ExpectInputError(const Outcome& outcome, const std::string& message,
                        const std::string& results) {
    EXPECT_EQ(outcome.code, 1) << outcome.err;
    EXPECT_TRUE(Contains(outcome.last, "^zebrageo: error: ")) << outcome.last;
    EXPECT_TRUE(Contains(outcome.last, message))
        << outcome.last << "\n  !~ " << message;
    ExpectNoContractOutput(results);
  }
  static void ExpectNoContractOutput(const std::string& results) {
    for (const std::string& output : kContractOutputs) {
      EXPECT_FALSE(std::filesystem::exists(results + "/" + output))
          << output << " left";
    }
    EXPECT_FALSE(std::filesystem::exists(results + "/report.html"));
    for (const std::string& file : FilesUnder(results)) {
      EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
    }
  }

  // report.json's warnings, and a check that each warning stderr shows is
  // one of them.
  static std::vector<std::string> ReportWarnings(const std::string& results,
                                                 const std::string& err) {
    std::vector<std::string> warnings;
    const nlohmann::json report =
        nlohmann::json::parse(ReadWholeFile(results + "/report.json"));
    for (const nlohmann::json& w : report.at("warnings")) warnings.push_back(w);
    std::istringstream lines(err);
    // zebrageo's console format ("12:24:26 warning: text"), or glog's
    // (--log-level debug).
    const std::regex glog_warning(
        R"(^(?:[0-9]{2}:[0-9]{2}:[0-9]{2} warning: |W[0-9]{8} [0-9:.]+ +[0-9]+ [^\]]+\] )(.*)$)");
    for (std::string line; std::getline(lines, line);) {
      std::smatch match;
      if (!std::regex_match(line, match, glog_warning)) continue;
      EXPECT_NE(std::find(warnings.begin(), warnings.end(), match[1].str()),
                warnings.end())
          << "on stderr, not in report.json: " << match[1].str();
    }
    return warnings;
  }
  static bool AnyContains(const std::vector<std::string>& texts,
                          const std::string& pattern) {
    return std::any_of(texts.begin(), texts.end(), [&](const std::string& t) {
      return Contains(t, pattern);
    });
  }

  // score_results.py poses with `flags`: true when it passes; skips (with
  // the reason) when the scorer is absent.
  bool ScoreNoWorseThanTheInput(const std::string& survey,
                                const std::string& results,
                                const std::string& flags) {
    const std::string scorer =
        std::string(ZEBRAGEO_SHARED_DIR) + "/tools/score_results.py";
    if (!std::filesystem::exists("/usr/bin/python3") ||
        !std::filesystem::exists(scorer)) {
      std::cout << "[  NOTE    ] " << scorer
                << " or /usr/bin/python3 absent: accuracy not scored\n";
      return true;
    }
    const std::string out = folder_.Path("score.out");
    const int status = std::system(
        ("/usr/bin/python3 " + Quote(scorer) + " poses " + Quote(survey) + " " +
         Quote(results) + " " + flags + " > " + Quote(out) + " 2>&1")
            .c_str());
    std::cout << "[  SCORE   ] " << ReadWholeFile(out);
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
  }

  TemporaryFolder folder_;
  double t0_ = 0.0;  // first trajectory time of the copy
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_TOOLS_HOSTILE_SURVEY_H_
