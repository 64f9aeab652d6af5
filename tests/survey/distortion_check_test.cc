// The lens-distortion check of rig.yaml (survey/distortion_check.h) on
// amiens-short's left camera: its own distortion passes; k1 = 1e6 (issue
// 48's case) squeezes the image and k1 = -1 folds it.
#include "survey/distortion_check.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

Camera AmiensLeft(const std::array<double, 5>& distortion) {
  return Camera("left", 1024, 768, 836.057901, 834.088449, 506.053674,
                380.151138, distortion);
}

TEST(RadialDistortionProblem, ARealLensPasses) {
  EXPECT_EQ(RadialDistortionProblem(AmiensLeft(
                {-0.14662817, 0.042164678, -5.3e-05, 0.00072, 0.0037055453})),
            "");
  EXPECT_EQ(RadialDistortionProblem(AmiensLeft({0, 0, 0, 0, 0})), "");
}

TEST(RadialDistortionProblem, AHugeK1SqueezesTheImage) {
  const std::string problem =
      RadialDistortionProblem(AmiensLeft({1e6, 0.04, 0, 0, 0.0037}));
  EXPECT_THAT(problem, HasSubstr("k1 = 1e+06"));
  EXPECT_THAT(problem, HasSubstr("scales the radius of the image's corner"));
  // The corner is 37.7 deg off axis with this focal length.
  EXPECT_THAT(problem, HasSubstr("not the 37.7 deg"));
}

TEST(RadialDistortionProblem, AStrongBarrelFoldsTheImage) {
  // r (1 - r^2) peaks at r = 0.577 (radius 0.385), short of the corner's
  // 0.77: the map folds inside the image.
  const std::string problem =
      RadialDistortionProblem(AmiensLeft({-1.0, 0, 0, 0, 0}));
  EXPECT_THAT(problem, HasSubstr("folds the image"));
}

}  // namespace
}  // namespace zebrageo
