#include "survey/results.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "survey/input_error.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

std::vector<ReconstructedVertex> SampleVertices() {
  std::vector<ReconstructedVertex> vertices;
  for (int v = 0; v < 4; ++v) {
    ReconstructedVertex vertex;
    vertex.exposure_id = 123456789012;
    vertex.pair = 1;
    vertex.band_id = 42;
    vertex.group_id = 7;
    vertex.vertex = v;
    vertex.p_body = Eigen::Vector3d(8.0 + v / 3.0, -1.0 / 7.0, 2.1 + 1e-9 * v);
    Eigen::Matrix3d a = Eigen::Matrix3d::Random() * 0.01;
    vertex.covariance_body = a * a.transpose();
    vertex.uv_left = Eigen::Vector2d(1023.123456789, 700.5 / 3.0);
    vertex.uv_right = Eigen::Vector2d(-3.25, 1e-7);
    vertex.score = 0.9 / (v + 1);
    vertices.push_back(vertex);
  }
  return vertices;
}

TEST(ReconstructedBands, WriteThenReadIsExact) {
  TemporaryFolder folder;
  const std::vector<ReconstructedVertex> vertices = SampleVertices();
  const std::string path = folder.Path(kReconstructedBandsFile);
  WriteReconstructedBands(vertices, {"zebrageo reconstruct", "seed 1"}, path);
  EXPECT_EQ(folder.CountEntries(), 1);  // no temporary file left
  const std::vector<ReconstructedVertex> read =
      ReadReconstructedBands(path, kReconstructedBandsFile);
  ASSERT_EQ(read.size(), vertices.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].exposure_id, vertices[i].exposure_id);
    EXPECT_EQ(read[i].pair, vertices[i].pair);
    EXPECT_EQ(read[i].band_id, vertices[i].band_id);
    EXPECT_EQ(read[i].group_id, vertices[i].group_id);
    EXPECT_EQ(read[i].vertex, vertices[i].vertex);
    EXPECT_LE((read[i].p_body - vertices[i].p_body).norm(), 1e-12);
    EXPECT_LE((read[i].covariance_body - vertices[i].covariance_body).norm(),
              1e-12);
    EXPECT_LE((read[i].uv_left - vertices[i].uv_left).norm(), 1e-12);
    EXPECT_LE((read[i].uv_right - vertices[i].uv_right).norm(), 1e-12);
    EXPECT_EQ(read[i].score, vertices[i].score);
  }
}

TEST(ReconstructedBands, ReaderRejectsBadRows) {
  TemporaryFolder folder;
  const std::string header =
      "exposure_id,pair,band_id,group_id,vertex,x,y,z,sxx,sxy,sxz,syy,syz,szz,"
      "u_left,v_left,u_right,v_right,score\n";
  const std::string good =
      "1,0,5,2,0,1,2,3,0.01,0,0,0.01,0,0.01,10,20,5,20,0.9\n";
  auto error_of = [&](const std::string& rows) {
    const std::string path = folder.Write("r.csv", header + good + rows);
    return ErrorOf([&] { ReadReconstructedBands(path, "r.csv"); });
  };
  EXPECT_THAT(error_of("1,0,5,2,4,1,2,3,0.01,0,0,0.01,0,0.01,10,20,5,20,0.9\n"),
              HasSubstr("r.csv:3: column 'vertex': 4 is outside [0, 3]"));
  EXPECT_THAT(
      error_of("1,0,5,2,1,nan,2,3,0.01,0,0,0.01,0,0.01,10,20,5,20,0.9\n"),
      HasSubstr("r.csv:3: column 'x': \"nan\" is not finite"));
  EXPECT_THAT(
      error_of("1,0,5,2,1,1,2,3,-0.01,0,0,0.01,0,0.01,10,20,5,20,0.9\n"),
      HasSubstr("r.csv:3: column 'sxx': -0.01 must be >= 0"));
  EXPECT_THAT(error_of("1,0,5,2,1,1,2,3,0.01,0,0,0.01,0,0.01,10,20,5,20,1.5\n"),
              HasSubstr("r.csv:3: column 'score': 1.5 is outside [0, 1]"));
  EXPECT_THAT(error_of("1,0,5,2,0,1,2,3,0.01,0,0,0.01,0,0.01,10,20,5,20,0.9\n"),
              HasSubstr("r.csv:3: band_id 5 vertex 0 already on line 2"));
  EXPECT_THAT(error_of("9,0,5,2,1,1,2,3,0.01,0,0,0.01,0,0.01,10,20,5,20,0.9\n"),
              HasSubstr("r.csv:3: band_id 5 has another exposure_id, pair or "
                        "group_id than on line 2"));
  EXPECT_THAT(error_of("1,0,5,2,1,1,2,3\n"), HasSubstr("r.csv:3: truncated"));
  const std::string path = folder.Write("bad_header.csv", "exposure_id,pair\n");
  EXPECT_THAT(ErrorOf([&] { ReadReconstructedBands(path, "bad.csv"); }),
              HasSubstr("bad.csv:1: header lacks required column 'band_id'"));
}

TEST(Matches, WriteThenReadIsExact) {
  TemporaryFolder folder;
  const std::vector<VertexMatch> matches = {{10, 42, 0, "C1", 1, 3},
                                            {10, 42, 3, "C1", 1, 2},
                                            {-11, 7, 2, "piéton-9", 12, 0}};
  const std::string path = folder.Path(kMatchesFile);
  WriteMatches(matches, {}, path);
  EXPECT_EQ(folder.CountEntries(), 1);
  const std::vector<VertexMatch> read = ReadMatches(path, kMatchesFile);
  ASSERT_EQ(read.size(), matches.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].exposure_id, matches[i].exposure_id);
    EXPECT_EQ(read[i].band_id, matches[i].band_id);
    EXPECT_EQ(read[i].vertex, matches[i].vertex);
    EXPECT_EQ(read[i].crossing_id, matches[i].crossing_id);
    EXPECT_EQ(read[i].band, matches[i].band);
    EXPECT_EQ(read[i].db_vertex, matches[i].db_vertex);
  }
}

TEST(Matches, ReaderRejectsBadRowsAndWriterBadIds) {
  TemporaryFolder folder;
  const std::string header =
      "exposure_id,band_id,vertex,crossing_id,band,db_vertex\n";
  auto error_of = [&](const std::string& rows) {
    const std::string path = folder.Write("m.csv", header + rows);
    return ErrorOf([&] { ReadMatches(path, "matches.csv"); });
  };
  EXPECT_THAT(error_of("1,2,0,C1,1,4\n"),
              HasSubstr("matches.csv:2: column 'db_vertex': 4 is outside [0, "
                        "3]"));
  EXPECT_THAT(error_of("1,2,0,,1,1\n"),
              HasSubstr("matches.csv:2: column 'crossing_id' is empty"));
  EXPECT_THAT(error_of("1,2,0,C1,0,1\n"),
              HasSubstr("matches.csv:2: column 'band': 0 is outside"));
  EXPECT_THROW(WriteMatches({{1, 2, 0, "a,b", 1, 1}}, {}, folder.Path("w.csv")),
               std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(folder.Path("w.csv")));
}

TEST(CrossingDecisions, WriteThenReadIsExactAndReasonsStayOneField) {
  TemporaryFolder folder;
  const std::vector<CrossingDecision> decisions = {
      {5, 1, Decision::kMatched, "C1", "4 bands, rms 0.03 m"},
      {5, 2, Decision::kRefused, "", "ambiguous: C2 and C3"},
      {6, 3, Decision::kNoCandidate, "", ""}};
  const std::string path = folder.Path(kCrossingDecisionsFile);
  WriteCrossingDecisions(decisions, {"comment, with comma"}, path);
  EXPECT_EQ(folder.CountEntries(), 1);
  const std::vector<CrossingDecision> read =
      ReadCrossingDecisions(path, kCrossingDecisionsFile);
  ASSERT_EQ(read.size(), decisions.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].exposure_id, decisions[i].exposure_id);
    EXPECT_EQ(read[i].group_id, decisions[i].group_id);
    EXPECT_EQ(read[i].decision, decisions[i].decision);
    EXPECT_EQ(read[i].crossing_id, decisions[i].crossing_id);
  }
  EXPECT_EQ(read[0].reason, "4 bands; rms 0.03 m");
  EXPECT_EQ(read[1].reason, "ambiguous: C2 and C3");
  EXPECT_EQ(read[2].reason, "");
  EXPECT_STREQ(DecisionName(Decision::kNoCandidate), "no_candidate");
}

TEST(CrossingDecisions, ReaderRejectsUnknownDecisions) {
  TemporaryFolder folder;
  const std::string header =
      "exposure_id,group_id,decision,crossing_id,reason\n";
  auto error_of = [&](const std::string& rows) {
    const std::string path = folder.Write("d.csv", header + rows);
    return ErrorOf([&] { ReadCrossingDecisions(path, "d.csv"); });
  };
  EXPECT_THAT(error_of("1,2,maybe,,x\n"),
              HasSubstr("d.csv:2: column 'decision': 'maybe' is not matched, "
                        "refused or no_candidate"));
  EXPECT_THAT(error_of("1,2,matched,,x\n"),
              HasSubstr("d.csv:2: decision 'matched' without a crossing_id"));
  EXPECT_THAT(error_of("x,2,matched,C1,x\n"),
              HasSubstr("d.csv:2: column 'exposure_id': \"x\" is not an "
                        "integer"));
}

TEST(CameraPoses, WriteThenReadIsExact) {
  TemporaryFolder folder;
  std::vector<CameraPose> poses(2);
  poses[0].exposure_id = 100;
  poses[0].camera = "left";
  poses[0].time = 345678.123456789;
  poses[0].position = Geodetic{49.894123456789, 2.295812345678, 61.2345};
  poses[0].p_enu = Eigen::Vector3d(123.456789, -98.7654321, 1.25);
  poses[0].q_enu_cam = Eigen::Quaterniond(
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized()));
  poses[1] = poses[0];
  poses[1].camera = "right";
  poses[1].q_enu_cam = Eigen::Quaterniond(-0.5, 0.5, -0.5, 0.5);
  const std::string path = folder.Path(kPosesFile);
  WriteCameraPoses(poses, path);
  EXPECT_EQ(folder.CountEntries(), 1);
  const std::vector<CameraPose> read = ReadCameraPoses(path, kPosesFile);
  ASSERT_EQ(read.size(), 2u);
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].exposure_id, poses[i].exposure_id);
    EXPECT_EQ(read[i].camera, poses[i].camera);
    EXPECT_EQ(read[i].time, poses[i].time);
    EXPECT_EQ(read[i].position.lat_deg, poses[i].position.lat_deg);
    EXPECT_EQ(read[i].position.lon_deg, poses[i].position.lon_deg);
    EXPECT_EQ(read[i].position.h_m, poses[i].position.h_m);
    EXPECT_LE((read[i].p_enu - poses[i].p_enu).norm(), 1e-12);
    // Written scalar first: w, x, y, z, and read back identically.
    EXPECT_LE((read[i].q_enu_cam.coeffs() - poses[i].q_enu_cam.coeffs()).norm(),
              1e-12);
  }
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line[0] == '#') {
  }
  EXPECT_EQ(line,
            "exposure_id,camera,time,lat,lon,h,east,north,up,qw,qx,qy,qz");
}

TEST(CameraPoses, ReaderRejectsNonRotationsAndBadLatitudes) {
  TemporaryFolder folder;
  const std::string header =
      "exposure_id,camera,time,lat,lon,h,east,north,up,qw,qx,qy,qz\n";
  auto error_of = [&](const std::string& rows) {
    const std::string path = folder.Write("p.csv", header + rows);
    return ErrorOf([&] { ReadCameraPoses(path, "poses.csv"); });
  };
  EXPECT_THAT(error_of("1,left,2,49,2,60,0,0,0,1,0,0,0.1\n"),
              HasSubstr("poses.csv:2: quaternion qw,qx,qy,qz has norm"));
  EXPECT_THAT(error_of("1,left,2,95,2,60,0,0,0,1,0,0,0\n"),
              HasSubstr("poses.csv:2: column 'lat': 95 is outside [-90, 90]"));
  EXPECT_THAT(error_of("1,left,2,45,2,60,0,0,0,1,0,0,-inf\n"),
              HasSubstr("poses.csv:2: column 'qz': \"-inf\" is not finite"));
}

// The file holds 0.1 mm, 0.001 px and 0.01 in the normalized residual
// (what the adjustment ships): read back to that resolution.
TEST(GcpResiduals, WriteThenReadKeepsTheWrittenResolution) {
  TemporaryFolder folder;
  const std::vector<GcpResidual> residuals = {
      {"C1", 1, 0, GcpRole::kControl, Eigen::Vector3d(0.01, -0.02, 0.003), 0.4,
       12, GcpStatus::kControl, 0.83},
      {"C2", 3, 3, GcpRole::kCheck, Eigen::Vector3d(-1.0 / 3, 0.0, 1e-12), 0.0,
       0, GcpStatus::kCheck, 0.0},
      {"C3", 2, 1, GcpRole::kControl, Eigen::Vector3d(0.51, 0.2, -0.1), 1.23456,
       4, GcpStatus::kRejected, 7.126}};
  const std::string path = folder.Path(kGcpResidualsFile);
  WriteGcpResiduals(residuals, path);
  EXPECT_EQ(folder.CountEntries(), 1);
  const std::vector<GcpResidual> read =
      ReadGcpResiduals(path, kGcpResidualsFile);
  ASSERT_EQ(read.size(), residuals.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].crossing_id, residuals[i].crossing_id);
    EXPECT_EQ(read[i].band, residuals[i].band);
    EXPECT_EQ(read[i].vertex, residuals[i].vertex);
    EXPECT_EQ(read[i].role, residuals[i].role);
    EXPECT_EQ(read[i].status, residuals[i].status);
    EXPECT_LE((read[i].d_enu - residuals[i].d_enu).cwiseAbs().maxCoeff(),
              0.5e-4);
    EXPECT_NEAR(read[i].rms_px, residuals[i].rms_px, 0.5e-3);
    EXPECT_EQ(read[i].n_images, residuals[i].n_images);
    EXPECT_NEAR(read[i].normalized_residual, residuals[i].normalized_residual,
                0.5e-2);
  }
  // Written again, the file is the same.
  const std::string again = folder.Path("again.csv");
  WriteGcpResiduals(read, again);
  std::ifstream a(path), b(again);
  std::stringstream text_a, text_b;
  text_a << a.rdbuf();
  text_b << b.rdbuf();
  EXPECT_EQ(text_a.str(), text_b.str());
}

TEST(GcpResiduals, FilesWithoutStatusTakeTheRole) {
  TemporaryFolder folder;
  const std::string path =
      folder.Write("g.csv",
                   "crossing_id,band,vertex,role,de,dn,du,d3d,rms_px,n_images\n"
                   "C1,1,0,control,0,0,0,0,0.1,3\n"
                   "C1,1,1,check,0,0,0,0,0.1,3\n");
  const std::vector<GcpResidual> read =
      ReadGcpResiduals(path, kGcpResidualsFile);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].status, GcpStatus::kControl);
  EXPECT_EQ(read[1].status, GcpStatus::kCheck);
}

TEST(GcpResiduals, ReaderRejectsUnknownRoles) {
  TemporaryFolder folder;
  const std::string path =
      folder.Write("g.csv",
                   "crossing_id,band,vertex,role,de,dn,du,d3d,rms_px,n_images\n"
                   "C1,1,0,control,0,0,0,0,0.1,3\n"
                   "C1,1,1,truth,0,0,0,0,0.1,3\n");
  EXPECT_THAT(ErrorOf([&] { ReadGcpResiduals(path, "gcp_residuals.csv"); }),
              HasSubstr("gcp_residuals.csv:3: column 'role': 'truth' is not "
                        "control or check"));
}

TEST(AdjustedBands, WriteThenReadIsExact) {
  TemporaryFolder folder;
  std::vector<AdjustedBand> bands(2);
  for (int k = 0; k < 4; ++k) {
    bands[0].corners[k] =
        Geodetic{49.8941 + k * 1e-6 / 3.0, 2.2958 + (k % 2) * 1e-5, 60.0 + k};
  }
  bands[0].crossing_id = "C1";
  bands[0].band = 2;
  bands[0].band_id = 42;
  bands[0].exposure_id = 1001;
  bands[1] = bands[0];
  bands[1].crossing_id.reset();  // unmatched: null in the file
  bands[1].band.reset();
  bands[1].band_id = 43;
  const std::string path = folder.Path(kBandsGeoJsonFile);
  WriteAdjustedBands(bands, path);
  EXPECT_EQ(folder.CountEntries(), 1);
  const std::vector<AdjustedBand> read =
      ReadAdjustedBands(path, kBandsGeoJsonFile);
  ASSERT_EQ(read.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(read[i].crossing_id, bands[i].crossing_id);
    EXPECT_EQ(read[i].band, bands[i].band);
    EXPECT_EQ(read[i].band_id, bands[i].band_id);
    EXPECT_EQ(read[i].exposure_id, bands[i].exposure_id);
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(read[i].corners[k].lat_deg, bands[i].corners[k].lat_deg);
      EXPECT_EQ(read[i].corners[k].lon_deg, bands[i].corners[k].lon_deg);
      EXPECT_EQ(read[i].corners[k].h_m, bands[i].corners[k].h_m);
    }
  }
}

TEST(AdjustedBands, ReaderNamesTheLineOfABadFeature) {
  TemporaryFolder folder;
  const std::string path = folder.Write(
      "b.geojson",
      "{\"type\": \"FeatureCollection\", \"features\": [\n"
      "{\"type\": \"Feature\", \"geometry\": {\"type\": \"Polygon\", "
      "\"coordinates\": [[[2, 49, 1], [2.1, 49, 1], [2.1, 49.1, 1], [2, "
      "49.1, 1], [2, 49, 1]]]}, \"properties\": {\"crossing_id\": null, "
      "\"band\": null, \"band_id\": 1, \"exposure_id\": 2}},\n"
      "{\"type\": \"Feature\", \"geometry\": {\"type\": \"Polygon\", "
      "\"coordinates\": [[[2, 49, 1], [2.1, 49, 1], [2.1, 49.1, 1], [2, "
      "49.1, 1], [2, 49.5, 1]]]}, \"properties\": {\"crossing_id\": null, "
      "\"band\": null, \"band_id\": 1, \"exposure_id\": 2}}\n"
      "]}\n");
  EXPECT_THAT(ErrorOf([&] { ReadAdjustedBands(path, "bands.geojson"); }),
              HasSubstr("bands.geojson:3: feature 2: ring is not closed"));
}

TEST(Results, WritersToAMissingFolderThrowAndLeaveNothing) {
  TemporaryFolder folder;
  const std::string missing = folder.Path("no/such/folder/file");
  EXPECT_ANY_THROW(WriteReconstructedBands(SampleVertices(), {}, missing));
  EXPECT_ANY_THROW(WriteMatches({}, {}, missing));
  EXPECT_ANY_THROW(WriteCrossingDecisions({}, {}, missing));
  EXPECT_ANY_THROW(WriteCameraPoses({}, missing));
  EXPECT_ANY_THROW(WriteGcpResiduals({}, missing));
  EXPECT_ANY_THROW(WriteAdjustedBands({}, missing));
  EXPECT_EQ(folder.CountEntries(), 0);
}

}  // namespace
}  // namespace zebrageo
