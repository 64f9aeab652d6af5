#include "reconstruction/transversal_sides.h"

#include <glog/logging.h>
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace zebrageo {
namespace {

// A skewed band (a parallelogram) in a rectified image: long sides x = 70
// and x = 103, transversal sides y = y0 + tan(skew) (x - 86.5) with y0 = 60
// (begin, top) and 240 (end), bright paint on dark asphalt, blurred
// along y by `blur_y` (far transversal sides are blurred along the road).
constexpr double kSkew = 14.0 * M_PI / 180.0;

double InsideBand(double x, double y) {
  const double t = std::tan(kSkew) * (x - 86.5);
  return x > 70.0 && x < 103.0 && y > 60.0 + t && y < 240.0 + t ? 1.0 : 0.0;
}

cv::Mat RenderBand(double blur_y) {
  cv::Mat image(300, 170, CV_32F);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      double sum = 0.0;
      for (int k = 0; k < 64; ++k) {
        sum += InsideBand(x - 0.5 + (k % 8 + 0.5) / 8.0,
                          y - 0.5 + (k / 8 + 0.5) / 8.0);
      }
      image.at<float>(y, x) = static_cast<float>(50.0 + 120.0 * sum / 64.0);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7, blur_y);
  // A fixed seed: cv::randn draws from the global cv::theRNG(), whose state
  // depends on the tests run before (the result depended on their order).
  cv::Mat noise(image.size(), CV_32F);
  cv::RNG rng(20261202);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.5);
  return image + noise;
}

// The search area of section 5.1: between the long sides (inset), +-27 px
// around the approximate (unskewed) transversal side y = y0.
std::array<Eigen::Vector2d, 4> Area(double y0) {
  return {Eigen::Vector2d(73, y0 - 27), Eigen::Vector2d(100, y0 - 27),
          Eigen::Vector2d(100, y0 + 27), Eigen::Vector2d(73, y0 + 27)};
}

void ExpectSkewedSide(const ImageLine& line, double y0, double blur) {
  // The true line: normal (-sin, cos) of the skew, through (86.5, y0).
  const Eigen::Vector2d normal(-std::sin(kSkew), std::cos(kSkew));
  const double angle = std::acos(std::abs(line.normal.dot(normal)));
  // Blur along the road spreads the profile: 0.3 degrees for sharp sides,
  // 0.6 for very blurred ones (0.15 px over the side's 30 px).
  EXPECT_LT(angle, 0.15 * std::max(2.0, blur) * M_PI / 180.0);
  EXPECT_LT(std::abs(line.Distance(Eigen::Vector2d(86.5, y0))), 0.1);
}

class HoughTransversal : public ::testing::TestWithParam<double> {};

TEST_P(HoughTransversal, FindsTheSkewedSidesWithinATenthOfAPixel) {
  const cv::Mat image = RenderBand(GetParam());
  const EdgeMap edges = DetectSubpixelEdges(image, cv::Mat(), EdgeOptions());
  BandOptions options;
  const Eigen::Vector2d expected_normal(0.0, 1.0);  // unskewed guess
  const std::vector<ImageLine> begin =
      HoughTransversalCandidates(edges, Area(60.0), expected_normal, options);
  // At the end the image darkens along +y: the expected polarity flips.
  const std::vector<ImageLine> end =
      HoughTransversalCandidates(edges, Area(240.0), -expected_normal, options);
  ASSERT_FALSE(begin.empty());
  ASSERT_FALSE(end.empty());
  int t = -1, l = -1;
  ASSERT_TRUE(ChooseTransversalPair(begin, end, Eigen::Vector2d(0, 1), options,
                                    &t, &l));
  ImageLine top = begin[t], bottom = end[l];
  // Gammas are opposite: into the band at both ends.
  EXPECT_GT(top.gamma.y(), 0.0);
  EXPECT_LT(bottom.gamma.y(), 0.0);
  ASSERT_TRUE(RefineImageLine(edges, Area(60.0), options, &top));
  ASSERT_TRUE(RefineImageLine(edges, Area(240.0), options, &bottom));
  ExpectSkewedSide(top, 60.0, GetParam());
  ExpectSkewedSide(bottom, 240.0, GetParam());
}

// Sharp (near) and blurred along the road (far) transversal sides.
INSTANTIATE_TEST_SUITE_P(Blur, HoughTransversal,
                         ::testing::Values(0.7, 2.5, 4.0));

TEST(HoughTransversal, PairChoiceRequiresPaintBetweenTheSides) {
  ImageLine a, b;
  a.gamma = Eigen::Vector2d(0, -50);  // darkens into the band: a gap
  b.gamma = Eigen::Vector2d(0, 50);
  int t, l;
  EXPECT_FALSE(ChooseTransversalPair({a}, {b}, Eigen::Vector2d(0, 1),
                                     BandOptions(), &t, &l));
  EXPECT_TRUE(ChooseTransversalPair({b}, {a}, Eigen::Vector2d(0, 1),
                                    BandOptions(), &t, &l));
}

TEST(HoughTransversal, PairChoiceTakesTheMostOppositeStrongPair) {
  // Equations 2 and 3: among pairs scoring within 80 % of the best, the
  // one with the smallest gamma dot product.
  ImageLine b1, b2, e1, e2;
  b1.gamma = Eigen::Vector2d(20, 90);  // strongest, but slanted
  b2.gamma = Eigen::Vector2d(0, 85);
  e1.gamma = Eigen::Vector2d(0, -88);
  e2.gamma = Eigen::Vector2d(0, -30);  // weak: out of the 80 %
  int t, l;
  ASSERT_TRUE(ChooseTransversalPair({b1, b2}, {e1, e2}, Eigen::Vector2d(0, 1),
                                    BandOptions(), &t, &l));
  EXPECT_EQ(t, 0);  // (0*0 + 90*-88) < (0 + 85*-88)
  EXPECT_EQ(l, 0);
}

TEST(HoughTransversal, PaintedEndStopsAtTheBandAShadowBoundaryRunsOn) {
  // A painted end: nothing across the line beyond the long sides.
  const cv::Mat band = RenderBand(0.7);
  const EdgeMap band_edges =
      DetectSubpixelEdges(band, cv::Mat(), EdgeOptions());
  BandOptions options;
  std::vector<ImageLine> begin = HoughTransversalCandidates(
      band_edges, Area(60.0), Eigen::Vector2d(0, 1), options);
  ASSERT_FALSE(begin.empty());
  ASSERT_TRUE(RefineImageLine(band_edges, Area(60.0), options, &begin[0]));
  // The band's corners on that line (long sides x = 70 and x = 103).
  auto on_line = [](const ImageLine& line, double x) {
    return Eigen::Vector2d(x,
                           (line.rho - line.normal.x() * x) / line.normal.y());
  };
  const Eigen::Vector2d band_ends[2] = {on_line(begin[0], 70.0),
                                        on_line(begin[0], 103.0)};
  const bool both[2] = {true, true};
  EXPECT_LT(TransversalRunOn(band_edges, begin[0], band_ends, both), 0.1);

  // A shadow boundary across bare road at y = 150: as strong beyond the
  // "band" as inside it.
  cv::Mat road(300, 170, CV_32F);
  for (int y = 0; y < road.rows; ++y) {
    road.row(y).setTo(y < 150 ? 90.0 : 45.0);
  }
  cv::GaussianBlur(road, road, cv::Size(0, 0), 0.7);
  cv::Mat noise(road.size(), CV_32F);
  cv::RNG rng(20261203);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.5);
  road += noise;
  const EdgeMap road_edges =
      DetectSubpixelEdges(road, cv::Mat(), EdgeOptions());
  // The image darkens along +y: a begin side would brighten.
  std::vector<ImageLine> shadow = HoughTransversalCandidates(
      road_edges, Area(150.0), Eigen::Vector2d(0, -1), options);
  ASSERT_FALSE(shadow.empty());
  ASSERT_TRUE(RefineImageLine(road_edges, Area(150.0), options, &shadow[0]));
  const Eigen::Vector2d shadow_ends[2] = {on_line(shadow[0], 70.0),
                                          on_line(shadow[0], 103.0)};
  const double run_on =
      TransversalRunOn(road_edges, shadow[0], shadow_ends, both);
  EXPECT_GT(run_on, 0.8);
  EXPECT_GT(run_on, options.max_transversal_run_on);
  // Beyond neither side: nothing to compare, no run-on.
  const bool neither[2] = {false, false};
  EXPECT_EQ(TransversalRunOn(road_edges, shadow[0], shadow_ends, neither), 0.0);
}

TEST(EdgeStep, APaintedEndStepsLikeTheLongSidesALineInPlainPaintDoesNot) {
  const cv::Mat band = RenderBand(0.7);
  const EdgeMap edges = DetectSubpixelEdges(band, cv::Mat(), EdgeOptions());
  const BandOptions options;
  auto horizontal = [](double y) {
    ImageLine line;
    line.normal = Eigen::Vector2d(0, 1);
    line.rho = y;
    return line;
  };
  ImageLine long_side;
  long_side.normal = Eigen::Vector2d(1, 0);
  long_side.rho = 70.0;
  const double long_step =
      EdgeStep(edges, long_side, Eigen::Vector2d(70, 80),
               Eigen::Vector2d(70, 220), options.end_step_profile_px);
  // Paint 120 grey levels over the asphalt.
  EXPECT_NEAR(long_step, 120.0, 12.0);
  // The begin side, skewed: a line along it between the long sides.
  const double t = std::tan(kSkew);
  ImageLine end;
  end.normal = Eigen::Vector2d(-std::sin(kSkew), std::cos(kSkew));
  end.rho = end.normal.dot(Eigen::Vector2d(86.5, 60.0));
  const double end_step = EdgeStep(
      edges, end, Eigen::Vector2d(70, 60 + t * (70 - 86.5)),
      Eigen::Vector2d(103, 60 + t * (103 - 86.5)), options.end_step_profile_px);
  EXPECT_GT(end_step, 0.8 * long_step);
  // Across the middle of the band: paint on both sides, only noise.
  const double paint_step =
      EdgeStep(edges, horizontal(150.0), Eigen::Vector2d(70, 150),
               Eigen::Vector2d(103, 150), options.end_step_profile_px);
  EXPECT_LT(paint_step, options.min_end_step_fraction * long_step);
}

// A near end a few pixels inside the border of what the images see (a
// band's end just above the bottom of the image): the refinement and the
// end's step use what the image holds on both sides of the edge.
TEST(HoughTransversal, AnEndNearTheImageBorderIsRefinedAndStepsLikeThePaint) {
  const cv::Mat image = RenderBand(0.7);
  // Nothing is seen above y = 50: the end (y = 56 to 64 across the band)
  // is 6-14 px inside, less than the profiles' reach.
  cv::Mat valid(image.size(), CV_8U, cv::Scalar(255));
  valid.rowRange(0, 50).setTo(0);
  const EdgeMap edges = DetectSubpixelEdges(image, valid, EdgeOptions());
  const BandOptions options;
  const std::vector<ImageLine> begin = HoughTransversalCandidates(
      edges, Area(60.0), Eigen::Vector2d(0.0, 1.0), options);
  ASSERT_FALSE(begin.empty());
  ImageLine top = begin[0];
  ASSERT_TRUE(RefineImageLine(edges, Area(60.0), options, &top));
  ExpectSkewedSide(top, 60.0, 0.7);
  const double t = std::tan(kSkew);
  const double end_step = EdgeStep(
      edges, top, Eigen::Vector2d(70, 60 + t * (70 - 86.5)),
      Eigen::Vector2d(103, 60 + t * (103 - 86.5)), options.end_step_profile_px);
  EXPECT_NEAR(end_step, 120.0, 15.0);  // the paint's 120 grey levels
}

// The skewed band of RenderBand seen far away: an original pixel covers 6
// rectified rows along the band (about 14 m ahead of a 2 m high camera at
// 1.5 cm per rectified pixel), worn paint only 40 grey levels over the
// asphalt, read noise 3 grey levels; then resampled (bilinear) to the
// rectified grid, as the rectification does.
cv::Mat RenderFarBand(uint64_t seed) {
  constexpr int kRows = 6;  // rectified rows per original row
  cv::Mat original(300 / kRows, 170, CV_32F);
  for (int y = 0; y < original.rows; ++y) {
    for (int x = 0; x < original.cols; ++x) {
      double sum = 0.0;
      for (int k = 0; k < 64; ++k) {
        sum += InsideBand(x - 0.5 + (k % 8 + 0.5) / 8.0,
                          kRows * y - 0.5 + kRows * (k / 8 + 0.5) / 8.0);
      }
      original.at<float>(y, x) = static_cast<float>(50.0 + 40.0 * sum / 64.0);
    }
  }
  cv::GaussianBlur(original, original, cv::Size(0, 0), 0.7, 0.7);
  cv::Mat noise(original.size(), CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  original += noise;
  cv::Mat rectified;
  cv::resize(original, rectified, cv::Size(170, 300), 0, 0, cv::INTER_LINEAR);
  return rectified;
}

TEST(HoughTransversal, AFarEndFittedAlongItsCrossingsDirectionKeepsItsCorners) {
  // Corner errors along the band (rectified px) at the long sides x = 70
  // and x = 103, free fit against the fit along the crossing's direction
  // (here the true one: the crossing's direction comes from its near
  // ends, much more precise than a far end's own).
  const Eigen::Vector2d normal(-std::sin(kSkew), std::cos(kSkew));
  const BandOptions options;
  double free_ss = 0.0, fixed_ss = 0.0;
  int n = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const EdgeMap edges =
        DetectSubpixelEdges(RenderFarBand(seed), cv::Mat(), EdgeOptions());
    const std::vector<ImageLine> begin = HoughTransversalCandidates(
        edges, Area(60.0), Eigen::Vector2d(0.0, 1.0), options);
    ASSERT_FALSE(begin.empty());
    ImageLine free_line = begin[0];
    ASSERT_TRUE(RefineImageLine(edges, Area(60.0), options, &free_line));
    ImageLine fixed_line = free_line;
    ASSERT_TRUE(
        RefineImageLine(edges, Area(60.0), options, &fixed_line, &normal));
    EXPECT_NEAR(std::abs(fixed_line.normal.dot(normal)), 1.0, 1e-12);
    for (double x : {70.0, 103.0}) {
      const double y_true = 60.0 + std::tan(kSkew) * (x - 86.5);
      auto error = [&](const ImageLine& line) {
        return (line.rho - line.normal.x() * x) / line.normal.y() - y_true;
      };
      free_ss += std::pow(error(free_line), 2);
      fixed_ss += std::pow(error(fixed_line), 2);
      ++n;
    }
  }
  const double free_rms = std::sqrt(free_ss / n);
  const double fixed_rms = std::sqrt(fixed_ss / n);
  LOG(INFO) << "far end corners: free " << free_rms << " px, fixed "
            << fixed_rms << " px (rectified)";
  // About 0.6 px free, 0.27 px fixed (a twentieth of an original pixel).
  EXPECT_LT(fixed_rms, 0.6 * free_rms);
  EXPECT_LT(fixed_rms, 0.4);
}

}  // namespace
}  // namespace zebrageo
