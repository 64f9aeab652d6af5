#include "reconstruction/subpixel_edges.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "survey/option_check.h"

namespace zebrageo {
namespace {

// Minimum cosine between the gradients of two chained edge points (about
// 45 degrees): a chain follows one edge, it does not turn a corner.
constexpr double kMinChainGradientCosine = 0.7;

float Bilinear(const cv::Mat& image, double x, double y) {
  if (!(x >= 0.0 && y >= 0.0 && x <= image.cols - 1 && y <= image.rows - 1)) {
    return 0.0f;
  }
  const int x0 = std::min(static_cast<int>(x), image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), image.rows - 2);
  const float fx = static_cast<float>(x - x0);
  const float fy = static_cast<float>(y - y0);
  const float* r0 = image.ptr<float>(y0);
  const float* r1 = image.ptr<float>(y0 + 1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
         fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

// The forward neighbour of edge point `p` along its edge: the closest point
// in the 3x3 (then 5x5) neighbourhood that lies ahead along the tangent and
// has a similar gradient.
int ForwardNeighbour(const std::vector<EdgePoint>& points, const cv::Mat& index,
                     int p) {
  const EdgePoint& e = points[p];
  const double tx = -e.gy / e.norm;  // tangent: gradient turned by +90 deg
  const double ty = e.gx / e.norm;
  for (int radius = 1; radius <= 2; ++radius) {
    int best = -1;
    double best_distance = 1e9;
    for (int dy = -radius; dy <= radius; ++dy) {
      const int y = e.py + dy;
      if (y < 0 || y >= index.rows) continue;
      for (int dx = -radius; dx <= radius; ++dx) {
        const int x = e.px + dx;
        if ((dx == 0 && dy == 0) || x < 0 || x >= index.cols) continue;
        const int q = index.at<int>(y, x);
        if (q < 0) continue;
        const EdgePoint& f = points[q];
        const double vx = f.x - e.x;
        const double vy = f.y - e.y;
        if (vx * tx + vy * ty <= 0.0) continue;
        if (e.gx * f.gx + e.gy * f.gy <
            kMinChainGradientCosine * e.norm * f.norm) {
          continue;
        }
        const double distance = std::hypot(vx, vy);
        if (distance < best_distance) {
          best_distance = distance;
          best = q;
        }
      }
    }
    if (best >= 0) return best;
  }
  return -1;
}

}  // namespace

std::string EdgeOptions::Check() const {
  OptionCheck check;
  OPTION_IN(check, gaussian_sigma_px, "[", 0.3, 10.0, "]");
  OPTION_GT(check, low_threshold, 0.0);
  OPTION_GE(check, high_threshold, low_threshold);
  OPTION_GE(check, min_chain_points, 2);
  return check.problem();
}

bool EdgeMap::IsUsable(double x, double y) const {
  const int xi = static_cast<int>(std::lround(x));
  const int yi = static_cast<int>(std::lround(y));
  if (xi < 0 || yi < 0 || xi >= width || yi >= height) return false;
  return usable.empty() || usable.at<uint8_t>(yi, xi) != 0;
}

cv::Vec2f EdgeMap::GradientAt(double x, double y) const {
  return cv::Vec2f(Bilinear(gx, x, y), Bilinear(gy, x, y));
}

namespace {

// Non-maximum suppression and Devernay's sub-pixel correction of the
// gradient `norm` of `edges`; `index` (CV_32S, -1 elsewhere) gets each
// point's index.
void SuppressNonMaxima(const EdgeMap& edges, const cv::Mat& norm,
                       const EdgeOptions& options, cv::Mat* index_out,
                       std::vector<EdgePoint>* points_out) {
  const cv::Mat& usable = edges.usable;
  cv::Mat& index = *index_out;
  std::vector<EdgePoint>& points = *points_out;
  points.clear();
  const float low = static_cast<float>(options.low_threshold);
  for (int y = 1; y + 1 < norm.rows; ++y) {
    const float* n0 = norm.ptr<float>(y - 1);
    const float* n1 = norm.ptr<float>(y);
    const float* n2 = norm.ptr<float>(y + 1);
    const float* gxr = edges.gx.ptr<float>(y);
    const float* gyr = edges.gy.ptr<float>(y);
    const uint8_t* ok = usable.empty() ? nullptr : usable.ptr<uint8_t>(y);
    for (int x = 1; x + 1 < norm.cols; ++x) {
      const float b = n1[x];
      if (b < low || (ok != nullptr && ok[x] == 0)) continue;
      float a, c;
      const bool along_x = std::abs(gxr[x]) >= std::abs(gyr[x]);
      if (along_x) {
        a = n1[x - 1];
        c = n1[x + 1];
      } else {
        a = n0[x];
        c = n2[x];
      }
      if (!(b > a && b >= c)) continue;
      const float curvature = a - 2.0f * b + c;
      const float offset = curvature < 0.0f ? 0.5f * (a - c) / curvature : 0.0f;
      EdgePoint e;
      e.x = static_cast<float>(x) + (along_x ? offset : 0.0f);
      e.y = static_cast<float>(y) + (along_x ? 0.0f : offset);
      e.gx = gxr[x];
      e.gy = gyr[x];
      e.norm = b;
      e.px = x;
      e.py = y;
      index.at<int>(y, x) = static_cast<int>(points.size());
      points.push_back(e);
    }
  }
}

// Chains of the points: each point links to its closest forward
// neighbour; a point claimed by several keeps the closest predecessor.
// Open chains from their first point, then closed contours.
std::vector<std::vector<int>> LinkChains(const std::vector<EdgePoint>& points,
                                         const cv::Mat& index) {
  const int n = static_cast<int>(points.size());
  std::vector<int> next(n, -1), prev(n, -1);
  for (int p = 0; p < n; ++p) next[p] = ForwardNeighbour(points, index, p);
  std::vector<double> prev_distance(n, 1e9);
  for (int p = 0; p < n; ++p) {
    const int q = next[p];
    if (q < 0) continue;
    const double d =
        std::hypot(points[q].x - points[p].x, points[q].y - points[p].y);
    if (d < prev_distance[q]) {
      prev_distance[q] = d;
      prev[q] = p;
    }
  }
  for (int p = 0; p < n; ++p) {
    if (next[p] >= 0 && prev[next[p]] != p) next[p] = -1;
  }

  std::vector<std::vector<int>> chains;
  std::vector<char> visited(n, 0);
  auto follow = [&](int start) {
    std::vector<int> chain;
    for (int p = start; p >= 0 && !visited[p]; p = next[p]) {
      visited[p] = 1;
      chain.push_back(p);
    }
    return chain;
  };
  for (int p = 0; p < n; ++p) {
    if (prev[p] < 0) chains.push_back(follow(p));
  }
  for (int p = 0; p < n; ++p) {
    if (!visited[p]) chains.push_back(follow(p));  // closed contours
  }

  return chains;
}

// Hysteresis per chain: the chains of `points` long enough and with a
// point above high_threshold go into `edges`, points renumbered sorted by
// (row, x), with the rows' first points.
void KeepChains(const std::vector<EdgePoint>& points,
                const std::vector<std::vector<int>>& chains,
                const EdgeOptions& options, int rows, EdgeMap* edges_out) {
  EdgeMap& edges = *edges_out;
  const int n = static_cast<int>(points.size());
  std::vector<int> chain_of(n, -1);
  std::vector<int> position_of(n, -1);
  int kept_chains = 0;
  for (const std::vector<int>& chain : chains) {
    if (static_cast<int>(chain.size()) < options.min_chain_points) continue;
    float strongest = 0.0f;
    for (int p : chain) strongest = std::max(strongest, points[p].norm);
    if (strongest < options.high_threshold) continue;
    for (size_t i = 0; i < chain.size(); ++i) {
      chain_of[chain[i]] = kept_chains;
      position_of[chain[i]] = static_cast<int>(i);
    }
    ++kept_chains;
  }
  std::vector<int> order;
  for (int p = 0; p < n; ++p) {
    if (chain_of[p] >= 0) order.push_back(p);
  }
  // Points were created in row-major order, so `order` is sorted already.
  edges.points.reserve(order.size());
  edges.chains.assign(kept_chains, {});
  std::vector<int> new_index(n, -1);
  for (int p : order) {
    new_index[p] = static_cast<int>(edges.points.size());
    EdgePoint e = points[p];
    e.chain = chain_of[p];
    edges.points.push_back(e);
  }
  for (int p : order) {
    std::vector<int>& chain = edges.chains[chain_of[p]];
    if (static_cast<int>(chain.size()) <= position_of[p]) {
      chain.resize(position_of[p] + 1, -1);
    }
    chain[position_of[p]] = new_index[p];
  }
  for (size_t c = 0; c < edges.chains.size(); ++c) {
    for (size_t i = 0; i < edges.chains[c].size(); ++i) {
      edges.points[edges.chains[c][i]].index_in_chain = static_cast<int>(i);
    }
  }
  edges.row_begin.assign(rows + 1, 0);
  for (const EdgePoint& e : edges.points) ++edges.row_begin[e.py + 1];
  std::partial_sum(edges.row_begin.begin(), edges.row_begin.end(),
                   edges.row_begin.begin());
}

}  // namespace

cv::Mat UsableMask(const cv::Mat& valid_mask, const EdgeOptions& options) {
  cv::Mat usable;
  if (valid_mask.empty()) return usable;
  // Gradients within the smoothing support of an invalid pixel are
  // artefacts of the border.
  const int radius =
      static_cast<int>(std::ceil(3.0 * options.gaussian_sigma_px)) + 1;
  cv::erode(valid_mask, usable,
            cv::getStructuringElement(
                cv::MORPH_RECT, cv::Size(2 * radius + 1, 2 * radius + 1)));
  return usable;
}

EdgeMap DetectSubpixelEdges(const cv::Mat& image, const cv::Mat& valid_mask,
                            const EdgeOptions& options) {
  EdgeMap edges;
  EdgeScratch scratch;
  DetectSubpixelEdges(image, UsableMask(valid_mask, options), options, &scratch,
                      &edges);
  return edges;
}

void DetectSubpixelEdges(const cv::Mat& image, const cv::Mat& usable,
                         const EdgeOptions& options, EdgeScratch* scratch,
                         EdgeMap* edges_out) {
  CHECK_EQ(image.type(), CV_32F);
  EdgeMap& edges = *edges_out;
  edges.width = image.cols;
  edges.height = image.rows;
  edges.points.clear();
  edges.chains.clear();
  edges.usable = usable;
  cv::GaussianBlur(image, scratch->smooth, cv::Size(0, 0),
                   options.gaussian_sigma_px, options.gaussian_sigma_px,
                   cv::BORDER_REPLICATE);
  cv::Sobel(scratch->smooth, edges.gx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0,
            cv::BORDER_REPLICATE);
  cv::Sobel(scratch->smooth, edges.gy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0,
            cv::BORDER_REPLICATE);
  cv::magnitude(edges.gx, edges.gy, scratch->norm);

  // Non-maximum suppression and Devernay's sub-pixel correction. The index
  // image is -1 everywhere between calls: only the points' pixels are
  // reset after use, not the whole image.
  cv::Mat& index = scratch->index;
  if (index.rows != image.rows || index.cols != image.cols ||
      index.type() != CV_32S) {
    index.create(image.rows, image.cols, CV_32S);
    index.setTo(cv::Scalar(-1));
  }
  std::vector<EdgePoint>& points = scratch->candidates;
  SuppressNonMaxima(edges, scratch->norm, options, &index, &points);
  const std::vector<std::vector<int>> chains = LinkChains(points, index);
  for (const EdgePoint& e : points) index.at<int>(e.py, e.px) = -1;
  KeepChains(points, chains, options, image.rows, &edges);
}

}  // namespace zebrageo
