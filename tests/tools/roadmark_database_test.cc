// Road-mark databases through GDAL/OGR on the real binary: a survey's
// roadmarks.geojson converted by GDAL's own ogr2ogr to a GeoPackage in
// Lambert-93 (3D), a Shapefile in UTM, and a table of a real PostGIS server
// (a cluster of its own in a temporary folder), gives the same matches and
// poses (1 mm) as the GeoJSON. On a simulated survey and on a field case
// of ../shared (skipped when absent).
#include <glob.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <regex>
#include <set>

#include "tests/tools/geodata_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

// Replaces the line `key: ...` of a survey's survey.yaml.
void SetManifestKey(const std::string& survey, const std::string& key,
                    const std::string& value) {
  std::istringstream in(ReadWholeFile(survey + "/survey.yaml"));
  std::string text, line;
  while (std::getline(in, line)) {
    text += (line.rfind(key + ":", 0) == 0 ? key + ": " + value : line) + "\n";
  }
  std::ofstream(survey + "/survey.yaml") << text;
}

// The surveys, reconstructed once for every test of the file.
const ReconstructedSurvey* Survey(const std::string& name) {
  static std::map<std::string, std::unique_ptr<ReconstructedSurvey>> surveys;
  auto& survey = surveys[name];
  if (!survey) {
    if (name == "simulated") {
      survey = std::make_unique<ReconstructedSurvey>(SmallSurveyArguments());
    } else {
      const std::string source =
          SharedDatasetsFolder().empty()
              ? ""
              : SharedDatasetsFolder() + "/field-cases/" + name;
      if (source.empty() || !fs::exists(source + "/survey.yaml")) {
        return nullptr;
      }
      survey = std::make_unique<ReconstructedSurvey>("", source);
    }
  }
  return survey.get();
}

// The reference results: the survey as given (lines: with road lines).
const std::string& Reference(const ReconstructedSurvey& survey, bool lines) {
  static std::map<std::pair<const ReconstructedSurvey*, bool>, std::string>
      results;
  std::string& folder = results[{&survey, lines}];
  if (folder.empty()) {
    folder = survey.ProcessCopy(lines ? "geojson" : "geojson-no-lines", "",
                                nullptr, lines ? "" : "--no-lines");
  }
  return folder;
}

void ExpectSameMatchesAndPoses(const std::string& results,
                               const std::string& reference) {
  ASSERT_FALSE(results.empty());
  ASSERT_FALSE(reference.empty());
  const std::string matches = ReadWholeFile(results + "/" + kMatchesFile);
  EXPECT_EQ(WithoutComments(matches),
            WithoutComments(ReadWholeFile(reference + "/" + kMatchesFile)));
  EXPECT_GT(std::count(matches.begin(), matches.end(), '\n'), 10);
  const auto [worst_m, worst_q] =
      PoseDifference(results + "/" + kPosesFile, reference + "/" + kPosesFile);
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_LT(worst_q, 1e-6);
}

// ogr2ogr on the survey's roadmarks.geojson into `output` (relative to the
// survey), with `arguments`.
void Ogr2ogr(const std::string& survey, const std::string& arguments,
             const std::string& output) {
  const std::string log = survey + "/../ogr2ogr.log";
  ASSERT_EQ(Shell("cd " + Quote(survey) + " && ogr2ogr " + arguments + " " +
                      output + " roadmarks.geojson",
                  log),
            0)
      << ReadWholeFile(log);
}

class RoadmarkLayer : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (!HaveProgram("ogr2ogr")) {
      GTEST_SKIP() << "ogr2ogr (Debian gdal-bin) is not installed";
    }
    survey_ = Survey(GetParam());
    if (survey_ == nullptr) {
      GTEST_SKIP() << "../shared/datasets/field-cases/" << GetParam()
                   << " is absent";
    }
    ASSERT_TRUE(survey_->ok()) << survey_->error();
  }
  const ReconstructedSurvey* survey_ = nullptr;
};

TEST_P(RoadmarkLayer, GeoPackageInLambert93Gives3dSameMatchesAndPoses) {
  const std::string results =
      survey_->ProcessCopy("gpkg", "", [](const std::string& survey) {
        Ogr2ogr(survey, "-f GPKG -t_srs EPSG:2154 -nln zebra_bands",
                "marks.gpkg");
        SetManifestKey(survey, "roadmarks", "marks.gpkg");
      });
  ExpectSameMatchesAndPoses(results, Reference(*survey_, true));
}

TEST_P(RoadmarkLayer, ShapefileInUtmGivesSameMatchesAndPoses) {
  // A Shapefile holds one geometry type: the bands alone (no road lines),
  // compared with the GeoJSON adjusted without lines. Its attribute names
  // are cut to 10 characters (crossing_i) and guessed.
  const std::string results = survey_->ProcessCopy(
      "shp", "",
      [](const std::string& survey) {
        Ogr2ogr(survey,
                "-f 'ESRI Shapefile' -t_srs EPSG:32631 -where "
                "\"OGR_GEOMETRY='POLYGON'\"",
                "marks.shp");
        SetManifestKey(survey, "roadmarks", "marks.shp");
      },
      "--no-lines");
  ExpectSameMatchesAndPoses(results, Reference(*survey_, false));
}

// The layer ogr2ogr names for a GeoJSON: its "name" member, else the file's.
std::string GeoJsonLayerName(const std::string& path) {
  const std::string text = ReadWholeFile(path).substr(0, 300);
  const std::size_t key = text.find("\"name\"");
  if (key == std::string::npos) return fs::path(path).stem().string();
  const std::size_t open = text.find('"', text.find(':', key));
  return text.substr(open + 1, text.find('"', open + 1) - open - 1);
}

TEST_P(RoadmarkLayer, FlatGeobufWithRenamedAttributesGivesSameMatches) {
  const std::string results = survey_->ProcessCopy(
      "fgb",
      "roadmarks_fields: {crossing_id: ZEBRA, band: STRIPE_NO, "
      "sigma_xy: acc_plan, sigma_z: acc_alt}\n",
      [](const std::string& survey) {
        const std::string source = survey + "/roadmarks.geojson";
        const std::string text = ReadWholeFile(source);
        const bool lines = text.find("LineString") != std::string::npos;
        const bool ids = std::regex_search(text, std::regex(R"("id"\s*:)"));
        Ogr2ogr(survey,
                "-f FlatGeobuf -dim XYZ -t_srs EPSG:2154 -sql \"SELECT "
                "crossing_id AS "
                "ZEBRA, band AS STRIPE_NO, sigma_xy AS acc_plan, sigma_z AS "
                "acc_alt" +
                    std::string(lines ? ", type" : "") + (ids ? ", id" : "") +
                    " FROM \\\"" + GeoJsonLayerName(source) + "\\\"\"",
                "marks.fgb");
        SetManifestKey(survey, "roadmarks", "marks.fgb");
      });
  ExpectSameMatchesAndPoses(results, Reference(*survey_, true));
}

// The matches.csv rows (comments left out), one string per vertex match.
std::set<std::string> MatchRows(const std::string& results) {
  std::istringstream in(
      WithoutComments(ReadWholeFile(results + "/" + kMatchesFile)));
  std::set<std::string> rows;
  for (std::string line; std::getline(in, line);) rows.insert(line);
  return rows;
}

TEST_P(RoadmarkLayer, TwoDimensionalLayerMatchesNothingTheHeightsWouldRefuse) {
  // No heights: the bands get the trajectory's height less 1.5 m and a 5 m
  // sigma, so the database controls no height, and the survey says so.
  // Registration may then decide fewer crossings (the height guess and its
  // sigma weigh in), but a match it makes is one the 3D database makes.
  const std::string results =
      survey_->ProcessCopy("gpkg2d", "", [](const std::string& survey) {
        Ogr2ogr(survey, "-f GPKG -dim XY -t_srs EPSG:2154", "flat.gpkg");
        SetManifestKey(survey, "roadmarks", "flat.gpkg");
      });
  ASSERT_FALSE(results.empty());
  const std::string& reference = Reference(*survey_, true);
  const std::set<std::string> flat = MatchRows(results);
  const std::set<std::string> full = MatchRows(reference);
  int extra = 0;
  for (const std::string& row : flat) extra += full.count(row) == 0;
  EXPECT_EQ(extra, 0);
  EXPECT_GT(flat.size(), 8u);  // header and at least two bands' vertices
  EXPECT_THAT(ReadWholeFile(results + "/report.json"),
              HasSubstr("without heights"));
  const auto ours = CsvColumns(results + "/" + kPosesFile, {"east", "north"});
  const auto plain =
      CsvColumns(reference + "/" + kPosesFile, {"east", "north"});
  ASSERT_EQ(ours.size(), plain.size());
  double worst_m = 0.0;
  for (size_t i = 0; i < ours.size(); ++i) {
    worst_m = std::max(worst_m, std::hypot(ours[i][0] - plain[i][0],
                                           ours[i][1] - plain[i][1]));
  }
  std::cout << "2D layer: " << flat.size() - 1 << " of " << full.size() - 1
            << " vertex matches, largest horizontal pose difference " << worst_m
            << " m\n";
}

// A PostgreSQL + PostGIS cluster of its own, on a Unix socket in a
// temporary folder, stopped (and removed) when the object goes away, also
// when the test fails. PostgreSQL refuses to run as root: as root (CI),
// the server runs as the unprivileged user `nobody`.
class PostgisServer {
 public:
  PostgisServer() {
    bin_ = PostgresBin();
    if (bin_.empty()) {
      skip_ = "PostgreSQL server binaries are absent (Debian postgresql)";
      return;
    }
    if (!HaveProgram("psql")) {
      skip_ = "psql is absent (Debian postgresql-client)";
      return;
    }
    fs::permissions(folder_.Path(),
                    fs::perms::owner_all | fs::perms::group_read |
                        fs::perms::group_exec | fs::perms::others_read |
                        fs::perms::others_exec);
    socket_ = folder_.Path("pg");
    fs::create_directories(socket_);
    const std::string as_user =
        ::geteuid() == 0 ? "runuser -u nobody -- " : std::string();
    if (::geteuid() == 0 && Shell("chown nobody " + Quote(socket_),
                                  folder_.Path("chown.log")) != 0) {
      error_ = "cannot give the cluster's folder to nobody";
      return;
    }
    const std::string log = folder_.Path("server.log");
    if (Shell(as_user + Quote(bin_ + "/initdb") + " -D " +
                  Quote(socket_ + "/data") + " -A trust -U zebrageo --no-sync",
              log) != 0) {
      error_ = "initdb failed: " + ReadWholeFile(log);
      return;
    }
    stop_command_ = as_user + Quote(bin_ + "/pg_ctl") + " -D " +
                    Quote(socket_ + "/data") + " -m immediate -w stop";
    if (Shell(as_user + Quote(bin_ + "/pg_ctl") + " -D " +
                  Quote(socket_ + "/data") + " -l " +
                  Quote(socket_ + "/postgres.log") +
                  " -w -t 60 -o \"-c listen_addresses='' -c "
                  "unix_socket_directories='" +
                  socket_ + "' -c fsync=off\" start",
              log) != 0) {
      error_ = "pg_ctl start failed: " + ReadWholeFile(log) +
               ReadWholeFile(socket_ + "/postgres.log");
      return;
    }
    started_ = true;
    if (!Sql("CREATE EXTENSION postgis")) {
      skip_ =
          "the PostGIS extension is absent (Debian postgresql-15-postgis-3)";
    }
  }
  ~PostgisServer() {
    if (started_) Shell(stop_command_, folder_.Path("stop.log"));
  }

  const std::string& skip() const { return skip_; }
  const std::string& error() const { return error_; }
  std::string Connection() const {
    return "PG:host=" + socket_ + " user=zebrageo dbname=postgres";
  }
  bool Sql(const std::string& sql) const {
    return Shell("psql -v ON_ERROR_STOP=1 -h " + Quote(socket_) +
                     " -U zebrageo -d postgres -c " + Quote(sql),
                 folder_.Path("psql.log")) == 0;
  }
  std::string SqlLog() const { return ReadWholeFile(folder_.Path("psql.log")); }

 private:
  static std::string PostgresBin() {
    glob_t found;
    std::string bin;
    if (glob("/usr/lib/postgresql/*/bin/pg_ctl", 0, nullptr, &found) == 0 &&
        found.gl_pathc > 0) {
      bin = fs::path(found.gl_pathv[found.gl_pathc - 1]).parent_path();
    }
    globfree(&found);
    return bin;
  }

  TemporaryFolder folder_;
  std::string bin_, socket_, stop_command_, skip_, error_;
  bool started_ = false;
};

TEST_P(RoadmarkLayer, PostgisTableGivesSameMatchesAndPoses) {
  PostgisServer server;
  if (!server.skip().empty()) GTEST_SKIP() << server.skip();
  ASSERT_TRUE(server.error().empty()) << server.error();
  const std::string log = survey_->folder().Path("pg-ogr2ogr.log");
  ASSERT_EQ(Shell("ogr2ogr -f PostgreSQL " + Quote(server.Connection()) + " " +
                      Quote(survey_->survey() + "/roadmarks.geojson") +
                      " -nln zebra -dim XYZ -lco GEOMETRY_NAME=geom",
                  log),
            0)
      << ReadWholeFile(log);
  // A city-sized table holds other surveys' crossings: a copy of every band
  // 30 km east, with the same ids, must stay outside the bounding box read
  // (read, it would be a duplicate band and an error).
  ASSERT_TRUE(server.Sql(
      "INSERT INTO zebra (geom, crossing_id, band, sigma_xy, sigma_z, type) "
      "SELECT ST_Translate(geom, 0.4, 0), crossing_id, band, sigma_xy, "
      "sigma_z, type FROM zebra"))
      << server.SqlLog();
  const std::string results = survey_->ProcessCopy(
      "postgis", "roadmarks_layer: zebra\n",
      [&server](const std::string& survey) {
        SetManifestKey(survey, "roadmarks", "\"" + server.Connection() + "\"");
      },
      "", "--allow-outside-paths");
  ExpectSameMatchesAndPoses(results, Reference(*survey_, true));
  // A survey from someone else may not make zebrageo connect to a server.
  const std::string out = survey_->folder().Path("pg-refused.out");
  EXPECT_EQ(
      RunZebrageo("check " + Quote(survey_->folder().Path("postgis-survey")),
                  out, out),
      1);
  EXPECT_THAT(ReadWholeFile(out), HasSubstr("--allow-outside-paths"));
}

INSTANTIATE_TEST_SUITE_P(Surveys, RoadmarkLayer,
                         ::testing::Values("simulated", "amiens-short"));

}  // namespace
}  // namespace zebrageo
