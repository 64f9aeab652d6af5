// Issue 18: surveys that are valid but wrong, and surveys that reach
// outside their folder. Each case starts from `zebrageo simulate --preset
// demo --seed 5`, makes the issue's edit in a copy and drives the real
// binary: exit status, stderr's last line (file, line, problem),
// report.json's warnings (each warning stderr shows is listed there), no
// output of the contract left on error, and, where the survey is usable, a
// result no worse than the input by ../shared/tools/score_results.py.
//
// The demo survey takes about 60 s of CPU to render: it is made once per
// build of zebrageo, with a reference run, and kept in the system's
// temporary folder for every process of this binary (ctest runs each test
// in its own). A case copies it (images hard-linked) and runs only the
// command it needs.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
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
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<std::string> kContractOutputs = {
    "trajectory_corrected.csv", "poses.csv", "bands.geojson",
    "gcp_residuals.csv", "report.json"};

bool Contains(const std::string& text, const std::string& pattern) {
  return std::regex_search(text, std::regex(pattern));
}

std::string LastLine(const std::string& text) {
  std::string trimmed = text;
  while (!trimmed.empty() && trimmed.back() == '\n') trimmed.pop_back();
  return trimmed.substr(trimmed.rfind('\n') + 1);
}

void WriteFile(const std::string& path, const std::string& text) {
  // Remove first: the images of a copy are hard links to the cached survey.
  fs::remove(path);
  std::ofstream(path, std::ios::binary) << text;
}

// ------------------------------------------------------------ the demo

// "size:mtime" of the zebrageo binary: a rebuilt simulator makes a new demo.
std::string BinaryStamp() {
  const auto size = fs::file_size(ZEBRAGEO_BINARY);
  const auto time = fs::last_write_time(ZEBRAGEO_BINARY);
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
const Demo& CachedDemo() {
  static Demo* demo = nullptr;
  if (demo != nullptr) return *demo;
  const fs::path temp =
      fs::path(ZEBRAGEO_BINARY).parent_path().parent_path() / "test-cache";
  fs::create_directories(temp);
  const std::string prefix = "zebrageo-issue18-";
  const fs::path folder = temp / (prefix + BinaryStamp());
  demo = new Demo{(folder / "demo5").string(), (folder / "reference").string(),
                  (folder / "reference.err").string()};
  const int lock = ::open((temp / "zebrageo-issue18.lock").c_str(),
                          O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  EXPECT_GE(lock, 0);
  EXPECT_EQ(::flock(lock, LOCK_EX), 0);
  if (!fs::exists(folder / "complete")) {
    for (const auto& entry : fs::directory_iterator(temp)) {
      if (entry.path().filename().string().rfind(prefix, 0) == 0) {
        fs::remove_all(entry.path());
      }
    }
    fs::create_directories(folder);
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

std::string Number(double value) {
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
    fs::create_directories(to);
    for (const auto& entry : fs::recursive_directory_iterator(from)) {
      const fs::path target = to / fs::relative(entry.path(), from);
      if (entry.is_directory()) {
        fs::create_directories(target);
        continue;
      }
      std::error_code error;
      if (entry.path().extension() == ".png") {
        fs::create_hard_link(entry.path(), target, error);
      }
      if (error || entry.path().extension() != ".png") {
        fs::copy_file(entry.path(), target);
      }
    }
    t0_ = std::stod(Csv::Read(to + "/trajectory.csv").rows.front()[0]);
    return to;
  }
  // A copy of the reference run's results folder.
  std::string CopyOfReference(const std::string& name = "results") {
    const std::string to = folder_.Path(name);
    fs::copy(CachedDemo().reference, to, fs::copy_options::recursive);
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
      EXPECT_FALSE(fs::exists(results + "/" + output)) << output << " left";
    }
    EXPECT_FALSE(fs::exists(results + "/report.html"));
    for (const std::string& file : FilesUnder(results)) {
      EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
    }
  }

  // report.json's warnings, and a check that each warning stderr shows is
  // one of them.
  static std::vector<std::string> ReportWarnings(const std::string& results,
                                                 const std::string& err) {
    std::vector<std::string> warnings;
    const json report = json::parse(ReadWholeFile(results + "/report.json"));
    for (const json& w : report.at("warnings")) warnings.push_back(w);
    std::istringstream lines(err);
    const std::regex glog_warning(
        R"(^W[0-9]{8} [0-9:.]+ +[0-9]+ [^\]]+\] (.*)$)");
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
    if (!fs::exists("/usr/bin/python3") || !fs::exists(scorer)) {
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

// ------------------------------------------------ bad: wrong results, time

TEST_F(HostileSurvey, AThreeSecondHoleWithExposuresInsideIsAnErrorNamingThem) {
  const std::string survey = CopyOfDemo();
  Csv trajectory = Csv::Read(survey + "/trajectory.csv");
  trajectory.Filter([&](const auto& row) {
    const double t = std::stod(row[0]);
    return !(t > t0_ + 6 && t < t0_ + 9);
  });
  trajectory.Write(survey + "/trajectory.csv");
  const std::string results = folder_.Path("results");
  // Before: exit 0, attitude 0.063 -> 1.13 deg, no warning.
  ExpectInputError(
      Run(survey, results),
      R"(exposures\.csv:[0-9]+: exposure [0-9]+ at t = [0-9.]+ falls in a gap )"
      R"(of trajectory\.csv: 3\.00 s with no sample \(t = [0-9.]+ on line )"
      R"([0-9]+ to [0-9.]+ on line [0-9]+\); its pose would be interpolated)",
      results);
  EXPECT_FALSE(fs::exists(results)) << "a refused survey creates nothing";
}

TEST_F(HostileSurvey, AThreeSecondHoleBetweenExposuresIsWarnedAndNoWorse) {
  const std::string survey = CopyOfDemo();
  auto outside_hole = [&](double t) { return !(t > t0_ + 6 && t < t0_ + 9); };
  Csv trajectory = Csv::Read(survey + "/trajectory.csv");
  trajectory.Filter(
      [&](const auto& row) { return outside_hole(std::stod(row[0])); });
  trajectory.Write(survey + "/trajectory.csv");
  Csv exposures = Csv::Read(survey + "/exposures.csv");
  exposures.Filter(
      [&](const auto& row) { return outside_hole(std::stod(row[1])); });
  exposures.Write(survey + "/exposures.csv");
  const std::string results = folder_.Path("results");
  const Outcome outcome = Run(survey, results);
  ASSERT_EQ(outcome.code, 0) << outcome.err;
  const std::vector<std::string> warnings =
      ReportWarnings(results, outcome.err);
  EXPECT_TRUE(AnyContains(warnings,
                          R"(^trajectory\.csv: 1 gap in the GNSS/INS solution )"
                          R"(.*3\.00 s with no sample)"));
  // Nothing is built across the gap: no jump, no chord through it. Before
  // the fix: attitude 0.038 -> 1.17 deg.
  EXPECT_FALSE(AnyContains(warnings, "jumps in the GNSS/INS trajectory"));
  EXPECT_TRUE(ScoreNoWorseThanTheInput(
      survey, results, "--not-worse --att-not-worse-deg 0 --max-att-deg 0.03"));
}

// The trajectory after t0 + 9 s moved 600 s later, the exposures too when
// `with_exposures`.
void ShiftTenMinutes(const std::string& survey, double t0,
                     bool with_exposures) {
  Csv trajectory = Csv::Read(survey + "/trajectory.csv");
  for (auto& row : trajectory.rows) {
    const double t = std::stod(row[0]);
    if (t > t0 + 9) row[0] = Number(t + 600);
  }
  trajectory.Write(survey + "/trajectory.csv");
  if (!with_exposures) return;
  Csv exposures = Csv::Read(survey + "/exposures.csv");
  for (auto& row : exposures.rows) {
    const double t = std::stod(row[1]);
    if (t > t0 + 9) row[1] = Number(t + 600);
  }
  exposures.Write(survey + "/exposures.csv");
}

TEST_F(HostileSurvey, ExposuresInATenMinuteGapAreAnErrorNotAQuarterHourSolve) {
  const std::string survey = CopyOfDemo();
  ShiftTenMinutes(survey, t0_, false);
  const std::string results = folder_.Path("results");
  // Before: more than 15 minutes of adjustment, no warning.
  ExpectInputError(
      Run(survey, results),
      R"(exposures\.csv:[0-9]+: exposure [0-9]+ at t = [0-9.]+ falls in a gap )"
      R"(of trajectory\.csv: 600\.01 s with no sample.*\([0-9]+ exposures are )"
      R"(in gaps longer than max_exposure_gap_s = 1 s\))",
      results);
}

TEST_F(HostileSurvey, ATenMinuteGapBetweenExposuresIsWarnedAndAdjusted) {
  const std::string survey = CopyOfDemo();
  ShiftTenMinutes(survey, t0_, true);
  const std::string results = folder_.Path("results");
  // Before: exit 3, "Ceres failed: Residual and Jacobian evaluation
  // failed", naming nothing.
  const Outcome outcome = Run(survey, results);
  ASSERT_EQ(outcome.code, 0) << outcome.err;
  EXPECT_TRUE(AnyContains(ReportWarnings(results, outcome.err),
                          R"(600\.01 s with no sample \(t = [0-9.]+ on line )"
                          R"([0-9]+ to [0-9.]+ on line [0-9]+\))"));
  // The truth covers the exposures before the gap (it was not shifted).
  EXPECT_TRUE(ScoreNoWorseThanTheInput(survey, results,
                                       "--not-worse --att-not-worse-deg 0"));
}

TEST_F(HostileSurvey, AnglesInRadiansAreAnErrorNamingTheColumns) {
  const std::string survey = CopyOfDemo();
  Csv trajectory = Csv::Read(survey + "/trajectory.csv");
  for (auto& row : trajectory.rows) {
    for (int column = 4; column <= 6; ++column) {
      row[column] = Number(std::stod(row[column]) * M_PI / 180.0);
    }
  }
  trajectory.Write(survey + "/trajectory.csv");
  const std::string results = folder_.Path("results");
  // Before: exit 0, a 7 m correction "without control", attitude 60 deg.
  ExpectInputError(
      Run(survey, results),
      R"(trajectory\.csv: columns 'roll', 'pitch', 'heading' look like )"
      R"(radians, not degrees: read as degrees, the heading differs from the )"
      R"(direction of travel by 6[0-9]\.[0-9] deg, read as radians by )"
      R"(0\.[0-9] deg \(median over [0-9]+ stretches of 1 s, lines 2-[0-9]+\))",
      results);
}

TEST_F(HostileSurvey, FilesOutsideTheSurveyAreRefusedNeverUsed) {
  const std::string survey = CopyOfDemo();
  // A valid image and a valid trajectory beside the survey.
  const std::string outside_png = folder_.Path("outside.png");
  fs::copy_file(survey + "/images/001000_left.png", outside_png);
  const std::string outside_csv = folder_.Path("outside.csv");
  fs::copy_file(survey + "/trajectory.csv", outside_csv);
  const std::string manifest = ReadWholeFile(survey + "/survey.yaml");
  const std::string exposures = ReadWholeFile(survey + "/exposures.csv");
  auto with_image = [&](const std::string& image) {
    // exposures.csv's line 6 is exposure 1002's left image.
    Csv csv = Csv::Read(survey + "/exposures.csv");
    csv.rows[4][3] = image;
    csv.Write(survey + "/exposures.csv");
  };
  struct Case {
    std::string what;
    std::function<void()> edit;
    std::string message;
  };
  const std::string outside =
      R"(, outside the survey folder: a survey names only files inside it, )"
      R"(symbolic links included \(zebrageo --allow-outside-paths)";
  const std::vector<Case> cases = {
      {"image /etc/passwd", [&] { with_image("/etc/passwd"); },
       R"(exposures\.csv:6: image /etc/passwd is an absolute path: a survey )"
       R"(names its files relative to its folder)"},
      {"image ../../../../../../etc/passwd",
       [&] { with_image("../../../../../../etc/passwd"); },
       R"(exposures\.csv:6: image \.\./\.\./\.\./\.\./\.\./\.\./etc/passwd )"
       R"(resolves to /etc/passwd)" +
           outside},
      {"a valid PNG outside", [&] { with_image("../outside.png"); },
       R"(exposures\.csv:6: image \.\./outside\.png resolves to .*/outside\.png)" +
           outside},
      {"a link to a valid PNG outside",
       [&] {
         fs::remove(survey + "/images/001002_left.png");
         fs::create_symlink(outside_png, survey + "/images/001002_left.png");
       },
       R"(exposures\.csv:6: image images/001002_left\.png resolves to )"
       R"(.*/outside\.png)" +
           outside},
      {"a valid trajectory outside",
       [&] {
         WriteFile(survey + "/survey.yaml",
                   std::regex_replace(manifest, std::regex("trajectory.csv"),
                                      "../outside.csv"));
       },
       R"(survey\.yaml:3: 'trajectory' names \.\./outside\.csv, which )"
       R"(resolves to .*/outside\.csv)" +
           outside},
      {"trajectory: ../../../../etc/shadow",
       [&] {
         WriteFile(survey + "/survey.yaml",
                   std::regex_replace(manifest, std::regex("trajectory.csv"),
                                      "../../../../etc/shadow"));
       },
       R"(survey\.yaml:3: 'trajectory' names \.\./\.\./\.\./\.\./etc/shadow, )"
       R"(which resolves to /etc/shadow)" +
           outside},
      {"rig: /etc/passwd",
       [&] {
         WriteFile(survey + "/survey.yaml",
                   std::regex_replace(manifest, std::regex("rig.yaml"),
                                      "/etc/passwd"));
       },
       R"(survey\.yaml:2: 'rig' names /etc/passwd, which is an absolute path)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    WriteFile(survey + "/survey.yaml", manifest);
    WriteFile(survey + "/exposures.csv", exposures);
    c.edit();
    const std::string results = folder_.Path("results");
    // Before: read, parsed, or used without a word.
    ExpectInputError(Run(survey, results), c.message, results);
    EXPECT_FALSE(fs::exists(results));
  }
  // For one's own surveys: the opt-out reads the trajectory outside.
  WriteFile(survey + "/survey.yaml",
            std::regex_replace(manifest, std::regex("trajectory.csv"),
                               "../outside.csv"));
  WriteFile(survey + "/exposures.csv", exposures);
  const Outcome trusted =
      Zebrageo("check --allow-outside-paths " + Quote(survey), "trusted");
  EXPECT_EQ(trusted.code, 0) << trusted.err;
}

// A PNG of width x height 8-bit grey pixels, all zero, written by
// streaming rows through zlib (20000x20000 is 389 KB on disk).
void WriteZeroPng(const std::string& path, uint32_t width, uint32_t height) {
  auto big_endian = [](uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                       static_cast<char>(v >> 8), static_cast<char>(v)};
  };
  auto chunk = [&](const std::string& type, const std::string& data) {
    const std::string body = type + data;
    const uLong crc = crc32(0, reinterpret_cast<const Bytef*>(body.data()),
                            static_cast<uInt>(body.size()));
    return big_endian(static_cast<uint32_t>(data.size())) + body +
           big_endian(static_cast<uint32_t>(crc));
  };
  z_stream z{};
  ASSERT_EQ(deflateInit(&z, Z_DEFAULT_COMPRESSION), Z_OK);
  const std::string row(width + 1, '\0');  // filter byte, then the pixels
  std::string idat;
  char buffer[1 << 16];
  for (uint32_t r = 0; r <= height; ++r) {
    const bool last = r == height;
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(row.data()));
    z.avail_in = last ? 0 : static_cast<uInt>(row.size());
    do {
      z.next_out = reinterpret_cast<Bytef*>(buffer);
      z.avail_out = sizeof(buffer);
      deflate(&z, last ? Z_FINISH : Z_NO_FLUSH);
      idat.append(buffer, sizeof(buffer) - z.avail_out);
    } while (z.avail_out == 0);
  }
  deflateEnd(&z);
  const std::string ihdr = big_endian(width) + big_endian(height) +
                           std::string("\x08\x00\x00\x00\x00", 5);
  WriteFile(path, std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) +
                      chunk("IDAT", idat) + chunk("IEND", ""));
}

TEST_F(HostileSurvey, AHugePngIsRefusedFromItsHeaderAndItsExposureHasNoPose) {
  const std::string survey = CopyOfDemo();
  const std::string image = survey + "/images/001010_left.png";
  WriteZeroPng(image, 20000, 20000);
  ASSERT_LT(fs::file_size(image), 500000u);
  const std::string results = folder_.Path("results");
  const Outcome outcome = Run(survey, results);
  ASSERT_EQ(outcome.code, 0) << outcome.err;
  // Before: 2.08 GB of memory (a normal run takes 240 MB) to decode it.
  rusage usage{};
  ASSERT_EQ(getrusage(RUSAGE_CHILDREN, &usage), 0);
  const double peak_mb = usage.ru_maxrss / 1024.0;
  std::cout << "[  MEMORY  ] largest child's peak: " << peak_mb << " MB\n";
  EXPECT_LT(peak_mb, 600.0);
  EXPECT_TRUE(AnyContains(
      ReportWarnings(results, outcome.err),
      R"(exposure 1010: images/001010_left\.png: image is 20000x20000 pixels, )"
      R"(more than the limit of 64 megapixels \(from its header; not )"
      R"(decoded\): exposure skipped)"));
  // A skipped exposure gets no row in poses.csv; every other one has both.
  const Csv poses = Csv::Read(results + "/poses.csv");
  int skipped_rows = 0;
  for (const auto& row : poses.rows) skipped_rows += row[0] == "1010";
  EXPECT_EQ(skipped_rows, 0);
  const Csv exposures = Csv::Read(survey + "/exposures.csv");
  EXPECT_EQ(poses.rows.size(), exposures.rows.size() - 2);
  EXPECT_TRUE(Contains(ReadWholeFile(results + "/skipped_exposures.csv"),
                       "\n1010,exposure 1010: images/001010_left.png"));
}

// --------------------------------------------- weak: right, but unclear

TEST_F(HostileSurvey, ByteOrderMarksAreAccepted) {
  const std::string survey = CopyOfDemo();
  for (const char* file :
       {"trajectory.csv", "exposures.csv", "survey.yaml", "rig.yaml"}) {
    WriteFile(survey + "/" + file,
              "\xEF\xBB\xBF" + ReadWholeFile(survey + "/" + file));
  }
  // Before: "trajectory.csv:1: header lacks required column 'time'".
  const Outcome outcome = Zebrageo("check " + Quote(survey));
  EXPECT_EQ(outcome.code, 0) << outcome.err;
  EXPECT_TRUE(Contains(ReadWholeFile(folder_.Path("run.out")),
                       "1810 trajectory samples over 18.09 s, 53 exposures, "
                       "106 images"));
}

TEST_F(HostileSurvey, SwappedLatitudeAndLongitudeAreAClearError) {
  const std::string survey = CopyOfDemo();
  Csv trajectory = Csv::Read(survey + "/trajectory.csv");
  for (auto& row : trajectory.rows) std::swap(row[1], row[2]);
  trajectory.Write(survey + "/trajectory.csv");
  const std::string results = folder_.Path("results");
  // Before: exit 0, poses 6,584 km from the origin, "no zebra crossing was
  // matched".
  ExpectInputError(Run(survey, results),
                   R"(trajectory\.csv:[0-9]+: latitude and longitude look )"
                   R"(swapped: \(lat, lon\) \(2\.29[0-9]+, 49\.89[0-9]+\) is )"
                   R"(69[0-9]{2} km from survey\.yaml's origin)",
                   results);
  // Without an origin in survey.yaml the trajectory makes its own frame:
  // the database is then what is far away.
  const std::string manifest = ReadWholeFile(survey + "/survey.yaml");
  WriteFile(survey + "/survey.yaml",
            std::regex_replace(manifest, std::regex("origin:.*\n"), ""));
  ExpectInputError(Run(survey, results),
                   R"(roadmarks\.geojson: the nearest of its [0-9]+ road-mark )"
                   R"(vertices .* is 69[0-9]{2} km from the trajectory .*: )"
                   R"(latitude and longitude of trajectory\.csv look swapped)",
                   results);
}

TEST_F(HostileSurvey, ADatabaseOfAnotherPlaceIsAClearError) {
  const std::string survey = CopyOfDemo();
  // 54 degrees of latitude south: about 6,000 km.
  json database = json::parse(ReadWholeFile(survey + "/roadmarks.geojson"));
  for (json& feature : database["features"]) {
    json& coordinates = feature["geometry"]["coordinates"];
    auto move = [](json& position) {
      position[1] = position[1].get<double>() - 54.0;
    };
    if (feature["geometry"]["type"] == "Polygon") {
      for (json& ring : coordinates) {
        for (json& position : ring) move(position);
      }
    } else {
      for (json& position : coordinates) move(position);
    }
  }
  WriteFile(survey + "/roadmarks.geojson", database.dump());
  const std::string results = folder_.Path("results");
  // Before: exit 0, "not adjusted: no control", the trajectory moved by
  // 0.23 m and 7 cm worse. Now no trajectory is written at all.
  ExpectInputError(
      Run(survey, results),
      R"(roadmarks\.geojson: the nearest of its [0-9]+ road-mark )"
      R"(vertices \(-4\.[0-9]+, 2\.[0-9]+\) is 59[0-9]{2} km from )"
      R"(the trajectory \(trajectory\.csv line [0-9]+, .*\), more )"
      R"(than max_database_distance_m = 5000 m; nothing in it can )"
      R"(control the trajectory)",
      results);
}

TEST_F(HostileSurvey, AFolderOrALoopWhereAFileIsExpectedIsNamedAsSuch) {
  const std::string survey = CopyOfDemo();
  const std::string manifest = ReadWholeFile(survey + "/survey.yaml");
  WriteFile(
      survey + "/survey.yaml",
      std::regex_replace(manifest, std::regex("trajectory.csv"), "images"));
  // Before: "'trajectory' names images, which does not exist".
  const Outcome folder = Zebrageo("check " + Quote(survey), "folder");
  EXPECT_EQ(folder.code, 1);
  EXPECT_TRUE(Contains(folder.last,
                       "survey\\.yaml:3: 'trajectory' names images, which is a "
                       "folder, not a file"))
      << folder.last;
  WriteFile(survey + "/survey.yaml", manifest);
  fs::remove(survey + "/images/001000_left.png");
  fs::create_directory(survey + "/images/001000_left.png");
  fs::remove(survey + "/images/001000_right.png");
  fs::create_symlink("001000_right.png", survey + "/images/001000_right.png");
  const Outcome images = Zebrageo("check " + Quote(survey), "images");
  EXPECT_EQ(images.code, 0) << images.err;
  const std::string out = ReadWholeFile(folder_.Path("images.out"));
  EXPECT_TRUE(Contains(out,
                       "warning: exposures\\.csv:2: image "
                       "images/001000_left\\.png is a folder, not a file"))
      << out;
  EXPECT_TRUE(Contains(out,
                       "warning: exposures\\.csv:3: image "
                       "images/001000_right\\.png is a loop of symbolic links"))
      << out;
}

TEST_F(HostileSurvey, ADuplicateKeyIsRefused) {
  const std::string survey = CopyOfDemo();
  WriteFile(survey + "/survey.yaml", ReadWholeFile(survey + "/survey.yaml") +
                                         "trajectory: truth/trajectory.csv\n");
  // Before: the first value read, the reference reader takes the last.
  const Outcome outcome = Zebrageo("check " + Quote(survey));
  EXPECT_EQ(outcome.code, 1);
  EXPECT_TRUE(Contains(outcome.last,
                       "survey\\.yaml:7: duplicate key 'trajectory' \\(first "
                       "on line 3\\)"))
      << outcome.last;
}

TEST_F(HostileSurvey, AResultsPathThatIsAFileIsAUsageError) {
  const std::string survey = CopyOfDemo();
  const std::string file = folder_.Write("results.txt", "my notes\n");
  // Before: exit 5, "internal error".
  const Outcome outcome = Run(survey, file);
  EXPECT_EQ(outcome.code, 2) << outcome.err;
  EXPECT_TRUE(Contains(outcome.err,
                       "results\\.txt is a file, not a results "
                       "folder"))
      << outcome.err;
  EXPECT_EQ(ReadWholeFile(file), "my notes\n");
}

TEST_F(HostileSurvey, ASecondCommandOnABusyResultsFolderIsRefused) {
  const std::string survey = CopyOfDemo();
  const std::string results = CopyOfReference();
  const std::string poses = ReadWholeFile(results + "/poses.csv");
  // Another zebrageo holds the folder: this test, as pid 4242.
  const int fd = ::open((results + "/.zebrageo.lock").c_str(),
                        O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  ASSERT_EQ(::ftruncate(fd, 0), 0);
  ASSERT_EQ(::pwrite(fd, "pid 4242\n", 9, 0), 9);
  // Before: both runs exit 0, the slower overwrites the faster.
  for (const std::string command : {"run", "adjust", "report"}) {
    SCOPED_TRACE(command);
    const Outcome outcome =
        Zebrageo(command + " " + Quote(survey) + " -o " + Quote(results));
    EXPECT_EQ(outcome.code, 2) << outcome.err;
    EXPECT_TRUE(Contains(outcome.last,
                         "results folder .* is in use by another zebrageo "
                         "process \\(pid 4242\\): wait for it to finish or "
                         "choose another -o"))
        << outcome.last;
    // Its outputs are not touched.
    EXPECT_EQ(ReadWholeFile(results + "/poses.csv"), poses);
  }
  ::close(fd);
  const Outcome free =
      Zebrageo("report " + Quote(survey) + " -o " + Quote(results), "free");
  EXPECT_EQ(free.code, 0) << free.err;
}

TEST_F(HostileSurvey, DiskFullLateInAdjustLeavesNoContractOutput) {
  const std::string survey = CopyOfDemo();
  const std::string results = CopyOfReference();
  // The disk fills up at the last file adjust writes (a test-only seam of
  // survey/atomic_file.h: a full tmpfs needs root).
  ASSERT_EQ(::setenv("ZEBRAGEO_FAIL_WRITE", "poses.csv", 1), 0);
  const Outcome outcome =
      Zebrageo("adjust " + Quote(survey) + " -o " + Quote(results));
  ::unsetenv("ZEBRAGEO_FAIL_WRITE");
  EXPECT_EQ(outcome.code, 5) << outcome.err;
  EXPECT_TRUE(Contains(outcome.last,
                       "cannot write .*poses\\.csv \\(disk "
                       "full\\?\\)"))
      << outcome.last;
  // Before: trajectory_corrected.csv, bands.geojson, gcp_residuals.csv and
  // report.json left behind. The earlier run's are gone too: they would not
  // match the stage files any more.
  ExpectNoContractOutput(results);
  // The stage outputs stay: a rerun resumes.
  EXPECT_TRUE(fs::exists(results + "/matches.csv"));
  EXPECT_TRUE(fs::exists(results + "/reconstructed_bands.csv"));
}

TEST_F(HostileSurvey, AFailedRerunRemovesTheEarlierContractOutputs) {
  const std::string survey = CopyOfDemo();
  const std::string results = CopyOfReference();
  Csv trajectory = Csv::Read(survey + "/trajectory.csv");
  trajectory.rows[100][3] = "nan";
  trajectory.Write(survey + "/trajectory.csv");
  ExpectInputError(Run(survey, results),
                   R"(trajectory\.csv:102: column 'h': "nan" is not finite)",
                   results);
  EXPECT_TRUE(fs::exists(results + "/reconstructed_bands.csv"));
}

TEST_F(HostileSurvey, TrajectoriesBelowTenHertzAreWarnedInTheReport) {
  const std::string survey = CopyOfDemo();
  const Csv full = Csv::Read(survey + "/trajectory.csv");
  for (const int hz : {5, 1}) {
    Csv slow = full;
    const int step = 100 / hz;
    slow.rows.clear();
    for (size_t i = 0; i < full.rows.size(); i += step) {
      slow.rows.push_back(full.rows[i]);
    }
    if ((full.rows.size() - 1) % step) slow.rows.push_back(full.rows.back());
    slow.Write(survey + "/trajectory.csv");
    const std::string pattern = "trajectory\\.csv: " + std::to_string(hz) +
                                "\\.0 Hz \\(median sample interval [0-9.]+ "
                                "s\\) is below the 10 Hz the survey format "
                                "asks for";
    if (hz == 1) {
      // Before: no word. `check` shows what run would report.
      const Outcome check = Zebrageo("check " + Quote(survey), "check");
      EXPECT_EQ(check.code, 0);
      EXPECT_TRUE(Contains(ReadWholeFile(folder_.Path("check.out")),
                           "warning: " + pattern));
      continue;
    }
    const std::string results = folder_.Path("results");
    const Outcome outcome = Run(survey, results);
    ASSERT_EQ(outcome.code, 0) << outcome.err;
    EXPECT_TRUE(AnyContains(ReportWarnings(results, outcome.err), pattern));
    EXPECT_TRUE(ScoreNoWorseThanTheInput(survey, results,
                                         "--not-worse --att-not-worse-deg 0"));
  }
}

TEST_F(HostileSurvey, EveryWarningOfTheReferenceRunIsInItsReport) {
  const Demo& demo = CachedDemo();
  const std::vector<std::string> warnings =
      ReportWarnings(demo.reference, ReadWholeFile(demo.reference_err));
  EXPECT_FALSE(warnings.empty());
  // Each once.
  std::vector<std::string> sorted = warnings;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
}

}  // namespace
}  // namespace zebrageo
