#include "reconstruction/edge_matching.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace zebrageo {
namespace {

constexpr double kBarWidth = 9.0;
const double kBars[] = {30.0, 62.0, 95.0, 126.0, 160.0};

// Brightness of the scene at abscissa X: bright bars on a dark road,
// blurred by a Gaussian of 0.8 px (exact integral over the pixel).
double Scene(double x) {
  double value = 60.0;
  for (double bar : kBars) {
    const double s = std::sqrt(2.0) * 0.8;
    value += 0.5 * 140.0 *
             (std::erf((x - bar) / s) - std::erf((x - bar - kBarWidth) / s));
  }
  return value;
}

// Rectified pair of the bar scene: a point at x in the left image is at
// x - disparity in the right image. In the right image, rows
// [occluded_from, occluded_to) of the bar at 95 are hidden by a dark
// object in front (with edges of its own).
void RenderPair(double disparity, int occluded_from, int occluded_to,
                cv::Mat* left, cv::Mat* right) {
  const int width = 200, height = 60;
  *left = cv::Mat(height, width, CV_32F);
  *right = cv::Mat(height, width, CV_32F);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double l = 0.0, r = 0.0;
      for (int k = 0; k < 8; ++k) {
        const double dx = (k + 0.5) / 8.0 - 0.5;
        l += Scene(x + dx);
        r += Scene(x + dx + disparity);
      }
      left->at<float>(y, x) = static_cast<float>(l / 8.0) + noise(rng);
      float value = static_cast<float>(r / 8.0) + noise(rng);
      const double xs = x + disparity;  // scene abscissa
      if (y >= occluded_from && y < occluded_to && xs > 90.0 && xs < 110.0) {
        value = 25.0f + noise(rng);
      }
      right->at<float>(y, x) = value;
    }
  }
  cv::GaussianBlur(*right, *right, cv::Size(3, 3), 0.5);
  cv::GaussianBlur(*left, *left, cv::Size(3, 3), 0.5);
}

TEST(EdgeMatching,
     MatchesAtTheTrueSubpixelDisparityAndLeavesTheOccludedEdgeAlone) {
  const double disparity = 3.37;
  cv::Mat left, right;
  RenderPair(disparity, 20, 40, &left, &right);
  const EdgeMap left_edges =
      DetectSubpixelEdges(left, cv::Mat(), EdgeOptions());
  const EdgeMap right_edges =
      DetectSubpixelEdges(right, cv::Mat(), EdgeOptions());
  const DisparityRange range = [](double, double, double* lo, double* hi) {
    *lo = -12.0;
    *hi = 12.0;
    return true;
  };
  const std::vector<EdgeMatch> matches = MatchEdges(
      left, right, left_edges, right_edges, range, MatchingOptions());
  int in_occlusion = 0, elsewhere = 0;
  for (const EdgeMatch& m : matches) {
    EXPECT_NEAR(m.x_left - m.x_right, disparity, 0.05)
        << "at " << m.x_left << ", " << m.y;
    const bool occluded_bar = m.x_left > 93.0 && m.x_left < 106.0;
    if (occluded_bar && m.y >= 20 && m.y < 40) ++in_occlusion;
    if (!occluded_bar && m.y >= 8 && m.y < 52) ++elsewhere;
  }
  // The occluded bar's two edges are not matched where they are hidden
  // (the rows next to the occluder are disturbed by its blur).
  EXPECT_LE(in_occlusion, 2);
  // The other bars (8 edges) are matched on nearly every row, occluded rows
  // included: the ordering constraint does not break around the occlusion.
  EXPECT_GE(elsewhere, 8 * 44 * 9 / 10);
}

TEST(EdgeMatching, NothingIsMatchedOutsideTheSearchVolume) {
  cv::Mat left, right;
  RenderPair(3.0, 0, 0, &left, &right);
  const EdgeMap le = DetectSubpixelEdges(left, cv::Mat(), EdgeOptions());
  const EdgeMap re = DetectSubpixelEdges(right, cv::Mat(), EdgeOptions());
  const DisparityRange range = [](double, double, double* lo, double* hi) {
    *lo = 5.0;  // the true disparity, 3, is outside
    *hi = 12.0;
    return true;
  };
  EXPECT_TRUE(
      MatchEdges(left, right, le, re, range, MatchingOptions()).empty());
}

TEST(EdgeMatching, ChainCrossingInterpolatesBetweenChainPoints) {
  EdgeMap edges;
  edges.points.resize(3);
  const float xs[3] = {10.0f, 10.4f, 10.8f};
  for (int i = 0; i < 3; ++i) {
    edges.points[i].x = xs[i];
    edges.points[i].y = static_cast<float>(i);
    edges.points[i].gx = 1.0f;
    edges.points[i].norm = 1.0f;
    edges.points[i].chain = 0;
    edges.points[i].index_in_chain = i;
  }
  edges.chains = {{0, 1, 2}};
  EXPECT_NEAR(ChainCrossing(edges, 1, 1.5), 10.6, 1e-6);
  EXPECT_NEAR(ChainCrossing(edges, 1, 0.25), 10.1, 1e-6);
  EXPECT_NEAR(ChainCrossing(edges, 1, 1.0), 10.4, 1e-6);
}

TEST(EdgeMatching, CheckNamesTheBadField) {
  MatchingOptions options;
  options.window_radius_px = 0;
  EXPECT_EQ(options.Check(), "window_radius_px = 0: must be in [1, 15]");
}

}  // namespace
}  // namespace zebrageo
