#include "survey/roadmark_layer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "survey/input_error.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

// A band 3 m x 0.5 m at (lat, lon), counter-clockwise seen from above.
RoadmarkBand Band(const std::string& crossing, int number, double lat,
                  double lon) {
  RoadmarkBand band;
  band.crossing_id = crossing;
  band.band = number;
  const double dlat = 0.5 / 111320.0;
  const double dlon = 3.0 / (111320.0 * std::cos(lat * M_PI / 180.0));
  band.corners = {Geodetic{lat, lon, 60.0}, Geodetic{lat, lon + dlon, 60.1},
                  Geodetic{lat + dlat, lon + dlon, 60.2},
                  Geodetic{lat + dlat, lon, 60.3}};
  band.sigma_xy_m = 0.04;
  band.sigma_z_m = 0.06;
  return band;
}

// GeoJSON text of bands with the given property names, 2D or 3D, corners
// in file order or reversed.
std::string GeoJson(const std::vector<RoadmarkBand>& bands,
                    const std::string& crossing_key,
                    const std::string& band_key, bool three_d,
                    bool reversed = false) {
  std::string text = "{\"type\":\"FeatureCollection\",\"features\":[";
  for (size_t i = 0; i < bands.size(); ++i) {
    std::string ring;
    for (int k = 0; k <= 4; ++k) {
      const int index = reversed ? (4 - k) % 4 : k % 4;
      const Geodetic& g = bands[i].corners[index];
      char position[128];
      if (three_d) {
        snprintf(position, sizeof(position), "[%.12f,%.12f,%.6f]", g.lon_deg,
                 g.lat_deg, g.h_m);
      } else {
        snprintf(position, sizeof(position), "[%.12f,%.12f]", g.lon_deg,
                 g.lat_deg);
      }
      ring += (k > 0 ? "," : "") + std::string(position);
    }
    text += (i > 0 ? "," : "") +
            std::string(
                "{\"type\":\"Feature\",\"geometry\":{\"type\":"
                "\"Polygon\",\"coordinates\":[[") +
            ring + "]]},\"properties\":{\"" + crossing_key + "\":\"" +
            bands[i].crossing_id + "\",\"" + band_key +
            "\":" + std::to_string(bands[i].band) +
            ",\"sigma_xy\":0.04,\"sigma_z\":0.06}}";
  }
  return text + "]}";
}

void ExpectSameCorners(const RoadmarkBand& a, const RoadmarkBand& b) {
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(a.corners[k].lat_deg, b.corners[k].lat_deg, 1e-10) << k;
    EXPECT_NEAR(a.corners[k].lon_deg, b.corners[k].lon_deg, 1e-10) << k;
    EXPECT_NEAR(a.corners[k].h_m, b.corners[k].h_m, 1e-6) << k;
  }
}

TEST(RoadmarkLayer, ReadsWhatTheContractReaderReads) {
  TemporaryFolder folder;
  const std::vector<RoadmarkBand> bands = {Band("a", 1, 49.89, 2.29),
                                           Band("a", 2, 49.89002, 2.29)};
  const std::string path = folder.Write(
      "marks.geojson", GeoJson(bands, "crossing_id", "band", true));
  const RoadmarkDatabase contract = ReadRoadmarks(path, "marks.geojson");
  RoadmarkLayerOptions options;
  options.source = path;
  const RoadmarkDatabase layer = ReadRoadmarkLayer(options, "marks.geojson");
  ASSERT_EQ(layer.bands.size(), contract.bands.size());
  for (size_t i = 0; i < layer.bands.size(); ++i) {
    EXPECT_EQ(layer.bands[i].crossing_id, contract.bands[i].crossing_id);
    EXPECT_EQ(layer.bands[i].band, contract.bands[i].band);
    EXPECT_DOUBLE_EQ(layer.bands[i].sigma_xy_m, contract.bands[i].sigma_xy_m);
    EXPECT_TRUE(layer.bands[i].height_known);
    ExpectSameCorners(layer.bands[i], contract.bands[i]);
  }
}

TEST(RoadmarkLayer, GuessesCommonAttributeNamesAndTakesAMap) {
  TemporaryFolder folder;
  const std::vector<RoadmarkBand> bands = {Band("z7", 3, 49.89, 2.29)};
  RoadmarkLayerOptions options;
  options.source = folder.Write("guess.geojson",
                                GeoJson(bands, "Crossing_I", "BAND_NO", true));
  EXPECT_EQ(ReadRoadmarkLayer(options, "guess.geojson").bands[0].band, 3);
  options.source = folder.Write("odd.geojson",
                                GeoJson(bands, "zebra_key", "stripe_k", true));
  try {
    ReadRoadmarkLayer(options, "odd.geojson");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("roadmarks_fields"));
    EXPECT_THAT(error.what(), HasSubstr("zebra_key"));
  }
  options.fields.crossing_id = "zebra_key";
  options.fields.band = "STRIPE_K";
  const RoadmarkDatabase db = ReadRoadmarkLayer(options, "odd.geojson");
  EXPECT_EQ(db.bands[0].crossing_id, "z7");
  options.fields.band = "no_such";
  EXPECT_THROW(ReadRoadmarkLayer(options, "odd.geojson"), InputError);
}

TEST(RoadmarkLayer, ClockwiseRingsComeBackCounterClockwiseFromTheSameCorner) {
  TemporaryFolder folder;
  const std::vector<RoadmarkBand> bands = {Band("a", 1, 49.89, 2.29)};
  RoadmarkLayerOptions options;
  options.source = folder.Write(
      "cw.geojson", GeoJson(bands, "crossing_id", "band", true, true));
  ExpectSameCorners(ReadRoadmarkLayer(options, "cw.geojson").bands[0],
                    bands[0]);
}

TEST(RoadmarkLayer, TwoDimensionalBandsGetTheGuessAndAWideSigma) {
  TemporaryFolder folder;
  const std::vector<RoadmarkBand> bands = {Band("a", 1, 49.89, 2.29)};
  RoadmarkLayerOptions options;
  options.source = folder.Write("flat.geojson",
                                GeoJson(bands, "crossing_id", "band", false));
  EXPECT_THROW(ReadRoadmarkLayer(options, "flat.geojson"), InputError);
  options.height_guess = [](double, double) { return 42.0; };
  const RoadmarkBand band = ReadRoadmarkLayer(options, "flat.geojson").bands[0];
  EXPECT_FALSE(band.height_known);
  EXPECT_DOUBLE_EQ(band.corners[2].h_m, 42.0);
  EXPECT_DOUBLE_EQ(band.sigma_z_m, options.sigma_z_without_height_m);
}

TEST(RoadmarkLayer, ReadsOnlyTheAreaAndRefusesDuplicates) {
  TemporaryFolder folder;
  // The same band twice: 30 km apart, and at the same place.
  const std::vector<RoadmarkBand> far = {Band("a", 1, 49.89, 2.29),
                                         Band("a", 1, 49.89, 2.69)};
  RoadmarkLayerOptions options;
  options.source =
      folder.Write("far.geojson", GeoJson(far, "crossing_id", "band", true));
  try {
    ReadRoadmarkLayer(options, "far.geojson");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("appears twice"));
    EXPECT_THAT(error.what(), HasSubstr("feature 1"));
  }
  options.area = BoxAround({Geodetic{49.8901, 2.2901, 60.0}}, 200.0);
  const RoadmarkDatabase db = ReadRoadmarkLayer(options, "far.geojson");
  ASSERT_EQ(db.bands.size(), 1u);
  EXPECT_NEAR(db.bands[0].corners[0].lon_deg, 2.29, 1e-9);
}

TEST(RoadmarkLayer, NamesWhatGdalCannotOpenWithoutAPassword) {
  RoadmarkLayerOptions options;
  options.source = "PG:host=/nonexistent dbname=x user=u password=secret";
  try {
    ReadRoadmarkLayer(options, options.source);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("password=***"));
    EXPECT_THAT(error.what(), ::testing::Not(HasSubstr("secret")));
  }
  EXPECT_EQ(RedactedSource("PG:dbname=a password='x y' host=h"),
            "PG:dbname=a password=*** host=h");
}

TEST(RoadmarkLayer, OptionsAreChecked) {
  RoadmarkLayerOptions options;
  EXPECT_THAT(options.Check(), HasSubstr("source"));
  options.source = "x.gpkg";
  options.sigma_z_without_height_m = 0.0;
  EXPECT_THAT(options.Check(), HasSubstr("sigma_z_without_height_m"));
}

}  // namespace
}  // namespace zebrageo
