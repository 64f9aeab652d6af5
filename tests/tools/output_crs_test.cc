// survey.yaml's output_crs and trajectory_crs on the real binary: a small
// simulated survey reconstructed once, then matched and adjusted as given
// (WGS84) and with each key; PROJ's cs2cs is the reference.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <regex>
#include <utility>

#include "survey/results_match.h"
#include "tests/tools/geodata_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

// Lambert-93 with EGM96 heights: a national projection and a geoid whose
// grid Debian's proj-data ships (the French NGF-IGN69 grid it does not).
constexpr char kOutputCrs[] = "EPSG:2154+5773";
constexpr char kEgm96Grid[] = "/usr/share/proj/egm96_15.gtx";

class OutputCrs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = new TemporaryFolder();
    survey_ = folder_->Path("survey");
    reconstructed_ = folder_->Path("reconstructed");
    const std::string log = folder_->Path("log");
    ASSERT_EQ(RunZebrageo("simulate " + SmallSurveyArguments() + " -o " +
                              Quote(survey_),
                          log, log),
              0)
        << ReadWholeFile(log);
    ASSERT_EQ(RunZebrageo("--log-level error reconstruct --lines " +
                              Quote(survey_) + " -o " + Quote(reconstructed_),
                          log, log),
              0)
        << ReadWholeFile(log);
    plain_ = ProcessCopy("plain", "");
  }
  static void TearDownTestSuite() {
    delete folder_;
    folder_ = nullptr;
  }

  // Copies the survey as `name`, appends `manifest_lines` to its
  // survey.yaml, and runs match and adjust on the shared reconstruction.
  // Returns the results folder ("" when a command failed).
  static std::string ProcessCopy(
      const std::string& name, const std::string& manifest_lines,
      const std::function<void(const std::string&)>& prepare = nullptr) {
    const std::string survey = folder_->Path(name + "-survey");
    const std::string results = folder_->Path(name + "-results");
    CopySurvey(survey_, survey);
    AppendToManifest(survey, manifest_lines);
    fs::copy(reconstructed_, results, fs::copy_options::recursive);
    if (prepare) prepare(survey);
    const std::string log = folder_->Path(name + ".log");
    for (const char* stage : {"match", "adjust"}) {
      if (RunZebrageo(std::string("--log-level error ") + stage + " " +
                          Quote(survey) + " -o " + Quote(results),
                      log, log) != 0) {
        ADD_FAILURE() << stage << ": " << ReadWholeFile(log);
        return "";
      }
    }
    return results;
  }

  static TemporaryFolder* folder_;
  static std::string survey_;
  static std::string reconstructed_;
  static std::string plain_;
};

TemporaryFolder* OutputCrs::folder_ = nullptr;
std::string OutputCrs::survey_;
std::string OutputCrs::reconstructed_;
std::string OutputCrs::plain_;

TEST_F(OutputCrs, PosesAgreeWithCs2csOnTheWgs84OutputToAMillimetre) {
  if (!HaveProgram("cs2cs") || !fs::exists(kEgm96Grid)) {
    GTEST_SKIP() << "cs2cs or " << kEgm96Grid
                 << " missing (Debian proj-bin, proj-data)";
  }
  const std::string results = ProcessCopy(
      "output", std::string("output_crs: \"") + kOutputCrs + "\"\n");
  ASSERT_FALSE(results.empty());
  for (const char* file : {kPosesFile, kTrajectoryCorrectedFile}) {
    SCOPED_TRACE(file);
    const std::string path = results + "/" + file;
    const std::string text = ReadWholeFile(path);
    EXPECT_THAT(text, HasSubstr(std::string("# output_crs: ") + kOutputCrs));
    EXPECT_THAT(text, HasSubstr("EGM96 height"));
    // The contract's columns are those of the run without output_crs (to
    // the last bits the threads of the solver leave to chance).
    const std::string contract = WithoutCrsColumns(text);
    const std::string plain = ReadWholeFile(plain_ + "/" + file);
    EXPECT_EQ(contract.substr(0, contract.find('\n', contract.find(",h,"))),
              plain.substr(0, plain.find('\n', plain.find(",h,"))));
    const auto contract_rows = CsvColumns(path, {"time", "lat", "lon", "h"});
    const auto plain_rows =
        CsvColumns(plain_ + "/" + file, {"time", "lat", "lon", "h"});
    ASSERT_EQ(contract_rows.size(), plain_rows.size());
    for (size_t i = 0; i < plain_rows.size(); ++i) {
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(contract_rows[i][k], plain_rows[i][k], 1e-9);
      }
    }
    const auto rows =
        CsvColumns(path, {"lat", "lon", "h", "crs_x", "crs_y", "crs_z"});
    ASSERT_GT(rows.size(), 10u);
    std::vector<Eigen::Vector3d> wgs84;
    for (const auto& row : rows) wgs84.emplace_back(row[0], row[1], row[2]);
    const std::vector<Eigen::Vector3d> reference =
        Cs2cs("EPSG:4979", kOutputCrs, wgs84, folder_->Path());
    ASSERT_EQ(reference.size(), rows.size());
    double worst_m = 0.0;
    for (size_t i = 0; i < rows.size(); ++i) {
      const Eigen::Vector3d ours(rows[i][3], rows[i][4], rows[i][5]);
      worst_m = std::max(worst_m, (ours - reference[i]).norm());
    }
    EXPECT_LT(worst_m, 1e-3);
    // Not the ellipsoidal height: the geoid is ~45 m up at Amiens.
    EXPECT_NEAR(rows[0][2] - rows[0][5], 45.0, 3.0);
  }
  // Control points and matches carry the CRS too; bands.geojson names it.
  for (const char* file : {kGcpResidualsFile, kMatchesFile}) {
    const auto rows = CsvColumns(results + "/" + file, {"crs_x", "crs_y"});
    EXPECT_FALSE(rows.empty()) << file;
  }
  const nlohmann::json bands =
      nlohmann::json::parse(ReadWholeFile(results + "/" + kBandsGeoJsonFile));
  EXPECT_EQ(bands["crs"]["properties"]["name"],
            "urn:ogc:def:crs,crs:EPSG::2154,crs:EPSG::5773");
  const double x =
      bands["features"][0]["geometry"]["coordinates"][0][0][0].get<double>();
  EXPECT_GT(x, 100000.0);  // a Lambert-93 easting, not a longitude
}

// matches.geojson and its two companions (issue 47): one geometry type
// each, in the output CRS with its "crs" member, as GDAL reads them; in
// WGS84 without output_crs.
TEST_F(OutputCrs, MatchesGeoJsonHoldOneGeometryTypeEachInTheOutputCrs) {
  if (!HaveProgram("ogrinfo") || !fs::exists(kEgm96Grid)) {
    GTEST_SKIP() << "ogrinfo or " << kEgm96Grid
                 << " missing (Debian gdal-bin, proj-data)";
  }
  const std::string results = ProcessCopy(
      "geojson", std::string("output_crs: \"") + kOutputCrs + "\"\n");
  ASSERT_FALSE(results.empty());
  const std::pair<const char*, const char*> files[] = {
      {kMatchesGeoJsonFile, "Line String"},
      {kMatchedBandsGeoJsonFile, "Polygon"},
      {kDatabaseFaultsGeoJsonFile, "Point"}};
  int features_seen = 0;
  for (const auto& [file, geometry] : files) {
    SCOPED_TRACE(file);
    const nlohmann::json json =
        nlohmann::json::parse(ReadWholeFile(results + "/" + file));
    EXPECT_EQ(json["crs"]["properties"]["name"],
              "urn:ogc:def:crs,crs:EPSG::2154,crs:EPSG::5773");
    const std::string log = folder_->Path(std::string(file) + ".ogrinfo");
    ASSERT_EQ(Shell("ogrinfo -ro -so -al " + Quote(results + "/" + file), log),
              0)
        << ReadWholeFile(log);
    const std::string info = ReadWholeFile(log);
    EXPECT_THAT(info, HasSubstr("Feature Count: " +
                                std::to_string(json["features"].size())));
    EXPECT_THAT(info, HasSubstr("Lambert-93"));
    if (json["features"].empty()) continue;
    features_seen += static_cast<int>(json["features"].size());
    // "Geometry: 3D Line String": one type for the layer, not "Unknown".
    EXPECT_TRUE(std::regex_search(
        info, std::regex("Geometry: (3D )?" + std::string(geometry) + "\n")))
        << info;
    for (const auto& feature : json["features"]) {
      EXPECT_EQ(feature["geometry"]["type"],
                std::regex_replace(geometry, std::regex(" "), ""));
    }
    // Lambert-93 eastings, not longitudes.
    const nlohmann::json* position =
        &json["features"][0]["geometry"]["coordinates"];
    while ((*position)[0].is_array()) position = &(*position)[0];
    EXPECT_GT((*position)[0].get<double>(), 100000.0);
  }
  EXPECT_GT(features_seen, 0);
  // Without output_crs: RFC 7946, longitude and latitude, no "crs".
  const nlohmann::json plain =
      nlohmann::json::parse(ReadWholeFile(plain_ + "/" + kMatchesGeoJsonFile));
  EXPECT_FALSE(plain.contains("crs"));
  ASSERT_FALSE(plain["features"].empty());
  EXPECT_LT(
      std::abs(
          plain["features"][0]["geometry"]["coordinates"][0][0].get<double>()),
      180.0);
}

TEST_F(OutputCrs, ProjectedTrajectoryGivesTheSamePosesToAMillimetre) {
  if (!HaveProgram("cs2cs") || !fs::exists(kEgm96Grid)) {
    GTEST_SKIP() << "cs2cs or " << kEgm96Grid
                 << " missing (Debian proj-bin, proj-data)";
  }
  // trajectory.csv converted by cs2cs to UTM 31N + EGM96 heights: x, y, z
  // in place of lat, lon, h.
  std::string projected;
  {
    const CsvTable table =
        CsvTable::Read(survey_ + "/trajectory.csv", "trajectory.csv",
                       {"time", "lat", "lon", "h"});
    std::vector<Eigen::Vector3d> wgs84;
    for (int row = 0; row < table.NumRows(); ++row) {
      wgs84.emplace_back(table.GetDouble(row, "lat"),
                         table.GetDouble(row, "lon"),
                         table.GetDouble(row, "h"));
    }
    const std::vector<Eigen::Vector3d> utm =
        Cs2cs("EPSG:4979", "EPSG:32631+5773", wgs84, folder_->Path());
    ASSERT_EQ(utm.size(), wgs84.size());
    std::istringstream in(ReadWholeFile(survey_ + "/trajectory.csv"));
    std::string line;
    int row = -1;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::vector<std::string> fields;
      std::stringstream split(line);
      for (std::string field; std::getline(split, field, ',');) {
        fields.push_back(field);
      }
      if (row >= 0) {
        fields[1] = FormatDouble(utm[row].x());
        fields[2] = FormatDouble(utm[row].y());
        fields[3] = FormatDouble(utm[row].z());
      } else {
        ASSERT_EQ(fields[1], "lat");
        fields[1] = "x", fields[2] = "y", fields[3] = "z";
      }
      for (size_t i = 0; i < fields.size(); ++i) {
        projected += (i > 0 ? "," : "") + fields[i];
      }
      projected += "\n";
      ++row;
    }
  }
  const std::string results =
      ProcessCopy("utm", "trajectory_crs: \"EPSG:32631+5773\"\n",
                  [&projected](const std::string& survey) {
                    std::ofstream(survey + "/trajectory.csv") << projected;
                  });
  ASSERT_FALSE(results.empty());
  const std::vector<std::string> columns = {"east", "north", "up", "qw",
                                            "qx",   "qy",    "qz"};
  const auto ours = CsvColumns(results + "/" + kPosesFile, columns);
  const auto plain = CsvColumns(plain_ + "/" + kPosesFile, columns);
  ASSERT_EQ(ours.size(), plain.size());
  double worst_m = 0.0, worst_q = 0.0;
  for (size_t i = 0; i < ours.size(); ++i) {
    const Eigen::Vector3d d(ours[i][0] - plain[i][0], ours[i][1] - plain[i][1],
                            ours[i][2] - plain[i][2]);
    worst_m = std::max(worst_m, d.norm());
    for (int k = 3; k < 7; ++k) {
      worst_q = std::max(worst_q, std::abs(ours[i][k] - plain[i][k]));
    }
  }
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_LT(worst_q, 1e-6);
  EXPECT_EQ(WithoutComments(ReadWholeFile(results + "/" + kMatchesFile)),
            WithoutComments(ReadWholeFile(plain_ + "/" + kMatchesFile)));
}

TEST_F(OutputCrs, MissingGeoidGridStopsTheSurveyNamingIt) {
  std::string survey;
  const std::string manifest_line =
      "output_crs: \"+proj=utm +zone=31 "
      "+datum=WGS84 +geoidgrids=no_such.gtx\"\n";
  CopySurvey(survey_, survey = folder_->Path("nogrid-survey"));
  AppendToManifest(survey, manifest_line);
  const std::string out = folder_->Path("nogrid.out");
  const std::string err = folder_->Path("nogrid.err");
  EXPECT_EQ(RunZebrageo("check " + Quote(survey), out, err), 1);
  const std::string message = ReadWholeFile(err);
  EXPECT_THAT(message, HasSubstr("survey.yaml:"));
  EXPECT_THAT(message, HasSubstr("output_crs"));
  EXPECT_THAT(message, HasSubstr("no_such.gtx"));
  EXPECT_THAT(message, HasSubstr("missing"));
}

TEST_F(OutputCrs, UnknownCrsIsAnErrorOnItsLine) {
  const std::string survey = folder_->Path("unknown-survey");
  CopySurvey(survey_, survey);
  AppendToManifest(survey, "trajectory_crs: EPSG:123456789\n");
  const std::string out = folder_->Path("unknown.out");
  const std::string err = folder_->Path("unknown.err");
  EXPECT_EQ(RunZebrageo("check " + Quote(survey), out, err), 1);
  EXPECT_THAT(ReadWholeFile(err), HasSubstr("survey.yaml:"));
  EXPECT_THAT(ReadWholeFile(err), HasSubstr("EPSG:123456789"));
}

}  // namespace
}  // namespace zebrageo
