#include "reconstruction/road_lines.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <random>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

// A CV_32F image of `rows` x `cols` gray 100 with Gaussian noise.
cv::Mat NoisyBackground(int rows, int cols, double sigma, unsigned seed) {
  cv::Mat image(rows, cols, CV_32F);
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(sigma));
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) image.at<float>(y, x) = 100.0f + noise(rng);
  }
  return image;
}

int CountSet(const cv::Mat& binary, int y, int x0, int x1) {
  int n = 0;
  for (int x = x0; x < x1; ++x) n += binary.at<uint8_t>(y, x) != 0;
  return n;
}

TEST(BrightLinePixels, FindsAPaintedLineAndIgnoresASpike) {
  cv::Mat image = NoisyBackground(20, 120, 3.0, 1);
  image(cv::Rect(40, 0, 5, 20)).setTo(200.0f);  // a 5-pixel line
  image.at<float>(10, 90) = 255.0f;             // one hot pixel
  // The seed's plain mean and deviation of the scan line.
  const cv::Mat bright = BrightLinePixels(image, cv::Mat(), 5, 1.5, true);
  for (int y = 0; y < image.rows; ++y) {
    // The median keeps the line's edges: exactly its 5 pixels.
    EXPECT_EQ(CountSet(bright, y, 40, 45), 5) << "row " << y;
    EXPECT_EQ(CountSet(bright, y, 38, 40) + CountSet(bright, y, 45, 47), 0);
    EXPECT_EQ(CountSet(bright, y, 0, 38) + CountSet(bright, y, 47, 120), 0)
        << "row " << y;
  }
}

TEST(BrightLinePixels, UsesOnlyValidPixelsForTheStatistics) {
  cv::Mat image = NoisyBackground(4, 100, 2.0, 2);
  image(cv::Rect(0, 0, 50, 4)).setTo(1000.0f);  // invalid, very bright
  image(cv::Rect(70, 0, 6, 4)).setTo(160.0f);   // the line
  cv::Mat valid = cv::Mat::zeros(image.size(), CV_8U);
  valid(cv::Rect(50, 0, 50, 4)).setTo(255);
  const cv::Mat with_mask = BrightLinePixels(image, valid, 5, 1.5);
  const cv::Mat without = BrightLinePixels(image, cv::Mat(), 5, 1.5);
  for (int y = 0; y < 4; ++y) {
    EXPECT_GE(CountSet(with_mask, y, 70, 76), 4);
    EXPECT_EQ(CountSet(with_mask, y, 0, 52), 0);
    // Without the mask the bright invalid half sets the threshold: the
    // line is lost.
    EXPECT_EQ(CountSet(without, y, 70, 76), 0);
  }
}

TEST(BrightLinePixels, RobustStatisticsKeepALineBesideZebraBands) {
  cv::Mat image = NoisyBackground(4, 200, 2.0, 3);
  for (int x = 10; x < 130; x += 34) {
    image(cv::Rect(x, 0, 17, 4)).setTo(210.0f);  // bands: 35 % of the row
  }
  image(cv::Rect(160, 0, 8, 4)).setTo(185.0f);  // a line, a bit darker
  const cv::Mat plain = BrightLinePixels(image, cv::Mat(), 5, 1.5, true);
  const cv::Mat robust = BrightLinePixels(image, cv::Mat(), 5, 1.5, false);
  for (int y = 0; y < 4; ++y) {
    EXPECT_EQ(CountSet(plain, y, 155, 175), 0);  // the seed loses it
    EXPECT_EQ(CountSet(robust, y, 160, 168), 8);
  }
}

TEST(BrightLinePixels, LocalReferenceFindsALineInAShadow) {
  // Sunlit asphalt (100) on the left 150 pixels, shadow (35) beyond, and
  // a line in the shadow at 70: under the row's median.
  cv::Mat image = NoisyBackground(4, 240, 2.0, 5);
  image(cv::Rect(150, 0, 90, 4)) -= 65.0f;
  image(cv::Rect(200, 0, 5, 4)) += 35.0f;
  const cv::Mat row_reference = BrightLinePixels(image, cv::Mat(), 5, 1.5);
  cv::Mat local = BrightLinePixels(image, cv::Mat(), 5, 1.5, false, 41);
  // Noise sets a pixel here and there; a line is two pixels wide at least.
  KeepRunsByWidth(cv::Mat(), 2, 10, &local);
  for (int y = 0; y < 4; ++y) {
    EXPECT_EQ(CountSet(row_reference, y, 195, 210), 0);
    EXPECT_EQ(CountSet(local, y, 200, 205), 5);
    // The shadow's edge is a step, not a bright run; nothing else is set.
    EXPECT_EQ(CountSet(local, y, 0, 198) + CountSet(local, y, 207, 240), 0)
        << "row " << y;
  }
}

TEST(JoinChainsAcrossBreaks, JoinsAContinuationOnlyAndOnlyAUniqueOne) {
  // A slanted line (1 column per 10 rows) broken at rows 40-51: written
  // bottom to top (the join returns it top to bottom).
  auto segment = [](int y0, int y1, double x0) {
    std::vector<cv::Point> chain;
    for (int y = y1; y >= y0; --y) {
      chain.emplace_back(static_cast<int>(std::lround(x0 + 0.1 * y)), y);
    }
    return chain;
  };
  const auto upper = segment(0, 39, 20.0), lower = segment(52, 90, 20.0);
  auto joined = JoinChainsAcrossBreaks({upper, lower}, 20, 2.0);
  ASSERT_EQ(joined.size(), 1u);
  EXPECT_EQ(joined[0].size(), upper.size() + lower.size());
  EXPECT_EQ(joined[0].front().y, 0);
  EXPECT_EQ(joined[0].back().y, 90);
  // A gap too long, or a lower piece off the line's continuation: apart.
  EXPECT_EQ(JoinChainsAcrossBreaks({upper, lower}, 10, 2.0).size(), 2u);
  EXPECT_EQ(
      JoinChainsAcrossBreaks({upper, segment(52, 90, 24.0)}, 20, 2.0).size(),
      2u);
  // Two pieces that could both continue it (a fork): no join at all.
  EXPECT_EQ(
      JoinChainsAcrossBreaks({upper, lower, segment(55, 95, 20.5)}, 20, 2.0)
          .size(),
      3u);
}

TEST(HalfContrastEndRow, FindsThePaintsEndsWhateverTheChainsLength) {
  // A 5-pixel line painted over rows 20 to 59 and half of row 60 (gray 150
  // on 50), blurred; its chain, as a threshold would leave it, from 24 to
  // 57.
  cv::Mat image(80, 40, CV_32F, cv::Scalar(50.0f));
  image(cv::Rect(18, 20, 5, 40)).setTo(150.0f);
  image.row(60).colRange(18, 23).setTo(100.0f);  // half a row of paint
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.5);
  std::vector<cv::Point> chain;
  for (int y = 24; y <= 57; ++y) chain.emplace_back(20, y);
  const cv::Mat valid(image.size(), CV_8U, cv::Scalar(255));
  // Row r covers [r - 0.5, r + 0.5]: the paint spans [19.5, 60.0].
  EXPECT_NEAR(HalfContrastEndRow(image, valid, chain, -1, 8.0), 19.5, 0.1);
  EXPECT_NEAR(HalfContrastEndRow(image, valid, chain, +1, 8.0), 60.0, 0.1);
  // No step as strong as asked, or the ground beyond not valid: NaN.
  EXPECT_TRUE(std::isnan(HalfContrastEndRow(image, valid, chain, 1, 200.0)));
  cv::Mat cut = valid.clone();
  cut.rowRange(62, 80).setTo(0);
  EXPECT_TRUE(std::isnan(HalfContrastEndRow(image, cut, chain, 1, 8.0)));
}

TEST(KeepRunsByWidth, KeepsLineWidthsAndCountsBands) {
  cv::Mat binary = cv::Mat::zeros(3, 100, CV_8U);
  binary(cv::Rect(10, 0, 2, 3)).setTo(255);   // noise
  binary(cv::Rect(30, 0, 5, 3)).setTo(255);   // a lane line
  binary(cv::Rect(50, 0, 17, 3)).setTo(255);  // a zebra band
  binary(cv::Rect(95, 0, 5, 3)).setTo(255);   // cut by the image side
  EXPECT_EQ(KeepRunsByWidth(cv::Mat(), 3, 10, &binary), 3);
  for (int y = 0; y < 3; ++y) {
    EXPECT_EQ(CountSet(binary, y, 0, 100), 5);
    EXPECT_EQ(CountSet(binary, y, 30, 35), 5);
  }
}

TEST(KeepRunsOnEvenGround, DropsAKerbBetweenGutterAndSidewalk) {
  cv::Mat image(2, 60, CV_32F, cv::Scalar(70.0f));
  image(cv::Rect(10, 0, 5, 2)).setTo(200.0f);   // paint on asphalt
  image(cv::Rect(40, 0, 5, 2)).setTo(150.0f);   // kerb ...
  image(cv::Rect(45, 0, 15, 2)).setTo(130.0f);  // ... then the sidewalk
  cv::Mat binary = cv::Mat::zeros(image.size(), CV_8U);
  binary(cv::Rect(10, 0, 5, 2)).setTo(255);
  binary(cv::Rect(40, 0, 5, 2)).setTo(255);
  EXPECT_EQ(KeepRunsOnEvenGround(image, 0.5, &binary), 2);
  for (int y = 0; y < 2; ++y) {
    EXPECT_EQ(CountSet(binary, y, 10, 15), 5);
    EXPECT_EQ(CountSet(binary, y, 30, 60), 0);
  }
}

TEST(ThinLines, LeavesOnePixelPerRowNearTheMiddle) {
  cv::Mat binary = cv::Mat::zeros(60, 40, CV_8U);
  binary(cv::Rect(15, 5, 5, 50)).setTo(255);  // columns 15..19, middle 17
  const cv::Mat skeleton = ThinLines(binary);
  for (int y = 10; y < 50; ++y) {
    ASSERT_EQ(CountSet(skeleton, y, 0, 40), 1) << "row " << y;
    int x = 0;
    while (skeleton.at<uint8_t>(y, x) == 0) ++x;
    EXPECT_LE(std::abs(x - 17), 1) << "row " << y;
  }
}

TEST(FollowChains, EveryPixelOnceShortChainsDropped) {
  cv::Mat skeleton = cv::Mat::zeros(50, 50, CV_8U);
  // An L: down column 5 from row 2 to 30, then right along row 30 to 25.
  for (int y = 2; y <= 30; ++y) skeleton.at<uint8_t>(y, 5) = 255;
  for (int x = 6; x <= 25; ++x) skeleton.at<uint8_t>(30, x) = 255;
  // A diagonal of 15 pixels and a 4-pixel stub.
  for (int k = 0; k < 15; ++k) skeleton.at<uint8_t>(5 + k, 30 + k) = 255;
  for (int x = 40; x < 44; ++x) skeleton.at<uint8_t>(45, x) = 255;
  // A closed ring (no end).
  cv::circle(skeleton, cv::Point(15, 12), 6, 255, 1);
  const cv::Mat ring = skeleton(cv::Rect(8, 5, 15, 15)).clone();
  const int ring_pixels = cv::countNonZero(ring);
  const auto chains = FollowChains(skeleton, 10);
  ASSERT_EQ(chains.size(), 3u);
  EXPECT_EQ(chains[0].size(), 29u + 20u);  // the L, from its top end
  EXPECT_EQ(chains[0].front(), cv::Point(5, 2));
  EXPECT_EQ(chains[0].back(), cv::Point(25, 30));
  EXPECT_EQ(chains[1].size(), 15u);
  EXPECT_EQ(static_cast<int>(chains[2].size()), ring_pixels);
  for (const auto& chain : chains) {
    for (size_t i = 1; i < chain.size(); ++i) {
      EXPECT_LE(std::abs(chain[i].x - chain[i - 1].x), 1);
      EXPECT_LE(std::abs(chain[i].y - chain[i - 1].y), 1);
    }
  }
}

TEST(DropCollinearPoints, KeepsEndsCornersAndSpacing) {
  std::vector<cv::Point> chain;
  for (int y = 0; y <= 100; ++y) chain.emplace_back(10, y);
  for (int x = 11; x <= 60; ++x) chain.emplace_back(x, 100);
  const std::vector<int> kept = DropCollinearPoints(chain, 0.7, 1000);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0], 0);
  EXPECT_EQ(chain[kept[1]], cv::Point(10, 100));
  EXPECT_EQ(kept[2], static_cast<int>(chain.size()) - 1);
  const std::vector<int> spaced = DropCollinearPoints(chain, 0.7, 30);
  for (size_t i = 1; i < spaced.size(); ++i) {
    EXPECT_GT(spaced[i], spaced[i - 1]);
    EXPECT_LE(spaced[i] - spaced[i - 1], 30);
  }
  EXPECT_NE(std::find(spaced.begin(), spaced.end(), kept[1]), spaced.end());
}

TEST(RunCentre, SubPixelCentreOfABlurredLine) {
  for (double centre : {20.0, 20.3, 20.5, 20.8}) {
    cv::Mat image(1, 50, CV_32F);
    for (int x = 0; x < 50; ++x) {
      // A 5-pixel box blurred by the optics (Gaussian, sigma 0.8 px).
      const double a = (x - centre + 2.5) / (0.8 * std::sqrt(2.0));
      const double b = (x - centre - 2.5) / (0.8 * std::sqrt(2.0));
      image.at<float>(0, x) =
          static_cast<float>(90.0 + 60.0 * 0.5 * (std::erf(a) - std::erf(b)));
    }
    const cv::Mat bright = BrightLinePixels(image, cv::Mat(), 5, 1.5, true);
    double found = 0.0;
    ASSERT_TRUE(RunCentre(image, bright, 0, 20, &found));
    EXPECT_NEAR(found, centre, 0.1);
    EXPECT_FALSE(RunCentre(image, bright, 0, 40, &found));
  }
}

// Two 640 x 480 cameras 1 m apart, 2.5 m over the road (body z down, the
// road at z = +1), pitched down by 20 degrees.
RigCamera MakeCamera(const std::string& name, double y) {
  RigCamera rig_camera;
  rig_camera.camera =
      Camera(name, 640, 480, 550.0, 550.0, 320.0, 240.0, {0, 0, 0, 0, 0});
  const double pitch = 20.0 * M_PI / 180.0;
  Eigen::Matrix3d R_body_cam;
  R_body_cam.col(0) = Eigen::Vector3d(0, 1, 0);
  R_body_cam.col(2) = Eigen::Vector3d(std::cos(pitch), 0, std::sin(pitch));
  R_body_cam.col(1) = R_body_cam.col(2).cross(R_body_cam.col(0));
  rig_camera.T_body_cam.linear() = R_body_cam;
  rig_camera.T_body_cam.translation() = Eigen::Vector3d(0.8, y, -1.5);
  return rig_camera;
}

// The painted road of the stereo test, in the body frame (x forward, y
// right) on the plane z = 1: a solid line at y = -1.8, dashes at y = 1.6
// (3 m long, 6 m apart), a stop line across at x = 11 from y = -1.8 to
// -0.1, and a zebra crossing (0.5 m bands, x from 13 to 16).
double Paint(double x, double y) {
  const double w = 0.15;
  if (std::abs(y + 1.8) < w / 2 && x < 12.5) return 1.0;
  if (std::abs(y - 1.6) < w / 2 && std::fmod(x + 100.0, 6.0) < 3.0) {
    return 1.0;
  }
  if (std::abs(x - 11.0) < 0.15 && y > -1.8 && y < -0.1) return 1.0;
  if (x > 13.0 && x < 16.0 && y > -3.0 && y < 3.0 &&
      std::fmod(y + 100.0, 1.0) < 0.5) {
    return 1.0;
  }
  return 0.0;
}

// A building's shadow over the right half of the road, its edge crossing
// the dash x in [8, 11] at x = 9.5: the paint in it (0.35 x 210) is darker
// than the sunlit asphalt (90) that sets a scan line's median.
bool InShadow(double x, double y) { return y > 1.6 + 0.6 * (x - 9.5); }

cv::Mat Render(const RigCamera& c, unsigned seed, bool shadow = false) {
  cv::Mat image(c.camera.height(), c.camera.width(), CV_32F);
  const Eigen::Matrix3d R = c.T_body_cam.linear();
  const Eigen::Vector3d o = c.T_body_cam.translation();
  // 2 x 2 supersampling: the paint's edges are anti-aliased.
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      double sum = 0.0;
      for (double du : {-0.25, 0.25}) {
        for (double dv : {-0.25, 0.25}) {
          const Eigen::Vector3d ray =
              R * Eigen::Vector3d((u + du - 320.0) / 550.0,
                                  (v + dv - 240.0) / 550.0, 1.0);
          if (ray.z() <= 0) continue;
          const double t = (1.0 - o.z()) / ray.z();
          const Eigen::Vector3d p = o + t * ray;
          const double light = shadow && InShadow(p.x(), p.y()) ? 0.35 : 1.0;
          sum += 0.25 * light * (90.0 + 120.0 * Paint(p.x(), p.y()));
        }
      }
      image.at<float>(v, u) = static_cast<float>(sum);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.6);
  cv::Mat noise(image.size(), CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  return image + noise;
}

TEST(StereoLineExtractor, RecoversLanesAndStopLineNotTheZebra) {
  const RigCamera left = MakeCamera("left", -0.5);
  const RigCamera right = MakeCamera("right", 0.5);
  RoadPlane road;
  road.offset_m = 1.0;
  const StereoLineExtractor extractor(left, right, road, RoadLineOptions());
  ASSERT_TRUE(extractor.ok()) << extractor.error();
  const PairLines result = extractor.Extract(Render(left, 1), Render(right, 2));
  int solid = 0, dashed = 0, stop = 0;
  for (const RoadLine3d& line : result.lines) {
    ASSERT_EQ(line.points_body.size(), line.covariances_body.size());
    ASSERT_EQ(line.points_body.size(), line.uv_left.size());
    if (line.type == RoadLineType::kCrossingEdge) continue;  // below
    for (size_t k = 0; k < line.points_body.size(); ++k) {
      const Eigen::Vector3d& p = line.points_body[k];
      const Eigen::Matrix3d& c = line.covariances_body[k];
      SCOPED_TRACE(::testing::Message()
                   << RoadLineTypeName(line.type) << " at " << p.transpose());
      // Never inside the zebra crossing.
      EXPECT_FALSE(p.x() > 12.9 && p.x() < 16.1);
      if (line.type == RoadLineType::kStopLine) {
        EXPECT_NEAR(p.x(), 11.0, 0.04);
        EXPECT_NEAR(p.z(), 1.0, 1e-6);  // on the plane by construction
        continue;
      }
      // The solid line, or the dashes (a dash cut by the image border is
      // "solid": only the database can tell).
      const double truth_y = p.y() < 0.0 ? -1.8 : 1.6;
      EXPECT_NEAR(p.y(), truth_y, 0.03);
      // Height from stereo, within 3 sigma of its own covariance (and a
      // few centimetres).
      EXPECT_NEAR(p.z(), 1.0, std::max(0.01, 3.0 * std::sqrt(c(2, 2))));
      EXPECT_LT(std::sqrt(c(2, 2)), 0.05);
      EXPECT_GT(c.determinant(), 0.0);
    }
    const bool left_side = line.points_body[0].y() < 0.0;
    solid += line.type == RoadLineType::kLaneSolid && left_side;
    dashed += line.type == RoadLineType::kLaneDashed && !left_side;
    stop += line.type == RoadLineType::kStopLine;
  }
  EXPECT_GE(solid, 1);
  EXPECT_GE(dashed, 1);
  EXPECT_EQ(stop, 1);
  EXPECT_GT(result.wide_runs, 50);  // the zebra bands, seen and left out
}

TEST(StereoLineExtractor, CrossingEdgesOnTheBandsEndsPaintOnTheLeft) {
  const RigCamera left = MakeCamera("left", -0.5);
  const RigCamera right = MakeCamera("right", 0.5);
  RoadPlane road;
  road.offset_m = 1.0;
  // The crossing lies 12 m ahead of the cameras: beyond the default range
  // of crossing edges (11 m), none.
  for (const RoadLine3d& line :
       StereoLineExtractor(left, right, road, RoadLineOptions())
           .Extract(Render(left, 1), Render(right, 2))
           .lines) {
    EXPECT_NE(line.type, RoadLineType::kCrossingEdge);
  }
  RoadLineOptions options;
  options.crossing_edges.max_end_range_m = 14.0;
  const StereoLineExtractor extractor(left, right, road, options);
  ASSERT_TRUE(extractor.ok()) << extractor.error();
  const PairLines result = extractor.Extract(Render(left, 1), Render(right, 2));
  // The crossing's bands run x 13..16: its near edge (the paint ahead of
  // it). The far one lies on the rectification's range limit (16 m): the
  // ground beyond it is not seen, so it may be the view's end, not the
  // paint's.
  int near_edges = 0, far_edges = 0;
  for (const RoadLine3d& line : result.lines) {
    if (line.type != RoadLineType::kCrossingEdge) continue;
    ASSERT_GE(line.points_body.size(), 3u);
    const bool near = line.points_body[0].x() < 14.5;
    near_edges += near;
    far_edges += !near;
    double mean_x = 0.0;
    for (size_t k = 0; k < line.points_body.size(); ++k) {
      const Eigen::Vector3d& p = line.points_body[k];
      const Eigen::Matrix3d& c = line.covariances_body[k];
      SCOPED_TRACE(::testing::Message() << "edge point " << p.transpose());
      // 13 m ahead of cameras 2.5 m up, a centimetre of stereo height is
      // 5 cm along the road: within 3 sd of its own covariance, which is
      // under 15 cm.
      EXPECT_NEAR(p.x(), 13.0, 3.0 * std::sqrt(c(0, 0)));
      EXPECT_LT(std::sqrt(c(0, 0)), 0.15);
      mean_x += p.x() / line.points_body.size();
      // At a band's centre (bands where fmod(y, 1) < 0.5).
      EXPECT_NEAR(std::fmod(p.y() + 100.0, 1.0), 0.25, 0.03);
      EXPECT_NEAR(p.z(), 1.0, 0.03);
      EXPECT_GT(c.determinant(), 0.0);
    }
    EXPECT_NEAR(mean_x, 13.0, 0.03);
    // Seen from above, the paint to the left of the way the points run:
    // in FRD left of (dx, dy) is (dy, -dx); the paint is +x of the near
    // edge, -x of the far one.
    const Eigen::Vector3d d = line.points_body.back() - line.points_body[0];
    EXPECT_GT((near ? 1.0 : -1.0) * d.y(), 0.0);
  }
  EXPECT_EQ(near_edges, 1);
  EXPECT_EQ(far_edges, 0);
}

// The dash x in [8, 11] at y = 1.6 (body frame) among the lines of a pair:
// its reconstructed extent along x, 0 when no dash lies there, and the
// mid-point of its ends in `centre_x`.
double ShadowedDashLength(const RoadLineOptions& options,
                          double* centre_x = nullptr) {
  const RigCamera left = MakeCamera("left", -0.5);
  const RigCamera right = MakeCamera("right", 0.5);
  RoadPlane road;
  road.offset_m = 1.0;
  const StereoLineExtractor extractor(left, right, road, options);
  EXPECT_TRUE(extractor.ok()) << extractor.error();
  const PairLines result =
      extractor.Extract(Render(left, 3, true), Render(right, 4, true));
  double longest = 0.0;
  for (const RoadLine3d& line : result.lines) {
    if (line.type != RoadLineType::kLaneDashed ||
        line.points_body[0].y() < 0.0) {
      continue;  // the solid line's far part, x in [..., 12.5]
    }
    double lo = 1e9, hi = -1e9;
    for (const Eigen::Vector3d& p : line.points_body) {
      EXPECT_NEAR(p.y(), 1.6, 0.03) << p.transpose();
      lo = std::min(lo, p.x());
      hi = std::max(hi, p.x());
    }
    if (lo > 7.5 && hi < 11.5 && hi - lo > longest) {
      longest = hi - lo;
      if (centre_x != nullptr) {
        *centre_x =
            0.5 * (line.points_body.front().x() + line.points_body.back().x());
      }
    }
  }
  return longest;
}

TEST(StereoLineExtractor, FindsADashWholeAcrossAShadowsEdge) {
  // The local reference in the shadow and the joining across its edge:
  // one whole dash, its ends at half contrast on the paint's ends: its
  // length and centre (the along-track control point) within centimetres.
  double centre_x = 0.0;
  EXPECT_NEAR(ShadowedDashLength(RoadLineOptions(), &centre_x), 3.0, 0.1);
  EXPECT_NEAR(centre_x, 9.5, 0.04);
  // Ends as the vertex averaging leaves them: inside the paint (here by
  // 5 cm each; by 0.1-0.2 m on rendered surveys, more blurred).
  RoadLineOptions inside;
  inside.half_contrast_ends = false;
  EXPECT_LT(ShadowedDashLength(inside), 2.95);
  // The seed's scan-line statistics lose the shadowed part of the dash.
  RoadLineOptions seed;
  seed.background_window_m = 0.0;
  seed.max_break_m = 0.0;
  EXPECT_LT(ShadowedDashLength(seed), 2.0);
}

TEST(ReconstructedLines, RoundTripAndClearErrors) {
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("road_lines_test_" +
        std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
        ".csv"))
          .string();
  std::vector<ReconstructedLinePoint> points(2);
  points[0].exposure_id = 7;
  points[0].line_id = 3;
  points[0].type = RoadLineType::kStopLine;
  points[0].p_body = Eigen::Vector3d(10.1, -1.0 / 3.0, 2.5);
  points[0].covariance_body << 1e-4, 1e-6, 2e-6, 1e-6, 3e-4, 4e-6, 2e-6, 4e-6,
      5e-4;
  points[1] = points[0];
  points[1].point = 1;
  points[1].type = RoadLineType::kLaneDashed;
  WriteReconstructedLines(points, {"test"}, path);
  const auto read = ReadReconstructedLines(path, "lines.csv");
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].type, RoadLineType::kStopLine);
  EXPECT_EQ(read[1].type, RoadLineType::kLaneDashed);
  EXPECT_EQ(read[0].p_body, points[0].p_body);  // exact: shortest round trip
  EXPECT_EQ(read[1].covariance_body, points[0].covariance_body);
  {
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
    text.replace(text.rfind("lane_dashed"), 11, "zebra");
    std::ofstream(path) << text;
  }
  try {
    ReadReconstructedLines(path, "lines.csv");
    ADD_FAILURE() << "an unknown type was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lines.csv:4"), std::string::npos)
        << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace zebrageo
