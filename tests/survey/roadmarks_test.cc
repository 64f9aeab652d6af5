#include "survey/roadmarks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "survey/csv.h"
#include "survey/input_error.h"
#include "tests/survey/damaged_input.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

const Geodetic kOrigin{49.8941, 2.2958, 60.0};

// Corners of a 0.5 m x 3 m band whose first corner is `east` m east of the
// origin, in ring order (counter-clockwise from above unless reversed).
std::vector<Geodetic> Band(double east, bool clockwise = false) {
  const LocalFrame frame(kOrigin);
  std::vector<Eigen::Vector3d> enu = {{east, 0, 0.01},
                                      {east + 0.5, 0, 0.02},
                                      {east + 0.5, 3, 0.03},
                                      {east, 3, 0.04}};
  if (clockwise) std::swap(enu[1], enu[3]);
  std::vector<Geodetic> corners;
  for (const Eigen::Vector3d& p : enu) {
    corners.push_back(frame.GeodeticFromEnu(p));
  }
  return corners;
}

std::string Position(const Geodetic& p) {
  return "[" + FormatDouble(p.lon_deg) + ", " + FormatDouble(p.lat_deg) + ", " +
         FormatDouble(p.h_m) + "]";
}

// A Polygon feature with `ring` written as given (not closed for you).
std::string PolygonFeature(const std::vector<Geodetic>& ring,
                           const std::string& properties) {
  std::string coordinates;
  for (const Geodetic& p : ring) {
    coordinates += (coordinates.empty() ? "" : ", ") + Position(p);
  }
  return "{\"type\": \"Feature\", \"geometry\": {\"type\": \"Polygon\", "
         "\"coordinates\": [[" +
         coordinates + "]]}, \"properties\": {" + properties + "}}";
}

std::vector<Geodetic> Closed(std::vector<Geodetic> corners) {
  corners.push_back(corners.front());
  return corners;
}

std::string BandFeature(const std::string& crossing, int band, double east) {
  return PolygonFeature(Closed(Band(east)),
                        "\"crossing_id\": \"" + crossing +
                            "\", \"band\": " + std::to_string(band) +
                            ", \"sigma_xy\": 0.05, \"sigma_z\": 0.1");
}

std::string Collection(const std::vector<std::string>& features) {
  std::string text = "{\"type\": \"FeatureCollection\", \"features\": [\n";
  for (size_t i = 0; i < features.size(); ++i) {
    text += features[i] + (i + 1 < features.size() ? ",\n" : "\n");
  }
  return text + "]}\n";
}

std::string ErrorOf(const std::string& text) {
  try {
    ParseRoadmarks(text, "roadmarks.geojson");
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

const char kProperties[] =
    "\"crossing_id\": \"C3\", \"band\": 2, \"sigma_xy\": 0.05, "
    "\"sigma_z\": 0.1";

TEST(Roadmarks, ReadsBandsAndLinesKeepingTheFilesRingOrder) {
  const std::vector<Geodetic> clockwise = Band(2.0, /*clockwise=*/true);
  const std::string text = Collection(
      {BandFeature("C1", 1, 0.0),
       PolygonFeature(Closed(clockwise),
                      "\"crossing_id\": 17, \"band\": 1, \"sigma_xy\": 0.07, "
                      "\"sigma_z\": 0"),
       "{\"type\": \"Feature\", \"geometry\": {\"type\": \"LineString\", "
       "\"coordinates\": [" +
           Position(Band(5)[0]) + ", " + Position(Band(5)[3]) +
           "]}, \"properties\": {\"type\": \"stop_line\"}}",
       // Not used: a point, a line without type, a polygon road mark.
       "{\"type\": \"Feature\", \"geometry\": {\"type\": \"Point\", "
       "\"coordinates\": [2.3, 49.9]}, \"properties\": {}}",
       "{\"type\": \"Feature\", \"geometry\": {\"type\": \"LineString\", "
       "\"coordinates\": [[2.3, 49.9]]}, \"properties\": {}}",
       PolygonFeature({Band(9)[0]}, "\"type\": \"arrow\""),
       "{\"type\": \"Feature\", \"geometry\": null, \"properties\": {}}"});
  const RoadmarkDatabase database = ParseRoadmarks(text, "roadmarks.geojson");
  ASSERT_EQ(database.bands.size(), 2u);
  EXPECT_EQ(database.bands[0].crossing_id, "C1");
  EXPECT_EQ(database.bands[0].band, 1);
  EXPECT_EQ(database.bands[0].sigma_xy_m, 0.05);
  EXPECT_EQ(database.bands[0].sigma_z_m, 0.1);
  // Integer ids name crossings too.
  EXPECT_EQ(database.bands[1].crossing_id, "17");
  // db_vertex indices refer to the file's ring: kept as written.
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(database.bands[1].corners[k].lat_deg, clockwise[k].lat_deg);
    EXPECT_EQ(database.bands[1].corners[k].lon_deg, clockwise[k].lon_deg);
    EXPECT_EQ(database.bands[1].corners[k].h_m, clockwise[k].h_m);
  }
  ASSERT_EQ(database.lines.size(), 1u);
  EXPECT_EQ(database.lines[0].type, "stop_line");
  EXPECT_EQ(database.lines[0].id, "line-0");
  EXPECT_EQ(database.lines[0].points.size(), 2u);
  EXPECT_EQ(database.lines[0].sigma_xy_m, 0.05);  // defaults
  EXPECT_EQ(database.lines[0].sigma_z_m, 0.10);
}

TEST(Roadmarks, WriteThenReadIsExact) {
  TemporaryFolder folder;
  RoadmarkDatabase database;
  for (int b = 1; b <= 3; ++b) {
    RoadmarkBand band;
    band.crossing_id = "passage piéton 7";  // non-ASCII UTF-8
    band.band = b;
    const std::vector<Geodetic> corners = Band(b * 1.0 / 3.0);
    std::copy(corners.begin(), corners.end(), band.corners.begin());
    band.sigma_xy_m = 0.1 / 3.0;
    band.sigma_z_m = 0.2 / 7.0;
    database.bands.push_back(band);
  }
  RoadmarkLine line;
  line.id = "L1";
  line.type = "lane_dashed";
  line.points = Band(20.0);
  line.sigma_xy_m = 0.03;
  line.sigma_z_m = 0.06;
  database.lines.push_back(line);
  WriteRoadmarks(database, folder.Path("roadmarks.geojson"));
  EXPECT_EQ(folder.CountEntries(), 1);  // no temporary file left
  const RoadmarkDatabase read =
      ReadRoadmarks(folder.Path("roadmarks.geojson"), "roadmarks.geojson");
  ASSERT_EQ(read.bands.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const RoadmarkBand& a = database.bands[i];
    const RoadmarkBand& b = read.bands[i];
    EXPECT_EQ(a.crossing_id, b.crossing_id);
    EXPECT_EQ(a.band, b.band);
    EXPECT_EQ(a.sigma_xy_m, b.sigma_xy_m);
    EXPECT_EQ(a.sigma_z_m, b.sigma_z_m);
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(a.corners[k].lat_deg, b.corners[k].lat_deg);
      EXPECT_EQ(a.corners[k].lon_deg, b.corners[k].lon_deg);
      EXPECT_EQ(a.corners[k].h_m, b.corners[k].h_m);
    }
  }
  ASSERT_EQ(read.lines.size(), 1u);
  EXPECT_EQ(read.lines[0].id, "L1");
  EXPECT_EQ(read.lines[0].type, "lane_dashed");
  EXPECT_EQ(read.lines[0].sigma_xy_m, 0.03);
  ASSERT_EQ(read.lines[0].points.size(), 4u);
  EXPECT_EQ(read.lines[0].points[3].lon_deg, line.points[3].lon_deg);
}

TEST(Roadmarks, WriteToAMissingFolderThrowsAndLeavesNothing) {
  TemporaryFolder folder;
  EXPECT_ANY_THROW(WriteRoadmarks(RoadmarkDatabase(), folder.Path("x/r.json")));
  EXPECT_EQ(folder.CountEntries(), 0);
}

TEST(Roadmarks, NamesTheLineOfAJsonSyntaxError) {
  const std::string text =
      "{\"type\": \"FeatureCollection\",\n\"features\": [\n{\"type\": "
      "\"Feature\",,\n]}\n";
  const std::string error = ErrorOf(text);
  EXPECT_THAT(error, HasSubstr("roadmarks.geojson:3: malformed JSON"));
  EXPECT_THAT(ErrorOf("\x89PNG\r\n garbage"),
              HasSubstr("roadmarks.geojson:1: malformed JSON"));
}

TEST(Roadmarks, RejectsWhatIsNotAFeatureCollection) {
  EXPECT_THAT(ErrorOf("{\"type\": \"Feature\"}"),
              HasSubstr("roadmarks.geojson:1: not a GeoJSON "
                        "FeatureCollection"));
  EXPECT_THAT(ErrorOf("{\"type\": \"FeatureCollection\"}"),
              HasSubstr("has no \"features\" array"));
  EXPECT_THAT(ErrorOf("{\"type\": \"FeatureCollection\", \"crs\": {\"type\": "
                      "\"name\", \"properties\": {\"name\": "
                      "\"urn:ogc:def:crs:EPSG::2154\"}}, \"features\": []}"),
              HasSubstr("coordinates must be WGS84"));
}

TEST(Roadmarks, RejectsAnUnclosedRingNamingTheFeatureAndItsLine) {
  std::vector<Geodetic> ring = Closed(Band(3.0));
  ring[4].lon_deg += 1e-7;
  const std::string text =
      Collection({BandFeature("C1", 1, 0.0), BandFeature("C1", 2, 1.0),
                  PolygonFeature(ring, kProperties)});
  EXPECT_THAT(ErrorOf(text),
              HasSubstr("roadmarks.geojson:4: feature 3 (crossing 'C3', band "
                        "2): ring is not closed"));
}

TEST(Roadmarks, FindsTheLineOfAFeatureInPrettyPrintedJson) {
  std::vector<Geodetic> ring = Closed(Band(3.0));
  ring.pop_back();
  const std::string text =
      "{\n  \"type\": \"FeatureCollection\",\n  \"name\": \"x, [y]\",\n"
      "  \"features\": [\n    " +
      BandFeature("C1", 1, 0.0) + ",\n\n    " +
      PolygonFeature(ring, kProperties) + "\n  ]\n}\n";
  EXPECT_THAT(ErrorOf(text),
              HasSubstr("roadmarks.geojson:7: feature 2 (crossing 'C3', band "
                        "2): ring has 4 positions; a band needs 5"));
}

TEST(Roadmarks, RejectsPositionsWithoutHeightOrOutOfRange) {
  std::string feature = PolygonFeature(Closed(Band(0.0)), kProperties);
  const size_t at = feature.find("[[[") + 2;
  const size_t end = feature.find(']', at);
  std::string two = feature;
  two.replace(at, end - at + 1, "[2.2958, 49.8941]");
  EXPECT_THAT(ErrorOf(Collection({two})),
              HasSubstr("roadmarks.geojson:2: feature 1 (crossing 'C3', band "
                        "2): position 0 has no height"));
  std::string swapped = feature;
  swapped.replace(at, end - at + 1, "[2.2958, 149.8941, 60]");
  EXPECT_THAT(ErrorOf(Collection({swapped})),
              HasSubstr("position 0 latitude 149.8941 is outside [-90, 90]"));
  std::string text = feature;
  text.replace(at, end - at + 1, "[2.2958, \"49.8941\", 60]");
  EXPECT_THAT(ErrorOf(Collection({text})),
              HasSubstr("position 0 holds a value that is not a number"));
  text = feature;
  text.replace(at, end - at + 1, "[2.2958, 1e999, 60]");
  EXPECT_THAT(ErrorOf(Collection({text})),
              HasSubstr("roadmarks.geojson:2: malformed JSON: number overflow "
                        "parsing '1e999'"));
}

TEST(Roadmarks, RejectsDegenerateBands) {
  std::vector<Geodetic> repeated = Band(0.0);
  repeated[2] = repeated[1];
  EXPECT_THAT(
      ErrorOf(Collection({PolygonFeature(Closed(repeated), kProperties)})),
      HasSubstr("roadmarks.geojson:2: feature 1 (crossing 'C3', band "
                "2): degenerate band: corners 1 and 2 are the same "
                "point"));
  // All four corners on one line: zero area.
  const LocalFrame frame(kOrigin);
  std::vector<Geodetic> flat;
  for (double e : {0.0, 1.0, 2.0, 3.0}) {
    flat.push_back(frame.GeodeticFromEnu(Eigen::Vector3d(e, 0.0, 0.0)));
  }
  const std::string flat_error =
      ErrorOf(Collection({PolygonFeature(Closed(flat), kProperties)}));
  EXPECT_THAT(flat_error, HasSubstr("roadmarks.geojson:2: feature 1"));
  EXPECT_THAT(flat_error, HasSubstr("degenerate band"));
  // A sliver of 2 mm x 3 m: 0.006 m^2.
  std::vector<Geodetic> sliver;
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.002, 0, 0),
        Eigen::Vector3d(0.002, 3, 0), Eigen::Vector3d(0, 3, 0)}) {
    sliver.push_back(frame.GeodeticFromEnu(p));
  }
  EXPECT_THAT(
      ErrorOf(Collection({PolygonFeature(Closed(sliver), kProperties)})),
      HasSubstr("degenerate band: area 0.006"));
  // Corners out of order: a bow tie.
  std::vector<Geodetic> bowtie = Band(0.0);
  std::swap(bowtie[2], bowtie[3]);
  EXPECT_THAT(
      ErrorOf(Collection({PolygonFeature(Closed(bowtie), kProperties)})),
      HasSubstr("degenerate band: the ring is self-intersecting"));
}

TEST(Roadmarks, RejectsMissingOrMistypedProperties) {
  const std::vector<Geodetic> ring = Closed(Band(0.0));
  EXPECT_THAT(ErrorOf(Collection(
                  {PolygonFeature(ring,
                                  "\"crossing_id\": \"C3\", \"band\": 2, "
                                  "\"sigma_z\": 0.1")})),
              HasSubstr("roadmarks.geojson:2: feature 1 (crossing 'C3', band "
                        "2): missing property 'sigma_xy'"));
  EXPECT_THAT(ErrorOf(Collection({PolygonFeature(
                  ring,
                  "\"crossing_id\": \"C3\", \"band\": 2, \"sigma_xy\": "
                  "-0.05, \"sigma_z\": 0.1")})),
              HasSubstr("property 'sigma_xy' = -0.05: must be a finite number "
                        ">= 0"));
  EXPECT_THAT(ErrorOf(Collection({PolygonFeature(
                  ring,
                  "\"crossing_id\": \"C3\", \"band\": 0, \"sigma_xy\": "
                  "0.05, \"sigma_z\": 0.1")})),
              HasSubstr("property 'band' = 0: must be an integer >= 1"));
  EXPECT_THAT(ErrorOf(Collection(
                  {PolygonFeature(ring,
                                  "\"crossing_id\": \"C3\", \"band\": 1.5, "
                                  "\"sigma_xy\": 0.05, \"sigma_z\": 0.1")})),
              HasSubstr("property 'band' = 1.5: must be an integer >= 1"));
  EXPECT_THAT(ErrorOf(Collection({PolygonFeature(
                  ring, "\"band\": 1, \"sigma_xy\": 0.05, \"sigma_z\": 0.1")})),
              HasSubstr("feature 1 (band 1): missing property 'crossing_id'"));
  EXPECT_THAT(ErrorOf(Collection(
                  {PolygonFeature(ring,
                                  "\"crossing_id\": \"a,b\", \"band\": 1, "
                                  "\"sigma_xy\": 0.05, \"sigma_z\": 0.1")})),
              HasSubstr("property 'crossing_id' \"a,b\" must be non-empty, "
                        "without ','"));
}

TEST(Roadmarks, RejectsDuplicateBandsNamingBothLines) {
  const std::string text =
      Collection({BandFeature("C1", 1, 0.0), BandFeature("C1", 2, 1.0),
                  BandFeature("C1", 1, 2.0)});
  EXPECT_THAT(ErrorOf(text),
              HasSubstr("roadmarks.geojson:4: feature 3 (crossing 'C1', band "
                        "1): duplicate band: crossing 'C1' band 1 already "
                        "appears on line 2"));
}

TEST(Roadmarks, RejectsPolygonsWithHolesAndMultiPartBands) {
  const std::string ring = PolygonFeature(Closed(Band(0.0)), kProperties);
  std::string holed = ring;
  const size_t end = holed.find("]]}");
  holed.insert(end + 1, ", [[0, 0, 0]]");
  EXPECT_THAT(ErrorOf(Collection({holed})),
              HasSubstr("polygon has 2 rings; a band has exactly one"));
  // GIS exports promote polygons to one-part MultiPolygons: accepted.
  std::string multi = ring;
  multi.replace(multi.find("\"Polygon\""), 9, "\"MultiPolygon\"");
  multi.replace(multi.find("[[["), 3, "[[[[");
  multi.replace(multi.find("]]]"), 3, "]]]]");
  EXPECT_EQ(ParseRoadmarks(Collection({multi}), "r").bands.size(), 1u);
  std::string two_parts = multi;
  two_parts.insert(two_parts.find("]]]]") + 3, ", [[[0, 0, 0]]]");
  EXPECT_THAT(ErrorOf(Collection({two_parts})),
              HasSubstr("this MultiPolygon has 2 parts"));
}

TEST(Roadmarks, ReadOfAMissingFileNamesIt) {
  TemporaryFolder folder;
  try {
    ReadRoadmarks(folder.Path("r.geojson"), "roadmarks.geojson");
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("roadmarks.geojson: cannot open"));
  }
}

// Damaged files are refused naming roadmarks.geojson, the line and the
// problem, or read to at most the two bands and the line of the file, each
// band with its crossing.
TEST(Roadmarks, TruncatedOrCorruptedFilesAreRefusedByLineOrReadSoundly) {
  const std::string text =
      "\xEF\xBB\xBF" +
      Collection({BandFeature("C1", 1, 0.0), BandFeature("C1", 2, 1.0),
                  "{\"type\": \"Feature\", \"geometry\": {\"type\": "
                  "\"LineString\", \"coordinates\": [[2.3, 49.9, 1], [2.3, "
                  "49.91, 1]]}, \"properties\": {\"type\": \"lane\", \"id\": "
                  "3}}"});
  EXPECT_EQ(ParseRoadmarks(text, "r").bands.size(), 2u);  // BOM accepted
  const DamageCounts counts = ParseDamagedCopies(
      text, "roadmarks.geojson", {'\0', '[', '{', '"', '1', ',', '\xff'},
      [](const std::string& damaged) {
        const RoadmarkDatabase db =
            ParseRoadmarks(damaged, "roadmarks.geojson");
        EXPECT_LE(db.bands.size(), 2u);
        EXPECT_LE(db.lines.size(), 1u);
        for (const RoadmarkBand& band : db.bands) {
          EXPECT_FALSE(band.crossing_id.empty());
        }
      });
  EXPECT_GT(counts.refused, 0);
  EXPECT_GT(counts.parsed, 0);
  // Cut inside the second band: malformed JSON, on the line it ends.
  EXPECT_THAT(ErrorOf(text.substr(0, text.find("C1", text.find("C1") + 2))),
              HasSubstr("malformed JSON"));
}

TEST(Roadmarks, NamesTheLineOfAFeatureAfterAByteOrderMark) {
  std::vector<Geodetic> ring = Closed(Band(3.0));
  ring[4].lat_deg += 1e-6;
  const std::string text =
      "\xEF\xBB\xBF" + Collection({BandFeature("C1", 1, 0.0),
                                   PolygonFeature(ring, kProperties)});
  EXPECT_THAT(ErrorOf(text), HasSubstr("roadmarks.geojson:3: feature 2"));
}

}  // namespace
}  // namespace zebrageo
