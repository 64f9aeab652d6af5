#include "reconstruction/crossing_edges.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace zebrageo {
namespace {

constexpr double kGsd = 0.03;  // m per rectified pixel

// A rectified road image (rows grow towards the vehicle) of five bands
// 0.5 m wide, 1 m apart, their far ends on the line
// y = top_row + skew * (x - 100), running down to the image's bottom;
// paint 200, asphalt 90 (a shadow of 0.4 over x < shadow_x), blurred, with
// noise. The rows from `valid_rows` down are not valid (out of view).
struct Scene {
  cv::Mat image, valid;
};
Scene PartialBands(double top_row, double skew, int valid_rows,
                   double shadow_x = -1.0) {
  const int rows = 160, cols = 260;
  Scene scene;
  scene.image.create(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      // 4 x 4 supersampling: anti-aliased edges.
      double sum = 0.0;
      for (int k = 0; k < 16; ++k) {
        const double px = x + (k % 4 - 1.5) / 4.0;
        const double py = y + (k / 4 - 1.5) / 4.0;
        const double band = std::fmod((px - 40.0) * kGsd + 100.0, 1.0);
        const bool paint = px >= 40.0 && px < 40.0 + 5.0 / kGsd && band < 0.5 &&
                           py >= top_row + skew * (px - 100.0);
        double g = paint ? 200.0 : 90.0;
        if (px < shadow_x) g *= 0.4;
        sum += g / 16.0;
      }
      scene.image.at<float>(y, x) = static_cast<float>(sum);
    }
  }
  cv::GaussianBlur(scene.image, scene.image, cv::Size(0, 0), 1.0);
  cv::Mat noise(scene.image.size(), CV_32F);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  scene.image += noise;
  scene.valid = cv::Mat(rows, cols, CV_8U, cv::Scalar(255));
  scene.valid.rowRange(valid_rows, rows).setTo(0);
  return scene;
}

std::vector<BandEnd> Ends(const Scene& scene,
                          const CrossingEdgeOptions& options = {}) {
  const cv::Mat paint =
      BandPaintPixels(scene.image, scene.valid, kGsd, options);
  return FindBandEnds(scene.image, scene.valid, paint, kGsd, options);
}

TEST(CrossingEdges, TheSeenEndsOfBandsCutByTheBorderMakeOneEdge) {
  for (const double skew : {0.0, 0.3}) {
    SCOPED_TRACE(::testing::Message() << "skew " << skew);
    const Scene scene = PartialBands(30.0, skew, 120);
    const std::vector<BandEnd> ends = Ends(scene);
    // The far ends only: the near ones are out of view.
    ASSERT_EQ(ends.size(), 5u);
    for (const BandEnd& end : ends) {
      EXPECT_EQ(end.outward, -1);
      // On the painted end, at the band's centre.
      const double truth = 30.0 + skew * (end.mid_px.x() - 100.0);
      EXPECT_NEAR(end.mid_px.y(), truth, 0.5);
      const double band = std::fmod((end.mid_px.x() - 40.0) * kGsd, 1.0);
      EXPECT_NEAR(band, 0.25, 0.02);
      EXPECT_NEAR(end.end_slope, skew, 0.05);
    }
    const std::vector<std::vector<int>> edges =
        GroupCrossingEdges(ends, kGsd, CrossingEdgeOptions());
    ASSERT_EQ(edges.size(), 1u);
    EXPECT_EQ(edges[0].size(), 5u);
  }
}

TEST(CrossingEdges, NoEndWhereTheGroundBeyondIsOutOfView) {
  // The far ends 4 rows under the valid region's top edge: the ground
  // beyond them is not seen, so they may be the border's cut.
  Scene scene = PartialBands(30.0, 0.0, 120);
  scene.valid.rowRange(0, 26).setTo(0);
  EXPECT_TRUE(Ends(scene).empty());
}

TEST(CrossingEdges, EndsInAShadowCountAndOnlyOneLineGroups) {
  // A shadow over the left band (its paint darker than the sunlit
  // asphalt): the row mean over about one band period still finds it.
  const std::vector<BandEnd> shadowed = Ends(PartialBands(30.0, 0.0, 120, 65));
  EXPECT_EQ(shadowed.size(), 5u);
  // Ends off the line (one moved by 0.3 m) are left out of the edge; two
  // alone make none.
  std::vector<BandEnd> ends = Ends(PartialBands(30.0, 0.0, 120));
  ASSERT_EQ(ends.size(), 5u);
  ends[2].mid_px.y() += 10.0;
  std::vector<std::vector<int>> edges =
      GroupCrossingEdges(ends, kGsd, CrossingEdgeOptions());
  ASSERT_EQ(edges.size(), 1u);
  EXPECT_EQ(edges[0].size(), 4u);
  for (int i : edges[0]) EXPECT_NE(i, 2);
  ends.resize(2);
  EXPECT_TRUE(GroupCrossingEdges(ends, kGsd, CrossingEdgeOptions()).empty());
}

TEST(CrossingEdgeOptions, Check) {
  EXPECT_EQ(CrossingEdgeOptions().Check(), "");
  CrossingEdgeOptions o;
  o.max_band_width_m = o.min_band_width_m;
  EXPECT_NE(o.Check().find("band widths"), std::string::npos);
  o = CrossingEdgeOptions();
  o.min_bands = 1;
  EXPECT_NE(o.Check().find("min_bands"), std::string::npos);
}

}  // namespace
}  // namespace zebrageo
