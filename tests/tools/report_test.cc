// The report without a browser: `zebrageo run` on a small simulated survey
// writes report.json with the figures of SURVEY_FORMAT.md and a report.html
// whose sections and plots are all there, every inline SVG well-formed XML
// with something drawn; `zebrageo report` rebuilds the same report from the
// results folder alone. (ctest report_render also renders the page in
// headless Chromium when it is installed.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
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

bool IsNameStart(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == ':';
}
bool IsNameChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' ||
         c == '.' || c == '-';
}

// The text between '<' and '>': "/name", or "name", attributes name='v' or
// name="v" (no '<' in v), and an optional '/'. A scanner, not std::regex:
// libstdc++'s regex recurses once per character of a polyline's points
// and overflowed the stack under ASan.
bool ParseTag(const std::string& tag, std::string* name, bool* closing,
              bool* self_closing) {
  size_t i = 0;
  *closing = i < tag.size() && tag[i] == '/';
  if (*closing) ++i;
  if (i >= tag.size() || !IsNameStart(tag[i])) return false;
  const size_t begin = i;
  while (i < tag.size() && IsNameChar(tag[i])) ++i;
  *name = tag.substr(begin, i - begin);
  auto skip_space = [&] {
    while (i < tag.size() && std::isspace(static_cast<unsigned char>(tag[i])))
      ++i;
  };
  if (*closing) {
    skip_space();
    return i == tag.size();
  }
  *self_closing = false;
  while (true) {
    const size_t before = i;
    skip_space();
    if (i == tag.size()) return true;
    if (tag[i] == '/') {
      *self_closing = true;
      return i + 1 == tag.size();
    }
    if (i == before || !IsNameStart(tag[i])) return false;  // no space
    while (i < tag.size() && IsNameChar(tag[i])) ++i;
    skip_space();
    if (i >= tag.size() || tag[i] != '=') return false;
    ++i;
    skip_space();
    if (i >= tag.size() || (tag[i] != '\'' && tag[i] != '"')) return false;
    const char quote = tag[i++];
    while (i < tag.size() && tag[i] != quote) {
      if (tag[i] == '<') return false;
      ++i;
    }
    if (i >= tag.size()) return false;
    ++i;
  }
}

// "" when `xml` is one well-formed element (tags nested and closed, quoted
// attributes, no bare '<' or '&' in text), else what is wrong and where.
std::string XmlProblem(const std::string& xml) {
  std::vector<std::string> open;
  size_t at = 0;
  auto where = [&](const std::string& problem) {
    return problem + " at byte " + std::to_string(at) + ": " +
           xml.substr(at, 60);
  };
  const std::regex entity("^&(amp|lt|gt|quot|apos|#[0-9]+|#x[0-9a-fA-F]+);");
  while (at < xml.size()) {
    if (xml[at] == '&') {
      std::smatch m;
      const std::string rest = xml.substr(at, 12);
      if (!std::regex_search(rest, m, entity)) return where("bare '&'");
      at += m.length(0);
      continue;
    }
    if (xml[at] != '<') {
      if (open.empty() && !std::isspace(static_cast<unsigned char>(xml[at]))) {
        return where("text outside the root element");
      }
      ++at;
      continue;
    }
    const size_t end = xml.find('>', at);
    if (end == std::string::npos) return where("unclosed tag");
    const std::string tag = xml.substr(at + 1, end - at - 1);
    if (tag.find('<') != std::string::npos) return where("'<' inside a tag");
    std::string name;
    bool closing = false, self_closing = false;
    if (!ParseTag(tag, &name, &closing, &self_closing)) {
      return where("malformed tag");
    }
    if (closing) {
      if (open.empty() || open.back() != name) {
        return where("</" + name + "> closes " +
                     (open.empty() ? std::string("nothing") : open.back()));
      }
      open.pop_back();
      if (open.empty() && xml.find('<', end) != std::string::npos) {
        return where("a second root element");
      }
    } else if (!self_closing) {
      open.push_back(name);
    }
    at = end + 1;
  }
  if (!open.empty()) return "<" + open.back() + "> never closed";
  return "";
}

TEST(XmlProblem, TellsWellFormedFromBroken) {
  EXPECT_EQ(XmlProblem("<svg a='1' b=\"2\"><g><rect x='0'/></g>&amp;</svg>"),
            "");
  EXPECT_NE(XmlProblem("<svg><g></svg>"), "");
  EXPECT_NE(XmlProblem("<svg><rect x=1/></svg>"), "");
  EXPECT_NE(XmlProblem("<svg><text>a & b</text></svg>"), "");
  EXPECT_NE(XmlProblem("<svg><text>a < b</text></svg>"), "");
  EXPECT_NE(XmlProblem("<svg>"), "");
  EXPECT_NE(XmlProblem("<svg></svg><svg></svg>"), "");
}

// Every inline <svg>...</svg> of a page.
std::vector<std::string> SvgElements(const std::string& html) {
  std::vector<std::string> svgs;
  for (size_t at = html.find("<svg"); at != std::string::npos;
       at = html.find("<svg", at + 1)) {
    const size_t end = html.find("</svg>", at);
    if (end == std::string::npos) {
      svgs.push_back(html.substr(at));
      break;
    }
    svgs.push_back(html.substr(at, end + 6 - at));
  }
  return svgs;
}

// report.json's figures: what a program reading it relies on.
void ExpectReportFigures(const json& report) {
  EXPECT_EQ(report.at("zebrageo_version"), ZEBRAGEO_VERSION);
  const json& survey = report.at("survey");
  EXPECT_GT(survey.at("exposures").get<int>(), 10);
  EXPECT_GT(survey.at("database_bands").get<int>(), 0);
  const json& counts = report.at("counts");
  EXPECT_GE(counts.at("matched_crossings").get<int>(), 2);
  EXPECT_GT(counts.at("matched_vertices").get<int>(), 0);
  // The adjustment brings the bands' image residuals down.
  EXPECT_LT(report.at("rms_after").at("control_image").get<double>(),
            report.at("rms_before").at("control_image").get<double>());
  const json& control = report.at("gcp").at("control");
  EXPECT_GE(control.at("crossings").get<int>(), 2);
  EXPECT_GT(control.at("rmse_3d_m").get<double>(), 0.0);
  EXPECT_LT(control.at("rmse_3d_m").get<double>(), 0.5);
  EXPECT_LE(control.at("rmse_3d_m").get<double>(),
            control.at("max_3d_m").get<double>());
  EXPECT_EQ(report.at("crossings").size(),
            static_cast<size_t>(counts.at("matched_crossings").get<int>()));
  const json& timings = report.at("timings_s");
  for (const char* stage : {"reconstruct", "match", "adjust"}) {
    EXPECT_GE(timings.at(stage).get<double>(), 0.0) << stage;
  }
  EXPECT_GT(timings.at("total").get<double>(), 0.0);
  EXPECT_TRUE(report.at("warnings").is_array());
  EXPECT_TRUE(report.at("corrections").contains("rms_horizontal_m"));
}

// report.html: every section, every plot, well-formed, finite numbers.
void ExpectReportPage(const std::string& html, const json& report) {
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<h1>zebrageo report: zebrageo-sim-demo-seed1</h1>"),
            std::string::npos);
  EXPECT_NE(html.find("</html>"), std::string::npos) << "page cut short";
  for (const char* section :
       {"Warnings", "Accuracy", "Trajectory", "Ground control residuals",
        "Crossings", "Database faults found", "Stretches without control",
        "Road lines", "Counts", "Stage timings", "Adjustment", "Matching"}) {
    EXPECT_NE(html.find(std::string("<h2>") + section + "</h2>"),
              std::string::npos)
        << section;
  }
  for (const json& warning : report.at("warnings")) {
    EXPECT_NE(html.find(warning.get<std::string>()), std::string::npos)
        << "warning not shown: " << warning;
  }
  const std::vector<std::string> svgs = SvgElements(html);
  std::vector<std::string> titles;
  for (const std::string& svg : svgs) {
    EXPECT_EQ(XmlProblem(svg), "") << svg.substr(0, 200);
    EXPECT_TRUE(
        std::regex_search(svg, std::regex("<(polyline|circle|path|rect) ")))
        << "nothing drawn: " << svg.substr(0, 200);
    std::smatch title;
    if (std::regex_search(svg, title,
                          std::regex("font-weight='bold'>([^<]*)<"))) {
      titles.push_back(title[1]);
    }
  }
  // One before/after chart per unit (issue 47: px and m in one chart made
  // the bars incomparable), each unit once, then the other plots.
  const std::string rms_title = "Residual RMS before and after the adjustment";
  std::vector<std::string> units;
  while (!titles.empty() && titles.front().rfind(rms_title, 0) == 0) {
    units.push_back(titles.front().substr(rms_title.size()));
    titles.erase(titles.begin());
  }
  EXPECT_GE(units.size(), 2u);
  for (const char* unit : {" (px)", " (m)"}) {
    EXPECT_EQ(std::count(units.begin(), units.end(), unit), 1) << unit;
  }
  const std::vector<std::string> expected = {
      "Trajectory and correction magnitude",
      "Trajectory correction (corrected minus input)",
      "Heading correction",
      "Horizontal GCP residuals (adjusted minus database)",
      "Control points: 3D residual",
      "Control points: reprojection error",
      "Road-line control per stretch"};
  EXPECT_EQ(titles, expected);
  EXPECT_FALSE(std::regex_search(html, std::regex(R"(\b(nan|NaN|inf)\b)")))
      << "NaN or infinity in the page";
}

// Rows of the HTML table following `marker` in `html`: the text of each
// row's cells (header row included).
std::vector<std::vector<std::string>> TableAfter(const std::string& html,
                                                 const std::string& marker) {
  std::vector<std::vector<std::string>> rows;
  const size_t from = html.find(marker);
  if (from == std::string::npos) return rows;
  const size_t begin = html.find("<table>", from);
  const size_t end = html.find("</table>", begin);
  if (begin == std::string::npos || end == std::string::npos) return rows;
  const std::string table = html.substr(begin, end - begin);
  const std::regex row("<tr[^>]*>(.*?)</tr>"), cell("<t[hd]>(.*?)</t[hd]>");
  for (auto r = std::sregex_iterator(table.begin(), table.end(), row);
       r != std::sregex_iterator(); ++r) {
    const std::string text = (*r)[1];
    std::vector<std::string> cells;
    for (auto c = std::sregex_iterator(text.begin(), text.end(), cell);
         c != std::sregex_iterator(); ++c) {
      cells.push_back((*c)[1]);
    }
    rows.push_back(cells);
  }
  return rows;
}

// Issue 47: the tables a photogrammetrist reads, with units, the CRS named,
// one id per element.
void ExpectQaTables(const std::string& html, const std::string& results) {
  // Clip paths: one id per plot, never shared.
  const std::regex id_attribute(" id='([^']*)'");
  std::vector<std::string> ids;
  for (auto m = std::sregex_iterator(html.begin(), html.end(), id_attribute);
       m != std::sregex_iterator(); ++m) {
    ids.push_back((*m)[1]);
  }
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end())
      << "an id used twice";
  EXPECT_GE(ids.size(), 5u);
  // The output CRS named (the small survey has none: WGS84).
  EXPECT_NE(html.find("Output CRS: WGS84 (EPSG:4979"), std::string::npos);
  // Per control point: one row per line of gcp_residuals.csv, residuals in
  // cm as the file's metres say.
  std::vector<std::string> csv;
  {
    std::istringstream lines(ReadWholeFile(results + "/gcp_residuals.csv"));
    for (std::string line; std::getline(lines, line);) csv.push_back(line);
  }
  const auto gcp = TableAfter(html, "Each database vertex matched");
  ASSERT_GE(gcp.size(), 2u);
  ASSERT_EQ(gcp[0].size(), 12u);
  EXPECT_EQ(gcp[0][4], "East (cm)");
  size_t data_lines = 0;
  for (const std::string& line : csv) {
    if (!line.empty() && line[0] != '#') ++data_lines;
  }
  EXPECT_EQ(gcp.size(), data_lines) << "header + one row per point";
  for (size_t i = 1; i < gcp.size(); ++i) {
    EXPECT_TRUE(gcp[i][3] == "control" || gcp[i][3] == "check" ||
                gcp[i][3] == "rejected")
        << gcp[i][3];
    // A residual of the small survey is centimetres, not metres.
    EXPECT_LT(std::abs(std::stod(gcp[i][8])), 100.0) << "3D (cm)";
  }
  // Per camera: the rig's two cameras, reprojection RMS of a few pixels.
  const auto cameras = TableAfter(html, "<div id='camera-residuals'>");
  ASSERT_EQ(cameras.size(), 3u) << "header + 2 cameras";
  EXPECT_EQ(cameras[0][3], "RMS control (px)");
  for (size_t i = 1; i < cameras.size(); ++i) {
    EXPECT_GT(std::stoi(cameras[i][1]), 10) << "control observations";
    const double rms_px = std::stod(cameras[i][3]);
    EXPECT_GT(rms_px, 0.0);
    EXPECT_LT(rms_px, 3.0) << cameras[i][0];
  }
  // Every column header of every table names its unit or is a count/name:
  // no raw JSON key (snake_case) left.
  EXPECT_FALSE(std::regex_search(html, std::regex("<th>[a-z0-9]+_[a-z0-9_]+")))
      << "a raw JSON key as a header";
}

TEST(Report, RunWritesItsFiguresAndWellFormedPlotsAndReportRebuildsIt) {
  TemporaryFolder folder;
  const std::string survey = folder.Path("survey");
  const std::string results = folder.Path("results");
  ASSERT_EQ(RunZebrageo("--log-level error simulate " + SmallSurveyArguments() +
                            " -o " + Quote(survey),
                        folder.Path("sim.out"), folder.Path("sim.err")),
            0)
      << ReadWholeFile(folder.Path("sim.err"));
  ASSERT_EQ(RunZebrageo("--log-level error run " + Quote(survey) + " -o " +
                            Quote(results),
                        folder.Path("run.out"), folder.Path("run.err")),
            0)
      << ReadWholeFile(folder.Path("run.err"));
  const json report = json::parse(ReadWholeFile(results + "/report.json"));
  {
    SCOPED_TRACE("report.json");
    ExpectReportFigures(report);
  }
  {
    SCOPED_TRACE("report.html");
    ExpectReportPage(ReadWholeFile(results + "/report.html"), report);
    ExpectQaTables(ReadWholeFile(results + "/report.html"), results);
  }

  // `zebrageo report` from the results folder alone: the same figures.
  fs::remove(results + "/report.json");
  fs::remove(results + "/report.html");
  ASSERT_EQ(RunZebrageo("--log-level error report " + Quote(survey) + " -o " +
                            Quote(results),
                        folder.Path("report.out"), folder.Path("report.err")),
            0)
      << ReadWholeFile(folder.Path("report.err"));
  const json rebuilt = json::parse(ReadWholeFile(results + "/report.json"));
  for (const char* key : {"counts", "rms_before", "rms_after", "gcp",
                          "crossings", "corrections", "survey"}) {
    EXPECT_EQ(rebuilt.at(key), report.at(key)) << key;
  }
  // The same warnings; `run` lists them in the order the stages gave them.
  std::vector<std::string> warnings = report.at("warnings");
  std::vector<std::string> rebuilt_warnings = rebuilt.at("warnings");
  std::sort(warnings.begin(), warnings.end());
  std::sort(rebuilt_warnings.begin(), rebuilt_warnings.end());
  EXPECT_EQ(rebuilt_warnings, warnings);
  SCOPED_TRACE("rebuilt report.html");
  ExpectReportPage(ReadWholeFile(results + "/report.html"), rebuilt);
}

}  // namespace
}  // namespace zebrageo
