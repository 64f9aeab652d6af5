#include "reconstruction/bright_lines.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

namespace zebrageo {

bool IsSet(const cv::Mat& mask, int x, int y) {
  return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows &&
         mask.at<uint8_t>(y, x) != 0;
}

namespace {

// The median of `values` (reordered); values must not be empty.
template <typename T>
double MedianOf(std::vector<T>* values) {
  auto mid = values->begin() + values->size() / 2;
  std::nth_element(values->begin(), mid, values->end());
  return *mid;
}

// Row statistics as the seed has them: one reference and deviation for the
// whole scan line (robust unless `plain`). False when the row has too few
// valid pixels or no spread.
bool RowReference(const float* row, const uint8_t* ok, int cols, int min_count,
                  bool plain, std::vector<float>* values, double* reference,
                  double* sigma) {
  values->clear();
  for (int x = 0; x < cols; ++x) {
    if (ok == nullptr || ok[x] != 0) values->push_back(row[x]);
  }
  const int n = static_cast<int>(values->size());
  if (n < min_count) return false;
  if (plain) {
    double sum = 0.0, sum2 = 0.0;
    for (float v : *values) {
      sum += v;
      sum2 += static_cast<double>(v) * v;
    }
    *reference = sum / n;
    *sigma = std::sqrt(std::max(0.0, sum2 / n - *reference * *reference));
  } else {
    // Median and 1.4826 x median absolute deviation: the paint of zebra
    // bands crossing the scan line would otherwise raise the mean and
    // deviation, and the threshold above the line sought.
    *reference = MedianOf(values);
    for (float& v : *values) v = std::abs(v - static_cast<float>(*reference));
    *sigma = 1.4826 * MedianOf(values);
  }
  return *sigma > 0.0;
}

// The running median of the valid values within `half` of each position
// (NaN where there are fewer than `min_count`, or the position is invalid).
void RunningMedian(const float* values, const uint8_t* ok, int cols, int half,
                   int min_count, std::vector<double>* median) {
  median->assign(cols, std::numeric_limits<double>::quiet_NaN());
  // The valid values of [x - half, x + half], kept sorted as x slides.
  std::vector<float> window;
  window.reserve(2 * half + 1);
  auto is_valid = [&](int i) { return ok == nullptr || ok[i] != 0; };
  for (int i = 0; i < std::min(cols, half); ++i) {
    if (is_valid(i)) {
      window.insert(std::upper_bound(window.begin(), window.end(), values[i]),
                    values[i]);
    }
  }
  for (int x = 0; x < cols; ++x) {
    const int entering = x + half;
    if (entering < cols && is_valid(entering)) {
      const float v = values[entering];
      window.insert(std::upper_bound(window.begin(), window.end(), v), v);
    }
    const int leaving = x - half - 1;
    if (leaving >= 0 && is_valid(leaving)) {
      window.erase(
          std::lower_bound(window.begin(), window.end(), values[leaving]));
    }
    if (is_valid(x) && static_cast<int>(window.size()) >= min_count) {
      (*median)[x] = window[window.size() / 2];
    }
  }
}

// The local threshold of each pixel of a row: the running median within
// `half`, plus threshold_sigmas times the robust deviation about it
// (1.4826 x the running median of the absolute residuals: local, so
// shadowed asphalt, darker and flatter than sunlit, has its own). NaN
// where the window holds too few valid pixels. False when nothing is left.
bool LocalThreshold(const float* row, const uint8_t* ok, int cols, int half,
                    int min_count, double threshold_sigmas,
                    std::vector<float>* residual,
                    std::vector<double>* reference,
                    std::vector<double>* threshold) {
  RunningMedian(row, ok, cols, half, min_count, reference);
  residual->assign(cols, 0.0f);
  std::vector<uint8_t> finite(cols, 0);
  bool any = false;
  for (int x = 0; x < cols; ++x) {
    if (!std::isfinite((*reference)[x])) continue;
    (*residual)[x] = static_cast<float>(std::abs(row[x] - (*reference)[x]));
    finite[x] = 1;
    any = true;
  }
  if (!any) return false;
  RunningMedian(residual->data(), finite.data(), cols, half, min_count,
                threshold);
  for (int x = 0; x < cols; ++x) {
    double& t = (*threshold)[x];
    if (std::isfinite(t)) t = (*reference)[x] + threshold_sigmas * 1.4826 * t;
  }
  return true;
}

}  // namespace

cv::Mat BrightLinePixels(const cv::Mat& image, const cv::Mat& valid,
                         int median_window_px, double threshold_sigmas,
                         bool plain_statistics, int background_window_px,
                         double local_threshold_sigmas, double shadow_sigmas) {
  CV_Assert(image.type() == CV_32F);
  CV_Assert(valid.empty() ||
            (valid.type() == CV_8U && valid.size() == image.size()));
  cv::Mat out = cv::Mat::zeros(image.size(), CV_8U);
  const int half = median_window_px / 2;
  const int background_half = background_window_px / 2;
  const bool local = background_half > half;
  std::vector<float> values;
  values.reserve(image.cols);
  std::vector<double> threshold(image.cols), reference, local_threshold;
  for (int y = 0; y < image.rows; ++y) {
    const float* row = image.ptr<float>(y);
    const uint8_t* ok = valid.empty() ? nullptr : valid.ptr<uint8_t>(y);
    double mean = 0.0, sigma = 0.0;
    if (!RowReference(row, ok, image.cols, median_window_px, plain_statistics,
                      &values, &mean, &sigma)) {
      continue;
    }
    threshold.assign(image.cols, mean + threshold_sigmas * sigma);
    // In a shadow (the local reference darker than the scan line's by
    // shadow_sigmas deviations) the local threshold holds; elsewhere the
    // seed's, which the texture of sunlit ground and sidewalks has set.
    const double shadow_level = mean - shadow_sigmas * sigma;
    const int min_count = std::max(median_window_px, background_half);
    // A window's median lies under shadow_level only when more than half
    // of its values do: a row with fewer such pixels has no shadow.
    int dark = 0;
    for (int x = 0; local && x < image.cols; ++x) {
      dark += (ok == nullptr || ok[x] != 0) && row[x] < shadow_level;
    }
    if (local && dark > min_count / 2 &&
        LocalThreshold(row, ok, image.cols, background_half, min_count,
                       local_threshold_sigmas, &values, &reference,
                       &local_threshold)) {
      for (int x = 0; x < image.cols; ++x) {
        if (std::isfinite(local_threshold[x]) && reference[x] < shadow_level) {
          threshold[x] = local_threshold[x];
        }
      }
    }
    // The median of the window exceeds the centre's threshold exactly when
    // more than half of the window does.
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = half; x + half < image.cols; ++x) {
      const double t = threshold[x];
      if (!std::isfinite(t)) continue;
      int above = 0;
      bool all_valid = true;
      for (int i = x - half; i <= x + half; ++i) {
        above += row[i] > t;
        all_valid = all_valid && (ok == nullptr || ok[i] != 0);
      }
      if (all_valid && above > half) o[x] = 255;
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

namespace {

// The gray value at (x, y) of a CV_32F image, bilinear; NaN outside.
double Sample(const cv::Mat& image, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= image.cols || y0 + 1 >= image.rows) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double ax = x - x0, ay = y - y0;
  const float* r0 = image.ptr<float>(y0);
  const float* r1 = image.ptr<float>(y0 + 1);
  return (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x0 + 1]) +
         ay * ((1 - ax) * r1[x0] + ax * r1[x0 + 1]);
}

}  // namespace

bool RunsAcrossRows(const std::vector<cv::Point>& chain) {
  const cv::Point d = chain.back() - chain.front();
  return std::abs(d.y) >= 2 * std::abs(d.x);
}

ColumnFit FitColumns(const std::vector<cv::Point>& chain) {
  double sy = 0.0, sx = 0.0, syy = 0.0, sxy = 0.0;
  for (const cv::Point& p : chain) {
    sy += p.y;
    sx += p.x;
    syy += static_cast<double>(p.y) * p.y;
    sxy += static_cast<double>(p.x) * p.y;
  }
  const double n = static_cast<double>(chain.size());
  const double var = syy - sy * sy / n;
  ColumnFit fit;
  fit.slope = var > 0.0 ? (sxy - sx * sy / n) / var : 0.0;
  fit.x0 = (sx - fit.slope * sy) / n;
  return fit;
}

std::vector<std::vector<cv::Point>> JoinChainsAcrossBreaks(
    std::vector<std::vector<cv::Point>> chains, int max_gap_rows,
    double max_offset_px, int direction_rows) {
  const int n = static_cast<int>(chains.size());
  std::vector<bool> vertical(n, false);
  for (int i = 0; i < n; ++i) {
    std::vector<cv::Point>& c = chains[i];
    if (c.size() < 2) continue;
    const int dy = c.back().y - c.front().y;
    vertical[i] = RunsAcrossRows(c) && dy != 0;
    if (vertical[i] && dy < 0) std::reverse(c.begin(), c.end());
  }
  std::vector<ColumnFit> fits(n);
  for (int i = 0; i < n; ++i) {
    if (vertical[i]) fits[i] = FitColumns(chains[i]);
  }
  // Whether the upper end of chain b continues the lower end of chain a:
  // the two fitted lines meet in the middle of the gap, at the same slope
  // (within max_offset_px over direction_rows).
  auto continues = [&](int a, int b) {
    const int gap = chains[b].front().y - chains[a].back().y;
    if (gap <= 0 || gap > max_gap_rows) return false;
    const double middle = 0.5 * (chains[b].front().y + chains[a].back().y);
    return std::abs(fits[a].At(middle) - fits[b].At(middle)) <= max_offset_px &&
           std::abs(fits[a].slope - fits[b].slope) * direction_rows <=
               max_offset_px;
  };
  std::vector<int> next(n, -1), previous_count(n, 0), next_count(n, 0);
  for (int a = 0; a < n; ++a) {
    if (!vertical[a]) continue;
    for (int b = 0; b < n; ++b) {
      if (b == a || !vertical[b] || !continues(a, b)) continue;
      ++next_count[a];
      ++previous_count[b];
      next[a] = b;
    }
  }
  // Only unique partners on both sides join: two candidates is ambiguity.
  std::vector<int> previous(n, -1);
  for (int a = 0; a < n; ++a) {
    if (next[a] < 0 || next_count[a] != 1 || previous_count[next[a]] != 1) {
      next[a] = -1;
      continue;
    }
    previous[next[a]] = a;
  }
  std::vector<std::vector<cv::Point>> out;
  for (int a = 0; a < n; ++a) {
    if (previous[a] >= 0) continue;  // joined into the chain above it
    std::vector<cv::Point> joined = std::move(chains[a]);
    for (int b = next[a]; b >= 0; b = next[b]) {
      joined.insert(joined.end(), chains[b].begin(), chains[b].end());
    }
    out.push_back(std::move(joined));
  }
  return out;
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

double HalfContrastEndRow(const cv::Mat& image, const cv::Mat& valid,
                          const std::vector<cv::Point>& chain, int outward,
                          double min_contrast) {
  constexpr int kInside = 8, kGap = 6, kOutside = 6;
  const cv::Point end = outward > 0 ? chain.back() : chain.front();
  // The column of the line near its end: a straight fit to its last rows.
  std::vector<cv::Point> end_rows;
  for (const cv::Point& p : chain) {
    if (std::abs(p.y - end.y) <= 3 * kInside) end_rows.push_back(p);
  }
  const ColumnFit fit = FitColumns(end_rows);
  auto gray = [&](int row) {
    const double x = fit.At(row);
    if (!IsSet(valid, static_cast<int>(std::lround(x)), row)) {
      return std::numeric_limits<double>::quiet_NaN();
    }
    return (Sample(image, x - 1.0, row) + Sample(image, x, row) +
            Sample(image, x + 1.0, row)) /
           3.0;
  };
  std::vector<double> inside, outside;
  for (int k = 1; k <= kInside; ++k) {
    inside.push_back(gray(end.y - outward * k));
  }
  for (int k = kGap; k < kGap + kOutside; ++k) {
    outside.push_back(gray(end.y + outward * k));
  }
  for (const std::vector<double>* v : {&inside, &outside}) {
    for (double g : *v) {
      if (!std::isfinite(g)) return std::numeric_limits<double>::quiet_NaN();
    }
  }
  const double paint = MedianOf(&inside), ground = MedianOf(&outside);
  if (!(paint - ground > min_contrast)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double half = 0.5 * (paint + ground);
  // From a few rows inside outwards: the first fall below half.
  double previous = gray(end.y - outward * 3);
  for (int k = -2; k < kGap + kOutside; ++k) {
    const double g = gray(end.y + outward * k);
    if (g < half) {
      const double t = (previous - half) / std::max(1e-9, previous - g);
      return end.y + outward * (k - 1 + std::clamp(t, 0.0, 1.0));
    }
    previous = g;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace zebrageo
