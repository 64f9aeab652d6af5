// SimulationOptions: presets, Check() messages, SetOption over every field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "simulator/simulator.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

TEST(SimulationOptions, DefaultsAndEveryPresetAreValid) {
  EXPECT_EQ(SimulationOptions().Check(), "");
  for (const std::string& name : PresetNames()) {
    SimulationOptions options;
    options.seed = 42;
    EXPECT_EQ(ApplyPreset(name, &options), "") << name;
    EXPECT_EQ(options.Check(), "") << name;
    EXPECT_EQ(options.preset, name);
    EXPECT_EQ(options.seed, 42u) << "ApplyPreset must keep the seed";
  }
}

TEST(SimulationOptions, PresetsHaveTheirCharacter) {
  SimulationOptions demo, large, ambiguity, outage;
  ASSERT_EQ(ApplyPreset("demo", &demo), "");
  ASSERT_EQ(ApplyPreset("large", &large), "");
  ASSERT_EQ(ApplyPreset("ambiguity", &ambiguity), "");
  ASSERT_EQ(ApplyPreset("outage", &outage), "");
  EXPECT_LE(demo.road_length_m, 200.0);
  EXPECT_EQ(demo.num_crossings, 3);
  EXPECT_GE(large.road_length_m, 10000.0);
  EXPECT_FALSE(large.render_images);
  EXPECT_NEAR(ambiguity.drift_cross_track_m,
              ambiguity.band_width_m + ambiguity.band_gap_m, 1e-9);
  EXPECT_GT(outage.outage_duration_s, 30.0);
  EXPECT_GE(outage.outage_drift_m, 3.0);
}

TEST(SimulationOptions, UnknownPresetNamesTheKnownOnes) {
  SimulationOptions options;
  const std::string error = ApplyPreset("rural", &options);
  EXPECT_THAT(error, HasSubstr("unknown preset \"rural\""));
  EXPECT_THAT(error, HasSubstr("demo"));
  EXPECT_THAT(error, HasSubstr("large"));
}

TEST(SimulationOptions, CheckNamesTheFieldTheValueAndTheRule) {
  SimulationOptions options;
  options.road_width_m = 3.0;
  EXPECT_EQ(options.Check(), "road_width_m = 3: must be in [6.5, 26]");
  options = SimulationOptions();
  options.band_width_m = -0.5;
  options.threads = -2;
  const std::string both = options.Check();
  EXPECT_THAT(both, HasSubstr("band_width_m = -0.5: must be in [0.2, 1]"));
  EXPECT_THAT(both, HasSubstr("threads = -2: must be in [0, 1024]"));
  EXPECT_THAT(both, HasSubstr("; "));
}

TEST(SimulationOptions, CheckRejectsTooManyCrossingsForTheRoad) {
  SimulationOptions options;
  options.road_length_m = 100.0;
  options.num_crossings = 5;
  EXPECT_THAT(options.Check(), HasSubstr("road_length_m = 100: must be >= "));
}

TEST(SimulationOptions, CheckRejectsMoreFaultsThanCrossings) {
  SimulationOptions options;
  options.num_crossings = 2;
  options.num_missing_crossings = 2;
  options.num_repainted_crossings = 1;
  EXPECT_THAT(options.Check(), HasSubstr("must be <= num_crossings = 2"));
}

TEST(SimulationOptions, CheckRejectsADistortionThatFoldsInsideTheImage) {
  SimulationOptions options;
  options.k1 = -0.6;
  options.k2 = 0.0;
  options.k3 = 0.0;
  EXPECT_THAT(options.Check(), HasSubstr("distortion folds inside the image"));
}

TEST(SetOption, ReachesEveryFieldAndRoundTripsItsText) {
  SimulationOptions options;
  ASSERT_EQ(ApplyPreset("urban", &options), "");
  const auto values = OptionValues(options);
  EXPECT_EQ(values.size(), OptionNames().size());
  SimulationOptions copy;
  for (const std::string& name : OptionNames()) {
    ASSERT_TRUE(values.count(name)) << name;
    EXPECT_EQ(SetOption(name + "=" + values.at(name), &copy), "") << name;
  }
  EXPECT_EQ(OptionValues(copy), values);
}

TEST(SetOption, SetsTypedValues) {
  SimulationOptions options;
  EXPECT_EQ(SetOption("road_length_m=300", &options), "");
  EXPECT_EQ(options.road_length_m, 300.0);
  EXPECT_EQ(SetOption("num_crossings=9", &options), "");
  EXPECT_EQ(options.num_crossings, 9);
  EXPECT_EQ(SetOption("render_images=false", &options), "");
  EXPECT_FALSE(options.render_images);
  EXPECT_EQ(SetOption("pixel_depth=16", &options), "");
  EXPECT_EQ(options.pixel_depth, PixelDepth::kUint16);
  EXPECT_EQ(SetOption("seed=18446744073709551615", &options), "");
  EXPECT_EQ(options.seed, 18446744073709551615ull);
  EXPECT_EQ(SetOption("preset=my-street", &options), "");
  EXPECT_EQ(options.preset, "my-street");
}

TEST(SetOption, RejectsUnknownKeysAndBadValues) {
  SimulationOptions options;
  EXPECT_THAT(SetOption("road_lenght_m=300", &options),
              HasSubstr("unknown option \"road_lenght_m\""));
  EXPECT_THAT(SetOption("road_length_m", &options),
              HasSubstr("expected key=value"));
  EXPECT_EQ(SetOption("road_length_m=abc", &options),
            "road_length_m: \"abc\" is not a finite number");
  EXPECT_EQ(SetOption("road_length_m=nan", &options),
            "road_length_m: \"nan\" is not a finite number");
  EXPECT_EQ(SetOption("num_crossings=2.5", &options),
            "num_crossings: \"2.5\" is not an integer");
  EXPECT_EQ(SetOption("facades=maybe", &options),
            "facades: \"maybe\" is not a boolean (true or false)");
  EXPECT_EQ(SetOption("pixel_depth=12", &options),
            "pixel_depth: \"12\" is not a pixel depth (8 or 16)");
  EXPECT_EQ(SetOption("seed=-1", &options),
            "seed: \"-1\" is not a non-negative integer");
  EXPECT_EQ(options.road_length_m, SimulationOptions().road_length_m);
}

}  // namespace
}  // namespace zebrageo
