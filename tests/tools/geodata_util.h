// Helpers for the real-world geodata tests (issue 20): a small simulated
// survey reconstructed once, variants of it processed by the real binary,
// and PROJ's and GDAL's own command-line tools as independent references.
#ifndef ZEBRAGEO_TESTS_TOOLS_GEODATA_UTIL_H_
#define ZEBRAGEO_TESTS_TOOLS_GEODATA_UTIL_H_

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "survey/csv.h"
#include "survey/results.h"
#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {

namespace fs = std::filesystem;

// True when `program` is on the PATH.
inline bool HaveProgram(const std::string& program) {
  return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) ==
         0;
}

// Runs a shell command; its output (stdout and stderr) goes to `log`.
inline int Shell(const std::string& command, const std::string& log) {
  const int status =
      std::system((command + " >" + Quote(log) + " 2>&1").c_str());
  return status == -1 ? -1 : WEXITSTATUS(status);
}

// PROJ's cs2cs on many points: `in` rows of three numbers in the source
// CRS's axis order, the same rows out in the target's (EPSG:4979 reads lat
// lon h).
inline std::vector<Eigen::Vector3d> Cs2cs(
    const std::string& source, const std::string& target,
    const std::vector<Eigen::Vector3d>& points, const std::string& folder) {
  const std::string in = folder + "/cs2cs_in.txt";
  const std::string out = folder + "/cs2cs_out.txt";
  {
    std::ofstream stream(in);
    stream.precision(17);
    for (const Eigen::Vector3d& p : points) {
      stream << p.x() << " " << p.y() << " " << p.z() << "\n";
    }
  }
  const int status =
      std::system(("cs2cs -d 9 " + Quote(source) + " " + Quote(target) + " <" +
                   Quote(in) + " >" + Quote(out))
                      .c_str());
  std::vector<Eigen::Vector3d> result;
  if (status != 0) return result;
  std::ifstream stream(out);
  double x, y, z;
  while (stream >> x >> y >> z) result.emplace_back(x, y, z);
  return result;
}

// A CSV output with the named columns, as doubles, one vector per row.
inline std::vector<std::vector<double>> CsvColumns(
    const std::string& path, const std::vector<std::string>& columns) {
  const CsvTable table = CsvTable::Read(path, path, columns);
  std::vector<std::vector<double>> rows;
  for (int row = 0; row < table.NumRows(); ++row) {
    std::vector<double> values;
    for (const std::string& column : columns) {
      values.push_back(table.GetDouble(row, column));
    }
    rows.push_back(values);
  }
  return rows;
}

// The text of a CSV output without the output_crs comments and columns: what
// a run without output_crs writes.
inline std::string WithoutCrsColumns(const std::string& text) {
  std::istringstream in(text);
  std::string line, result;
  while (std::getline(in, line)) {
    if (line.rfind("# output_crs", 0) == 0 ||
        line.rfind("# crs_x,crs_y,crs_z:", 0) == 0) {
      continue;
    }
    if (line.rfind("#", 0) != 0) {
      // The three crs columns are the last ones of every row.
      for (int i = 0; i < 3; ++i) line = line.substr(0, line.rfind(','));
    }
    result += line + "\n";
  }
  return result;
}

// The text without its `#` comment lines (a stage's timings).
inline std::string WithoutComments(const std::string& text) {
  std::istringstream in(text);
  std::string line, result;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) != 0) result += line + "\n";
  }
  return result;
}

// Appends lines to a survey's survey.yaml.
inline void AppendToManifest(const std::string& survey,
                             const std::string& lines) {
  std::ofstream(survey + "/survey.yaml", std::ios::app) << lines;
}

// Copies a survey folder.
inline void CopySurvey(const std::string& from, const std::string& to) {
  fs::copy(from, to, fs::copy_options::recursive);
}

// A survey reconstructed once (reconstruct --lines), whose copies are
// matched and adjusted with changes to their survey.yaml or files.
class ReconstructedSurvey {
 public:
  // Simulates with `simulate_arguments`, or copies `source_survey` when
  // `simulate_arguments` is empty. Check ok() after.
  ReconstructedSurvey(const std::string& simulate_arguments,
                      const std::string& source_survey = "") {
    survey_ = folder_.Path("survey");
    reconstructed_ = folder_.Path("reconstructed");
    const std::string log = folder_.Path("setup.log");
    if (simulate_arguments.empty()) {
      CopySurvey(source_survey, survey_);
    } else if (RunZebrageo(
                   "simulate " + simulate_arguments + " -o " + Quote(survey_),
                   log, log) != 0) {
      error_ = ReadWholeFile(log);
      return;
    }
    if (RunZebrageo("--log-level error reconstruct --lines " + Quote(survey_) +
                        " -o " + Quote(reconstructed_),
                    log, log) != 0) {
      error_ = ReadWholeFile(log);
    }
  }

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  const std::string& survey() const { return survey_; }
  const TemporaryFolder& folder() const { return folder_; }

  // Copies the survey as `name`, appends `manifest_lines` to its
  // survey.yaml, lets `prepare` change the copy, then runs match and
  // adjust (with `adjust_arguments`; `stage_arguments` go to both) on the
  // shared reconstruction. Returns
  // the results folder, "" after an ADD_FAILURE when a command failed.
  std::string ProcessCopy(
      const std::string& name, const std::string& manifest_lines,
      const std::function<void(const std::string&)>& prepare = nullptr,
      const std::string& adjust_arguments = "",
      const std::string& stage_arguments = "") const {
    const std::string survey = folder_.Path(name + "-survey");
    const std::string results = folder_.Path(name + "-results");
    CopySurvey(survey_, survey);
    AppendToManifest(survey, manifest_lines);
    fs::copy(reconstructed_, results, fs::copy_options::recursive);
    if (prepare) prepare(survey);
    const std::string log = folder_.Path(name + ".log");
    for (const std::string& stage :
         {std::string("match"), "adjust " + adjust_arguments}) {
      if (RunZebrageo("--log-level error " + stage + " " + stage_arguments +
                          " " + Quote(survey) + " -o " + Quote(results),
                      log, log) != 0) {
        ADD_FAILURE() << name << ": " << stage << ": " << ReadWholeFile(log);
        return "";
      }
    }
    return results;
  }

 private:
  TemporaryFolder folder_;
  std::string survey_;
  std::string reconstructed_;
  std::string error_;
};

// The largest distance between the camera positions (east, north, up) of
// two poses.csv, and the largest difference of a quaternion component;
// infinity when their rows differ in number.
inline std::pair<double, double> PoseDifference(const std::string& a_path,
                                                const std::string& b_path) {
  const std::vector<std::string> columns = {"east", "north", "up", "qw",
                                            "qx",   "qy",    "qz"};
  const auto a = CsvColumns(a_path, columns);
  const auto b = CsvColumns(b_path, columns);
  if (a.size() != b.size() || a.empty()) {
    return {INFINITY, INFINITY};
  }
  double worst_m = 0.0, worst_q = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector3d d(a[i][0] - b[i][0], a[i][1] - b[i][1],
                            a[i][2] - b[i][2]);
    worst_m = std::max(worst_m, d.norm());
    for (int k = 3; k < 7; ++k) {
      worst_q = std::max(worst_q, std::abs(a[i][k] - b[i][k]));
    }
  }
  return {worst_m, worst_q};
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_TOOLS_GEODATA_UTIL_H_
