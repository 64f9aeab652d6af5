// The tie-point matcher's option checks (tiepoints/tie_points.h): bad
// options are reported, not aborted on.
#include "tiepoints/tie_points.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace zebrageo {
namespace {

TEST(TiePointOptions, DefaultsAreValid) {
  EXPECT_EQ(TiePointOptions().Check(), "");
}

TEST(TiePointOptions, CheckNamesTheField) {
  TiePointOptions options;
  options.min_triangulation_angle_rad = -0.1;
  EXPECT_EQ(options.Check(),
            "min_triangulation_angle_rad = -0.1: must be >= 0");
}

TEST(BuildTieTracks, BadOptionsThrowInsteadOfAborting) {
  TiePointOptions options;
  options.exposure_window = 0;
  TiePointSummary summary;
  try {
    BuildTieTracks(options, "", Rig(), Trajectory(), ExposureTable(), &summary);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()),
              "TiePointOptions: exposure_window = 0: must be >= 1");
  }
}

TEST(BuildTieTracks, NoExposuresGiveNoTracksWithoutASummary) {
  EXPECT_TRUE(BuildTieTracks(TiePointOptions(), "", Rig(), Trajectory(),
                             ExposureTable(), nullptr)
                  .empty());
}

}  // namespace
}  // namespace zebrageo
