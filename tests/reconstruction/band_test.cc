#include "reconstruction/band.h"

#include <gtest/gtest.h>

namespace zebrageo {
namespace {

TEST(BandOptions, CheckNamesTheBadField) {
  BandOptions options;
  options.hough_score_fraction = 1.5;
  EXPECT_EQ(options.Check(), "hough_score_fraction = 1.5: must be in (0, 1]");
  options = BandOptions();
  EXPECT_EQ(options.Check(), "");
  options.end_angle_min_share = 0.0;
  EXPECT_EQ(options.Check(), "end_angle_min_share = 0: must be in (0, 1]");
  options = BandOptions();
  options.max_end_disagreement_rad_per_m = 0.0;
  EXPECT_EQ(options.Check(), "max_end_disagreement_rad_per_m = 0: must be > 0");
}

}  // namespace
}  // namespace zebrageo
