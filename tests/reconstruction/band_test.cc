#include "reconstruction/band.h"

#include <gtest/gtest.h>

namespace zebrageo {
namespace {

TEST(BandOptions, CheckNamesTheBadField) {
  BandOptions options;
  options.hough_score_fraction = 1.5;
  EXPECT_EQ(options.Check(), "hough_score_fraction = 1.5: must be in (0, 1]");
}

}  // namespace
}  // namespace zebrageo
