#include "reconstruction/debug_images.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace zebrageo {
namespace {

cv::Point ToPoint(const Eigen::Vector2d& p) {
  // 4 fractional bits for sub-pixel drawing.
  return cv::Point(static_cast<int>(std::lround(p.x() * 16.0)),
                   static_cast<int>(std::lround(p.y() * 16.0)));
}

cv::Mat ToBgr(const cv::Mat& gray32) {
  cv::Mat gray8, bgr;
  gray32.convertTo(gray8, CV_8U);
  cv::cvtColor(gray8, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

}  // namespace

void WriteDebugImages(const std::string& prefix, const cv::Mat& rectified,
                      const cv::Mat& original, const EdgeMap& edges,
                      const std::vector<Eigen::Vector2d>& road_points,
                      const std::vector<Eigen::Vector2d>& off_road_points,
                      const LongSideDetection& detection,
                      const BandModelingDebug& band_debug,
                      const std::vector<Band>& bands,
                      const StereoPairReconstructor& pair) {
  const RoadRectification& rectification = pair.rectification();
  cv::Mat image = ToBgr(rectified);
  // Pixels outside the valid area are tinted red.
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      if (!rectification.IsValid(x, y)) {
        image.at<cv::Vec3b>(y, x)[2] = static_cast<uint8_t>(
            std::min(255, image.at<cv::Vec3b>(y, x)[2] + 60));
      }
    }
  }
  for (const EdgePoint& e : edges.points) {
    image.at<cv::Vec3b>(e.py, e.px) = cv::Vec3b(128, 128, 128);
  }
  auto dot = [&](const Eigen::Vector2d& p, const cv::Vec3b& colour) {
    const int x = static_cast<int>(std::lround(p.x()));
    const int y = static_cast<int>(std::lround(p.y()));
    if (x >= 0 && y >= 0 && x < image.cols && y < image.rows) {
      image.at<cv::Vec3b>(y, x) = colour;
    }
  };
  for (const Eigen::Vector2d& p : off_road_points) dot(p, {0, 0, 255});
  for (const Eigen::Vector2d& p : road_points) dot(p, {0, 255, 0});
  auto line = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                  const cv::Scalar& colour, int thickness) {
    cv::line(image, ToPoint(a), ToPoint(b), colour, thickness, cv::LINE_AA, 4);
  };
  for (const LongSide& side : detection.sides) {
    Eigen::Vector2d a, b;
    if (rectification.ProjectToRectified(0, side.Begin(), &a) &&
        rectification.ProjectToRectified(0, side.End(), &b)) {
      line(a, b, cv::Scalar(0, 255, 255), 1);
    }
  }
  for (const auto& segment : band_debug.band_pairs) {
    line(segment[0], segment[1], cv::Scalar(0, 128, 255), 2);
  }
  for (const auto& area : band_debug.search_areas) {
    for (int k = 0; k < 4; ++k) {
      line(area[k], area[(k + 1) % 4], cv::Scalar(255, 255, 0), 1);
    }
  }
  for (const auto& segment : band_debug.candidate_lines) {
    line(segment[0], segment[1], cv::Scalar(255, 0, 255), 1);
  }
  cv::Mat original_bgr = ToBgr(original);
  for (const Band& band : bands) {
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector2d a, b, ua, ub;
      if (rectification.ProjectToRectified(0, band.vertices_body[k], &a) &&
          rectification.ProjectToRectified(0, band.vertices_body[(k + 1) % 4],
                                           &b)) {
        line(a, b, cv::Scalar(255, 0, 0), 2);
      }
      if (pair.ProjectToOriginal(0, band.vertices_body[k], &ua) &&
          pair.ProjectToOriginal(0, band.vertices_body[(k + 1) % 4], &ub)) {
        cv::line(original_bgr, ToPoint(ua), ToPoint(ub), cv::Scalar(255, 0, 0),
                 1, cv::LINE_AA, 4);
      }
    }
  }
  cv::imwrite(prefix + "_rectified.png", image);
  cv::imwrite(prefix + "_left.png", original_bgr);
}

}  // namespace zebrageo
