#include "reconstruction/bright_lines.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

namespace zebrageo {

bool IsSet(const cv::Mat& mask, int x, int y) {
  return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows &&
         mask.at<uint8_t>(y, x) != 0;
}

cv::Mat BrightLinePixels(const cv::Mat& image, const cv::Mat& valid,
                         int median_window_px, double threshold_sigmas,
                         bool plain_statistics) {
  CV_Assert(image.type() == CV_32F);
  CV_Assert(valid.empty() ||
            (valid.type() == CV_8U && valid.size() == image.size()));
  cv::Mat out = cv::Mat::zeros(image.size(), CV_8U);
  const int half = median_window_px / 2;
  std::vector<float> values;
  values.reserve(image.cols);
  for (int y = 0; y < image.rows; ++y) {
    const float* row = image.ptr<float>(y);
    const uint8_t* ok = valid.empty() ? nullptr : valid.ptr<uint8_t>(y);
    // The scan line's statistics. Robust (median and 1.4826 x median
    // absolute deviation) unless plain_statistics: the paint of zebra bands
    // crossing the scan line would otherwise raise the mean and deviation,
    // and the threshold above the line sought.
    values.clear();
    for (int x = 0; x < image.cols; ++x) {
      if (ok == nullptr || ok[x] != 0) values.push_back(row[x]);
    }
    const int n = static_cast<int>(values.size());
    if (n < median_window_px) continue;
    double mean = 0.0, sigma = 0.0;
    if (plain_statistics) {
      double sum = 0.0, sum2 = 0.0;
      for (float v : values) {
        sum += v;
        sum2 += static_cast<double>(v) * v;
      }
      mean = sum / n;
      sigma = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
    } else {
      auto mid = values.begin() + n / 2;
      std::nth_element(values.begin(), mid, values.end());
      mean = *mid;
      for (float& v : values) v = std::abs(v - static_cast<float>(mean));
      std::nth_element(values.begin(), mid, values.end());
      sigma = 1.4826 * *mid;
    }
    if (!(sigma > 0.0)) continue;
    const double threshold = mean + threshold_sigmas * sigma;
    // The median of the window exceeds the threshold exactly when more than
    // half of the window does: a sliding count, no sorting.
    uint8_t* o = out.ptr<uint8_t>(y);
    int above = 0, invalid = 0;
    for (int x = 0; x < image.cols + half; ++x) {
      if (x < image.cols) {
        above += row[x] > threshold;
        invalid += ok != nullptr && ok[x] == 0;
      }
      const int leaving = x - median_window_px;
      if (leaving >= 0) {
        above -= row[leaving] > threshold;
        invalid -= ok != nullptr && ok[leaving] == 0;
      }
      const int centre = x - half;
      if (centre < half || centre + half >= image.cols) continue;
      if (invalid == 0 && above > half) o[centre] = 255;
    }
  }
  return out;
}

int KeepRunsByWidth(const cv::Mat& valid, int min_px, int max_px,
                    cv::Mat* binary) {
  CV_Assert(binary->type() == CV_8U);
  int wide = 0;
  for (int y = 0; y < binary->rows; ++y) {
    uint8_t* row = binary->ptr<uint8_t>(y);
    int x = 0;
    while (x < binary->cols) {
      if (row[x] == 0) {
        ++x;
        continue;
      }
      const int begin = x;
      while (x < binary->cols && row[x] != 0) ++x;
      const int width = x - begin;
      const bool bounded = (valid.empty() && begin > 0 && x < binary->cols) ||
                           (IsSet(valid, begin - 1, y) && IsSet(valid, x, y));
      if (width > max_px && bounded) ++wide;
      if (!bounded || width < min_px || width > max_px) {
        std::fill(row + begin, row + x, 0);
      }
    }
  }
  return wide;
}

int KeepRunsOnEvenGround(const cv::Mat& image, double max_side_difference,
                         cv::Mat* binary) {
  CV_Assert(binary->type() == CV_8U && image.type() == CV_32F &&
            image.size() == binary->size());
  int dropped = 0;
  for (int y = 0; y < binary->rows; ++y) {
    uint8_t* row = binary->ptr<uint8_t>(y);
    const float* gray = image.ptr<float>(y);
    int x = 0;
    while (x < binary->cols) {
      if (row[x] == 0) {
        ++x;
        continue;
      }
      const int begin = x;
      float peak = gray[x];
      while (x < binary->cols && row[x] != 0) peak = std::max(peak, gray[x++]);
      // The ground two and three pixels outside the run, each side.
      auto side = [&](int a, int b) {
        a = std::clamp(a, 0, binary->cols - 1);
        b = std::clamp(b, 0, binary->cols - 1);
        return 0.5 * (gray[a] + gray[b]);
      };
      const double left = side(begin - 3, begin - 2);
      const double right = side(x + 1, x + 2);
      const double contrast = peak - std::min(left, right);
      if (std::abs(left - right) > max_side_difference * contrast) {
        std::fill(row + begin, row + x, 0);
        ++dropped;
      }
    }
  }
  return dropped;
}

cv::Mat ThinLines(const cv::Mat& binary) {
  cv::Mat skeleton = cv::Mat::zeros(binary.size(), CV_8U);
  // Thinning costs per pixel of the image: only the part with lines.
  const cv::Rect box = cv::boundingRect(binary);
  if (box.area() == 0) return skeleton;
  const cv::Rect padded = (box + cv::Size(2, 2) - cv::Point(1, 1)) &
                          cv::Rect(0, 0, binary.cols, binary.rows);
  cv::Mat thin;
  cv::ximgproc::thinning(binary(padded), thin,
                         cv::ximgproc::THINNING_ZHANGSUEN);
  thin.copyTo(skeleton(padded));
  return skeleton;
}

std::vector<std::vector<cv::Point>> FollowChains(const cv::Mat& skeleton,
                                                 int min_length_px) {
  CV_Assert(skeleton.type() == CV_8U);
  cv::Mat work = skeleton.clone();
  // 4-neighbours first: along a staircase the chain takes the corner pixel
  // rather than cutting it off as a one-pixel spur.
  static const int kDx[8] = {1, 0, -1, 0, 1, -1, -1, 1};
  static const int kDy[8] = {0, 1, 0, -1, 1, 1, -1, -1};
  auto neighbours = [&](int x, int y) {
    int n = 0;
    for (int k = 0; k < 8; ++k) n += IsSet(work, x + kDx[k], y + kDy[k]);
    return n;
  };
  std::vector<std::vector<cv::Point>> chains;
  auto follow = [&](int x, int y) {
    std::vector<cv::Point> chain;
    for (;;) {
      chain.emplace_back(x, y);
      work.at<uint8_t>(y, x) = 0;
      int k = 0;
      while (k < 8 && !IsSet(work, x + kDx[k], y + kDy[k])) ++k;
      if (k == 8) break;
      x += kDx[k];
      y += kDy[k];
    }
    if (static_cast<int>(chain.size()) >= min_length_px) {
      chains.push_back(std::move(chain));
    }
  };
  // Open chains from their ends, then what is left (closed loops).
  for (int pass = 0; pass < 2; ++pass) {
    for (int y = 0; y < work.rows; ++y) {
      for (int x = 0; x < work.cols; ++x) {
        if (work.at<uint8_t>(y, x) != 0 &&
            (pass == 1 || neighbours(x, y) <= 1)) {
          follow(x, y);
        }
      }
    }
  }
  return chains;
}

std::vector<int> DropCollinearPoints(const std::vector<cv::Point>& chain,
                                     double tolerance_px, int max_spacing_px) {
  std::vector<int> kept;
  if (chain.empty()) return kept;
  std::vector<cv::Point> approx;
  cv::approxPolyDP(chain, approx, tolerance_px, false);
  // approxPolyDP returns points, in chain order: back to indices (a chain
  // visits each pixel once).
  std::vector<int> corners;
  size_t j = 0;
  for (const cv::Point& p : approx) {
    while (j < chain.size() && chain[j] != p) ++j;
    if (j == chain.size()) break;
    corners.push_back(static_cast<int>(j));
  }
  if (corners.empty() || corners.front() != 0)
    corners.insert(corners.begin(), 0);
  const int last = static_cast<int>(chain.size()) - 1;
  if (corners.back() != last) corners.push_back(last);
  max_spacing_px = std::max(1, max_spacing_px);
  for (size_t c = 0; c + 1 < corners.size(); ++c) {
    const int a = corners[c], b = corners[c + 1];
    const int pieces = (b - a + max_spacing_px - 1) / max_spacing_px;
    for (int s = 0; s < pieces; ++s) kept.push_back(a + (b - a) * s / pieces);
  }
  kept.push_back(last);
  return kept;
}

bool RunCentre(const cv::Mat& image, const cv::Mat& binary, int y, int x,
               double* centre) {
  if (y < 0 || y >= binary.rows) return false;
  const uint8_t* b = binary.ptr<uint8_t>(y);
  if (x < 0 || x >= binary.cols || b[x] == 0) {
    if (x + 1 >= 0 && x + 1 < binary.cols && b[x + 1] != 0) {
      ++x;
    } else if (x - 1 >= 0 && x - 1 < binary.cols && b[x - 1] != 0) {
      --x;
    } else {
      return false;
    }
  }
  int begin = x, end = x + 1;
  while (begin > 0 && b[begin - 1] != 0) --begin;
  while (end < binary.cols && b[end] != 0) ++end;
  // Background: the darker side two pixels outside the run (the median
  // decision makes the run about a pixel narrower than the paint's blur).
  const float* row = image.ptr<float>(y);
  const int lo = std::max(0, begin - 2),
            hi = std::min(binary.cols - 1, end + 1);
  const double background = std::min(row[lo], row[hi]);
  double weight = 0.0, moment = 0.0;
  for (int i = std::max(0, begin - 1); i <= std::min(binary.cols - 1, end);
       ++i) {
    const double w = std::max(0.0, row[i] - background);
    weight += w;
    moment += w * i;
  }
  if (!(weight > 0.0)) return false;
  *centre = moment / weight;
  return true;
}

}  // namespace zebrageo
