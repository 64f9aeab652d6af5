#include "reconstruction/subpixel_edges.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace zebrageo {
namespace {

// A vertical step edge at x = edge_x (dark 50 left, bright 200 right), as
// a camera with a Gaussian blur of `blur_px` sees it: each pixel is the
// exact integral of the blurred step over the pixel's area.
cv::Mat BlurredStep(double edge_x, double blur_px, int width, int height,
                    double angle_rad = 0.0) {
  cv::Mat image(height, width, CV_32F);
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      // Supersampled pixel area, analytic blur across the edge.
      double sum = 0.0;
      for (int k = 0; k < 16; ++k) {
        const double px = x - 0.5 + (k % 4 + 0.5) / 4.0;
        const double py = y - 0.5 + (k / 4 + 0.5) / 4.0;
        // Signed distance to the edge line through (edge_x, height / 2).
        const double d = (px - edge_x) * c + (py - height / 2.0) * s;
        sum += 0.5 * (1.0 + std::erf(d / (std::sqrt(2.0) * blur_px)));
      }
      image.at<float>(y, x) = static_cast<float>(50.0 + 150.0 * sum / 16.0);
    }
  }
  return image;
}

TEST(SubpixelEdges, BlurredStepEdgeIsLocatedWithinFiveHundredthsOfAPixel) {
  EdgeOptions options;
  for (double edge_x : {20.0, 20.1, 20.25, 20.4, 20.5, 20.63, 20.8, 20.95}) {
    for (double blur : {0.6, 1.0, 2.0}) {
      const cv::Mat image = BlurredStep(edge_x, blur, 41, 21);
      const EdgeMap edges = DetectSubpixelEdges(image, cv::Mat(), options);
      int count = 0;
      for (const EdgePoint& e : edges.points) {
        if (e.py < 5 || e.py > 15) continue;
        EXPECT_NEAR(e.x, edge_x, 0.05) << "blur " << blur;
        EXPECT_GT(e.gx, 0.0f);
        ++count;
      }
      EXPECT_EQ(count, 11) << "edge_x " << edge_x << " blur " << blur;
    }
  }
}

TEST(SubpixelEdges, TiltedEdgeIsOneChainOnTheTrueLine) {
  const double angle = 0.3;  // radians from vertical
  const cv::Mat image = BlurredStep(30.3, 1.0, 61, 61, angle);
  const EdgeMap edges = DetectSubpixelEdges(image, cv::Mat(), EdgeOptions());
  ASSERT_EQ(edges.chains.size(), 1u);
  EXPECT_GT(edges.chains[0].size(), 45u);
  for (const EdgePoint& e : edges.points) {
    if (e.py < 6 || e.py > 54 || e.px < 6 || e.px > 54) continue;
    const double d =
        (e.x - 30.3) * std::cos(angle) + (e.y - 30.5) * std::sin(angle);
    EXPECT_NEAR(d, 0.0, 0.06);
  }
  // Chains are ordered along the edge.
  const std::vector<int>& chain = edges.chains[0];
  for (size_t k = 1; k < chain.size(); ++k) {
    const EdgePoint& a = edges.points[chain[k - 1]];
    const EdgePoint& b = edges.points[chain[k]];
    EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 2.0);
    EXPECT_EQ(b.index_in_chain, static_cast<int>(k));
  }
}

TEST(SubpixelEdges, FlatNoisyImageHasNoChains) {
  cv::Mat image(60, 60, CV_32F);
  cv::RNG rng(77);  // not cv::theRNG(): independent of the tests before
  rng.fill(image, cv::RNG::NORMAL, 100.0, 1.5);
  const EdgeMap edges = DetectSubpixelEdges(image, cv::Mat(), EdgeOptions());
  EXPECT_TRUE(edges.chains.empty());
}

TEST(SubpixelEdges, InvalidMaskSuppressesItsBorder) {
  const cv::Mat image = BlurredStep(20.3, 1.0, 41, 21);
  cv::Mat mask(21, 41, CV_8U, cv::Scalar(255));
  mask.colRange(0, 22).setTo(0);  // the edge lies next to invalid pixels
  const EdgeMap edges = DetectSubpixelEdges(image, mask, EdgeOptions());
  EXPECT_TRUE(edges.points.empty());
}

TEST(SubpixelEdges, CheckNamesTheBadField) {
  EdgeOptions options;
  options.high_threshold = 1.0;
  EXPECT_EQ(options.Check(),
            "high_threshold = 1: must be >= low_threshold (3)");
  EXPECT_EQ(EdgeOptions().Check(), "");
}

}  // namespace
}  // namespace zebrageo
