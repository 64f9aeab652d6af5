// export-gcp on the real binary: a small simulated survey is processed by
// `zebrageo run`, its control points exported in every format, and each
// file read back by the format's own reader where Debian has one (GDAL's
// ogr2ogr for the GeoPackage) or parsed against the format's published
// specification (ODM, OpenSfM: no reader of theirs is packaged for Debian or
// npm). Coordinates are checked against the database and the simulation's
// truth, image observations against the true corners projected with the
// true trajectory.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "survey/csv.h"
#include "survey/exposures.h"
#include "survey/results.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
#include "survey/trajectory.h"
#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// One processed survey per test process (ctest runs each test alone).
class GcpExport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = new TemporaryFolder();
    const std::string survey = folder_->Path("survey");
    const std::string results = folder_->Path("results");
    ASSERT_EQ(RunZebrageo("--log-level error simulate " +
                              SmallSurveyArguments() + " -o " + Quote(survey),
                          folder_->Path("sim.out"), folder_->Path("sim.err")),
              0);
    ASSERT_EQ(RunZebrageo("--log-level error run " + Quote(survey) + " -o " +
                              Quote(results),
                          folder_->Path("run.out"), folder_->Path("run.err")),
              0)
        << ReadWholeFile(folder_->Path("run.err"));
    // Two crossings are too few for the adjustment to hold one out as check
    // points (--check-share): the first crossing is marked check here, as
    // a larger survey's adjustment would, so that the exports' handling of
    // roles is tested. Everything else is the run's own output.
    const std::string residuals = Results("gcp_residuals.csv");
    std::vector<GcpResidual> rows =
        ReadGcpResiduals(residuals, "gcp_residuals.csv");
    ASSERT_FALSE(rows.empty());
    const std::string check_crossing = rows.front().crossing_id;
    for (GcpResidual& r : rows) {
      if (r.crossing_id == check_crossing) {
        r.role = GcpRole::kCheck;      // a check crossing, as the adjustment
        r.status = GcpStatus::kCheck;  // writes it: role and status check
      }
    }
    WriteGcpResiduals(rows, residuals);
  }
  static void TearDownTestSuite() {
    delete folder_;
    folder_ = nullptr;
  }

  static std::string Survey(const std::string& name = "") {
    return folder_->Path("survey") + (name.empty() ? "" : "/" + name);
  }
  static std::string Results(const std::string& name = "") {
    return folder_->Path("results") + (name.empty() ? "" : "/" + name);
  }
  // Runs export-gcp; returns its exit status.
  static int Export(const std::string& arguments, const std::string& output) {
    return RunZebrageo(
        "--log-level error export-gcp " + Quote(Survey()) + " " +
            Quote(Results()) + " " + arguments + " -o " + Quote(output),
        folder_->Path("export.out"), folder_->Path("export.err"));
  }
  static std::string ExportError() {
    return ReadWholeFile(folder_->Path("export.err"));
  }

  static TemporaryFolder* folder_;
};
TemporaryFolder* GcpExport::folder_ = nullptr;

// The database vertex a GCP name "crossing/band/vertex" stands for.
Geodetic DatabaseVertex(const RoadmarkDatabase& database,
                        const std::string& name) {
  const size_t a = name.rfind('/', name.rfind('/') - 1);
  const size_t b = name.rfind('/');
  const std::string crossing = name.substr(0, a);
  const int band = std::stoi(name.substr(a + 1, b - a - 1));
  const int vertex = std::stoi(name.substr(b + 1));
  for (const RoadmarkBand& d : database.bands) {
    if (d.crossing_id == crossing && d.band == band) return d.corners[vertex];
  }
  ADD_FAILURE() << "no database vertex " << name;
  return {};
}

// Checks a point against the truth: its coordinates (the database's) lie
// within the database's error of a true corner, and each observation lies
// where that true corner projects in the image with the true trajectory.
class TruthCheck {
 public:
  explicit TruthCheck(const std::string& survey)
      : rig_(ReadRig(survey + "/rig.yaml", "rig.yaml")),
        exposures_(
            ReadExposures(survey + "/exposures.csv", "exposures.csv", rig_)),
        database_(ReadRoadmarks(survey + "/roadmarks.geojson", "db")),
        truth_db_(ReadRoadmarks(survey + "/truth/roadmarks.geojson", "truth")) {
    std::vector<TrajectorySample> samples = ReadTrajectorySamples(
        survey + "/truth/trajectory.csv", "truth/trajectory.csv");
    frame_ = LocalFrame(samples.front().position);
    truth_ = Trajectory(samples, frame_);
  }

  const RoadmarkDatabase& database() const { return database_; }

  // The true corner nearest `position` and its distance (m).
  Eigen::Vector3d NearestTrueCorner(const Geodetic& position,
                                    double* distance_m) const {
    const Eigen::Vector3d p = frame_.EnuFromGeodetic(position);
    Eigen::Vector3d best = Eigen::Vector3d::Zero();
    *distance_m = 1e9;
    for (const RoadmarkBand& band : truth_db_.bands) {
      for (const Geodetic& corner : band.corners) {
        const Eigen::Vector3d q = frame_.EnuFromGeodetic(corner);
        if ((q - p).norm() < *distance_m) {
          *distance_m = (q - p).norm();
          best = q;
        }
      }
    }
    return best;
  }

  // Pixel distance between `uv` in `image_name` (a base name) and the
  // projection of `p_enu` with the true pose.
  double PixelError(const Eigen::Vector3d& p_enu, const std::string& image_name,
                    const Eigen::Vector2d& uv) const {
    for (const ExposureImage& image : exposures_.images) {
      if (fs::path(image.image).filename() != image_name) continue;
      Pose pose;
      EXPECT_TRUE(truth_.InterpolatePose(image.time, &pose));
      const RigCamera& camera = rig_.cameras[image.camera];
      const Eigen::Isometry3d T_enu_cam = pose.T_enu_body() * camera.T_body_cam;
      Eigen::Vector2d projected;
      EXPECT_TRUE(
          camera.camera.Project(T_enu_cam.inverse() * p_enu, &projected));
      return (projected - uv).norm();
    }
    ADD_FAILURE() << "no image " << image_name;
    return 1e9;
  }

 private:
  Rig rig_;
  ExposureTable exposures_;
  RoadmarkDatabase database_;
  RoadmarkDatabase truth_db_;
  LocalFrame frame_{Geodetic{}};
  Trajectory truth_;
};

// The database is 5 to 15 cm off the street (SURVEY_FORMAT.md); corners
// are found to a pixel or two in 640x480 images.
constexpr double kMaxDatabaseErrorM = 0.35;
constexpr double kMaxPixelError = 3.0;

std::vector<std::string> Words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  std::string word;
  while (in >> word) words.push_back(word);
  return words;
}

// OpenDroneMap's documentation of gcp_list.txt: "The first line should
// contain the name of the projection used for the geo coordinates. ... The
// following lines should contain the data for each ground control point
// observation, one per line and in the following format: geo_x geo_y geo_z
// im_x im_y image_name [gcp_name] [extra1] [extra2]" with "Entries separated
// by tabs or spaces"; for EPSG:4326, geo_x is the longitude.
TEST_F(GcpExport, OdmGcpListFollowsTheSpecificationAndTheTruth) {
  const std::string path = folder_->Path("gcp_list.txt");
  ASSERT_EQ(Export("--format odm", path), 0) << ExportError();
  const TruthCheck truth(Survey());
  std::ifstream in(path);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "EPSG:4326");
  int observations = 0;
  double max_pixel_error = 0.0;
  double max_database_error_m = 0.0;
  std::map<std::string, int> per_point;
  while (std::getline(in, line)) {
    const std::vector<std::string> w = Words(line);
    ASSERT_GE(w.size(), 7u) << line;
    const Geodetic position{std::stod(w[1]), std::stod(w[0]), std::stod(w[2])};
    const Geodetic database = DatabaseVertex(truth.database(), w[6]);
    EXPECT_NEAR(position.lat_deg, database.lat_deg, 1e-9);
    EXPECT_NEAR(position.lon_deg, database.lon_deg, 1e-9);
    EXPECT_NEAR(position.h_m, database.h_m, 1e-4);
    double distance_m = 0.0;
    const Eigen::Vector3d corner =
        truth.NearestTrueCorner(position, &distance_m);
    EXPECT_LT(distance_m, kMaxDatabaseErrorM) << line;
    EXPECT_TRUE(fs::exists(Survey("images/" + w[5]))) << w[5];
    const double pixel_error = truth.PixelError(
        corner, w[5], Eigen::Vector2d(std::stod(w[3]), std::stod(w[4])));
    EXPECT_LT(pixel_error, kMaxPixelError) << line;
    max_pixel_error = std::max(max_pixel_error, pixel_error);
    max_database_error_m = std::max(max_database_error_m, distance_m);
    ++observations;
    ++per_point[w[6]];
  }
  std::cout << per_point.size() << " control points, " << observations
            << " observations; largest distance to a true corner "
            << max_database_error_m << " m, largest image error "
            << max_pixel_error << " px\n";
  EXPECT_GE(per_point.size(), 8u);  // several bands of a crossing
  EXPECT_GE(observations, 2 * static_cast<int>(per_point.size()));
  // Only control points: check points are left to the adjustment.
  for (const GcpResidual& r :
       ReadGcpResiduals(Results("gcp_residuals.csv"), "gcp_residuals.csv")) {
    const std::string name = r.crossing_id + "/" + std::to_string(r.band) +
                             "/" + std::to_string(r.vertex);
    EXPECT_EQ(per_point.count(name) > 0, r.role == GcpRole::kControl) << name;
  }
}

// `--crs utm` writes ODM's "WGS84 UTM <zone><N|S>" header and coordinates
// that agree with PROJ's own cs2cs applied to the WGS84 export, to 1 mm.
TEST_F(GcpExport, OdmUtmCoordinatesAgreeWithCs2cs) {
  if (std::system("command -v cs2cs >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "cs2cs (proj-bin) is not installed";
  }
  const std::string wgs84 = folder_->Path("gcp_wgs84.txt");
  const std::string utm = folder_->Path("gcp_utm.txt");
  ASSERT_EQ(Export("--format odm", wgs84), 0) << ExportError();
  ASSERT_EQ(Export("--format odm --crs utm", utm), 0) << ExportError();
  std::ifstream wgs84_in(wgs84);
  std::ifstream utm_in(utm);
  std::string wgs84_line, utm_line;
  std::getline(wgs84_in, wgs84_line);
  std::getline(utm_in, utm_line);
  EXPECT_EQ(utm_line, "WGS84 UTM 31N");  // the simulator's survey, at 2.3 E
  // cs2cs reads EPSG:4979 as latitude, longitude, height.
  const std::string cs2cs_in = folder_->Path("cs2cs.in");
  const std::string cs2cs_out = folder_->Path("cs2cs.out");
  std::vector<std::vector<std::string>> utm_rows;
  {
    std::ofstream out(cs2cs_in);
    while (std::getline(wgs84_in, wgs84_line) &&
           std::getline(utm_in, utm_line)) {
      const std::vector<std::string> w = Words(wgs84_line);
      out << w[1] << " " << w[0] << " " << w[2] << "\n";
      utm_rows.push_back(Words(utm_line));
    }
  }
  ASSERT_FALSE(utm_rows.empty());
  ASSERT_EQ(std::system(("cs2cs -f %.6f EPSG:4979 EPSG:32631 < " +
                         Quote(cs2cs_in) + " > " + Quote(cs2cs_out))
                            .c_str()),
            0);
  std::ifstream expected_in(cs2cs_out);
  std::string expected_line;
  double max_difference_m = 0.0;
  for (const std::vector<std::string>& row : utm_rows) {
    ASSERT_TRUE(std::getline(expected_in, expected_line));
    const std::vector<std::string> e = Words(expected_line);
    ASSERT_EQ(e.size(), 3u) << expected_line;
    for (int axis = 0; axis < 3; ++axis) {
      max_difference_m =
          std::max(max_difference_m,
                   std::abs(std::stod(row[axis]) - std::stod(e[axis])));
    }
  }
  EXPECT_LT(max_difference_m, 0.001);
}

TEST_F(GcpExport, AnUnknownCrsIsAUsageError) {
  const std::string path = folder_->Path("never.txt");
  EXPECT_EQ(Export("--format odm --crs EPSG:999999", path), 2);
  EXPECT_NE(ExportError().find("EPSG:999999"), std::string::npos)
      << ExportError();
  EXPECT_FALSE(fs::exists(path));
}

// OpenSfM's documentation (docs/gcp.html): {"points": [{"id": ..., "position":
// {"latitude", "longitude", "altitude"}, "observations": [{"shot_id": ...,
// "projection": [x, y]}]}]}, "projection: the normalized image coordinates
// of the GCP in the image"; OpenSfM normalises pixels as
// (pixel + 0.5 - size / 2) / max(width, height)
// (features.normalized_image_coordinates).
TEST_F(GcpExport, OpenSfmJsonFollowsTheSpecificationAndTheTruth) {
  const std::string path = folder_->Path("ground_control_points.json");
  ASSERT_EQ(Export("--format opensfm --include-check", path), 0)
      << ExportError();
  const TruthCheck truth(Survey());
  const Rig rig = ReadRig(Survey("rig.yaml"), "rig.yaml");
  const int width = rig.cameras[0].camera.width();
  const int height = rig.cameras[0].camera.height();
  std::ifstream in(path);
  const nlohmann::json root = nlohmann::json::parse(in);
  ASSERT_TRUE(root["points"].is_array());
  std::map<std::string, int> roles;
  for (const nlohmann::json& point : root["points"]) {
    const std::string id = point["id"];
    const Geodetic position{point["position"]["latitude"],
                            point["position"]["longitude"],
                            point["position"]["altitude"]};
    const Geodetic database = DatabaseVertex(truth.database(), id);
    EXPECT_DOUBLE_EQ(position.lat_deg, database.lat_deg);
    EXPECT_DOUBLE_EQ(position.lon_deg, database.lon_deg);
    double distance_m = 0.0;
    const Eigen::Vector3d corner =
        truth.NearestTrueCorner(position, &distance_m);
    EXPECT_LT(distance_m, kMaxDatabaseErrorM);
    ++roles[point["role"]];
    ASSERT_FALSE(point["observations"].empty());
    for (const nlohmann::json& o : point["observations"]) {
      const double size = std::max(width, height);
      const Eigen::Vector2d uv(
          o["projection"][0].get<double>() * size + width / 2.0 - 0.5,
          o["projection"][1].get<double>() * size + height / 2.0 - 0.5);
      EXPECT_LT(truth.PixelError(corner, o["shot_id"], uv), kMaxPixelError);
    }
  }
  int check_points = 0;
  for (const GcpResidual& r :
       ReadGcpResiduals(Results("gcp_residuals.csv"), "gcp_residuals.csv")) {
    check_points += r.role == GcpRole::kCheck;
  }
  EXPECT_EQ(roles["check"], check_points);
  EXPECT_GT(roles["control"], 0);
}

// The GeoPackage read by GDAL's own ogr2ogr (to CSV, geometry as X,Y,Z).
TEST_F(GcpExport, GeoPackageReadsBackInOgrWithResiduals) {
  if (std::system("command -v ogr2ogr >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "ogr2ogr (gdal-bin) is not installed";
  }
  const std::string path = folder_->Path("gcp.gpkg");
  ASSERT_EQ(Export("--format gpkg", path), 0) << ExportError();
  const std::string csv = folder_->Path("gcp.csv");
  ASSERT_EQ(std::system(("ogr2ogr -f CSV " + Quote(csv) + " " + Quote(path) +
                         " -lco GEOMETRY=AS_XYZ -lco STRING_QUOTING=IF_NEEDED")
                            .c_str()),
            0);
  const std::string srs = folder_->Path("srs.txt");
  ASSERT_EQ(std::system(("ogrinfo -ro -so " + Quote(path) +
                         " ground_control_points > " + Quote(srs))
                            .c_str()),
            0);
  EXPECT_NE(ReadWholeFile(srs).find("ID[\"EPSG\",4979]"), std::string::npos)
      << ReadWholeFile(srs);
  const CsvTable table = CsvTable::Read(
      csv, "gcp.csv", {"X", "Y", "Z", "name", "role", "de_m", "d3d_m"});
  const TruthCheck truth(Survey());
  std::map<std::string, GcpResidual> residuals;
  for (const GcpResidual& r :
       ReadGcpResiduals(Results("gcp_residuals.csv"), "gcp_residuals.csv")) {
    residuals[r.crossing_id + "/" + std::to_string(r.band) + "/" +
              std::to_string(r.vertex)] = r;
  }
  ASSERT_EQ(table.NumRows(), static_cast<int>(residuals.size()));
  for (int row = 0; row < table.NumRows(); ++row) {
    const std::string name = table.GetString(row, "name");
    const Geodetic database = DatabaseVertex(truth.database(), name);
    EXPECT_NEAR(table.GetDouble(row, "X"), database.lon_deg, 1e-12);
    EXPECT_NEAR(table.GetDouble(row, "Y"), database.lat_deg, 1e-12);
    EXPECT_NEAR(table.GetDouble(row, "Z"), database.h_m, 1e-9);
    const GcpResidual& r = residuals.at(name);
    EXPECT_EQ(table.GetString(row, "role"),
              r.role == GcpRole::kControl ? "control" : "check");
    EXPECT_NEAR(table.GetDouble(row, "de_m"), r.d_enu.x(), 1e-12);
    EXPECT_NEAR(table.GetDouble(row, "d3d_m"), r.d_enu.norm(), 1e-12);
  }
}

TEST_F(GcpExport, MetashapeReferenceMarksCheckPointsDisabled) {
  const std::string path = folder_->Path("markers.csv");
  ASSERT_EQ(Export("--format metashape", path), 0) << ExportError();
  const std::string text = ReadWholeFile(path);
  const std::string projections =
      ReadWholeFile(folder_->Path("markers_projections.csv"));
  std::map<std::string, GcpRole> roles;
  for (const GcpResidual& r :
       ReadGcpResiduals(Results("gcp_residuals.csv"), "gcp_residuals.csv")) {
    roles[r.crossing_id + "/" + std::to_string(r.band) + "/" +
          std::to_string(r.vertex)] = r.role;
  }
  std::istringstream in(text);
  std::string line;
  int rows = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::istringstream split(line);
    std::string field;
    while (std::getline(split, field, ',')) fields.push_back(field);
    ASSERT_EQ(fields.size(), 8u) << line;
    EXPECT_EQ(fields[7], roles.at(fields[0]) == GcpRole::kControl ? "1" : "0");
    EXPECT_NE(projections.find(fields[0] + ","), std::string::npos);
    ++rows;
  }
  EXPECT_EQ(rows, static_cast<int>(roles.size()));
}

// A compound CRS (projected + geoid heights) has no single EPSG code for
// gcp_list.txt's header, but Metashape's file still names it (issue 47: its
// CRS comment was empty).
TEST_F(GcpExport, MetashapeNamesACompoundCrs) {
  if (!fs::exists("/usr/share/proj/egm96_15.gtx")) {
    GTEST_SKIP() << "the EGM96 grid (Debian proj-data) is not installed";
  }
  const std::string path = folder_->Path("compound.csv");
  ASSERT_EQ(Export("--format metashape --crs EPSG:32631+5773", path), 0)
      << ExportError();
  const std::string text = ReadWholeFile(path);
  const std::string first = text.substr(0, text.find('\n'));
  EXPECT_NE(first.find("CRS EPSG:32631+5773 ("), std::string::npos) << first;
  EXPECT_NE(first.find("EGM96"), std::string::npos) << first;
}

// An observation the reconstruction placed outside its image (a band
// corner extrapolated past the edge: -5.1 px on the demo) is not exported;
// every exported observation lies on its image.
TEST_F(GcpExport, ObservationsOutsideTheImageAreLeftOut) {
  const std::string bands = Results("reconstructed_bands.csv");
  const std::string original = ReadWholeFile(bands);
  std::vector<ReconstructedVertex> vertices =
      ReadReconstructedBands(bands, "reconstructed_bands.csv");
  const std::vector<VertexMatch> matches =
      ReadMatches(Results("matches.csv"), "matches.csv");
  ASSERT_FALSE(matches.empty());
  const VertexMatch& moved = matches.back();
  int changed = 0;
  for (ReconstructedVertex& v : vertices) {
    if (v.exposure_id == moved.exposure_id && v.band_id == moved.band_id &&
        v.vertex == moved.vertex) {
      v.uv_left.x() = -5.1;
      ++changed;
    }
  }
  ASSERT_EQ(changed, 1);
  WriteReconstructedBands(vertices, {}, bands);
  const std::string path = folder_->Path("outside.csv");
  const int status = Export("--format metashape --include-check", path);
  {
    std::ofstream restore(bands, std::ios::binary);
    restore << original;
  }
  ASSERT_EQ(status, 0) << ExportError();
  const Rig rig = ReadRig(Survey("rig.yaml"), "rig.yaml");
  std::istringstream in(
      ReadWholeFile(folder_->Path("outside_projections.csv")));
  int rows = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::istringstream split(line);
    for (std::string field; std::getline(split, field, ',');) {
      fields.push_back(field);
    }
    ASSERT_EQ(fields.size(), 4u) << line;
    const double u = std::stod(fields[2]), v = std::stod(fields[3]);
    EXPECT_GE(u, -0.5) << line;
    EXPECT_GE(v, -0.5) << line;
    EXPECT_LE(u, rig.cameras.front().camera.width() - 0.5) << line;
    EXPECT_LE(v, rig.cameras.front().camera.height() - 0.5) << line;
    ++rows;
  }
  EXPECT_GT(rows, 10);
}

TEST_F(GcpExport, AFolderWithoutMatchesIsAClearError) {
  TemporaryFolder empty;
  const int status =
      RunZebrageo("export-gcp " + Quote(Survey()) + " " + Quote(empty.Path()) +
                      " --format odm -o " + Quote(empty.Path("gcp_list.txt")),
                  empty.Path("out"), empty.Path("err"));
  EXPECT_EQ(status, 1);
  EXPECT_NE(ReadWholeFile(empty.Path("err")).find("matches.csv"),
            std::string::npos)
      << ReadWholeFile(empty.Path("err"));
  EXPECT_FALSE(fs::exists(empty.Path("gcp_list.txt")));
}

}  // namespace
}  // namespace zebrageo
