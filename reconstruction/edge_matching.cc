#include "reconstruction/edge_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Candidate {
  int i = 0;  // position in the row's left list
  int j = 0;  // position in the row's right list
  double x_right = 0.0;
  double ncc = 0.0;
  double weight = 0.0;  // 2 * occlusion_cost - cost: what matching saves
};

// Normalised cross-correlation of the (2r+1)^2 windows centred on the left
// edge pixel and on the right edge at the same sub-pixel offset (the right
// window is resampled linearly along the row). -1 when a window leaves the
// image or is flat.
double WindowNcc(const cv::Mat& left, const cv::Mat& right, double x_left,
                 double x_right, int row, int r) {
  const int xl = static_cast<int>(std::lround(x_left));
  const double xr0 = x_right + (xl - x_left);
  const int xr = static_cast<int>(std::floor(xr0));
  const float f = static_cast<float>(xr0 - xr);
  if (row - r < 0 || row + r >= left.rows || xl - r < 0 ||
      xl + r >= left.cols || xr - r < 0 || xr + r + 1 >= right.cols) {
    return -1.0;
  }
  double sl = 0, sr = 0, sll = 0, srr = 0, slr = 0;
  for (int dy = -r; dy <= r; ++dy) {
    const float* pl = left.ptr<float>(row + dy) + xl;
    const float* pr = right.ptr<float>(row + dy) + xr;
    for (int dx = -r; dx <= r; ++dx) {
      const float a = pl[dx];
      const float b = (1.0f - f) * pr[dx] + f * pr[dx + 1];
      sl += a;
      sr += b;
      sll += a * a;
      srr += b * b;
      slr += a * b;
    }
  }
  const double n = (2 * r + 1) * (2 * r + 1);
  const double vl = sll - sl * sl / n;
  const double vr = srr - sr * sr / n;
  if (vl < 1e-3 * n || vr < 1e-3 * n) return -1.0;
  return (slr - sl * sr / n) / std::sqrt(vl * vr);
}

// Chain points usable for matching: not too close to the rows' direction.
bool Matchable(const EdgePoint& e, double min_sin) {
  return std::abs(e.gx) >= min_sin * e.norm;
}

// Local disparity of every point of every left chain: the median of the
// matched disparities within +-half_window chain positions (NaN when fewer
// than 3).
// The window slides along the chain with its values kept sorted (one
// insertion and one removal per step), so the median is read off instead
// of selected again from the whole window at every point: the same upper
// median as Median().
std::vector<double> ChainDisparities(const EdgeMap& left,
                                     const std::vector<double>& disparity,
                                     int half_window) {
  std::vector<double> reference(left.points.size(), kNaN);
  std::vector<double> window;  // sorted
  for (const std::vector<int>& chain : left.chains) {
    const int n = static_cast<int>(chain.size());
    window.clear();
    auto insert = [&](int m) {
      const double d = disparity[chain[m]];
      if (std::isnan(d)) return;
      window.insert(std::upper_bound(window.begin(), window.end(), d), d);
    };
    auto remove = [&](int m) {
      const double d = disparity[chain[m]];
      if (std::isnan(d)) return;
      window.erase(std::lower_bound(window.begin(), window.end(), d));
    };
    for (int m = 0; m <= std::min(n - 1, half_window); ++m) insert(m);
    for (int k = 0; k < n; ++k) {
      // window: positions max(0, k - half_window) .. min(n - 1, k +
      // half_window).
      if (window.size() >= 3) reference[chain[k]] = window[window.size() / 2];
      if (k - half_window >= 0) remove(k - half_window);
      if (k + 1 + half_window < n) insert(k + 1 + half_window);
    }
  }
  return reference;
}

// Largest-weight strictly increasing (in left and right order) subset of
// the candidates: the dynamic programming of the ordering constraint,
// O(K log n) with a Fenwick tree of prefix maxima over right positions.
std::vector<int> BestOrderedMatching(const std::vector<Candidate>& candidates,
                                     int num_right) {
  std::vector<std::pair<double, int>> tree(num_right + 1, {0.0, -1});
  auto query = [&](int j) {  // best over right positions < j
    std::pair<double, int> best(0.0, -1);
    for (int k = j; k > 0; k -= k & -k) {
      if (tree[k].first > best.first) best = tree[k];
    }
    return best;
  };
  auto update = [&](int j, std::pair<double, int> value) {
    for (int k = j + 1; k <= num_right; k += k & -k) {
      if (value.first > tree[k].first) tree[k] = value;
    }
  };
  const int n = static_cast<int>(candidates.size());
  std::vector<double> total(n);
  std::vector<int> parent(n, -1);
  for (int begin = 0; begin < n;) {
    int end = begin;
    while (end < n && candidates[end].i == candidates[begin].i) ++end;
    for (int c = begin; c < end; ++c) {
      const std::pair<double, int> best = query(candidates[c].j);
      total[c] = best.first + candidates[c].weight;
      parent[c] = best.second;
    }
    for (int c = begin; c < end; ++c) update(candidates[c].j, {total[c], c});
    begin = end;
  }
  int best = -1;
  double best_total = 0.0;
  for (int c = 0; c < n; ++c) {
    if (total[c] > best_total) {
      best_total = total[c];
      best = c;
    }
  }
  std::vector<int> chosen;
  for (int c = best; c >= 0; c = parent[c]) chosen.push_back(c);
  std::reverse(chosen.begin(), chosen.end());
  return chosen;
}

class RowMatcher {
 public:
  RowMatcher(const cv::Mat& left_image, const cv::Mat& right_image,
             const EdgeMap& left, const EdgeMap& right,
             const DisparityRange& range, const MatchingOptions& options)
      : left_image_(left_image),
        right_image_(right_image),
        left_(left),
        right_(right),
        range_(range),
        options_(options),
        min_sin_(std::sin(options.min_epipolar_angle_rad)),
        min_cos_(std::cos(options.max_gradient_angle_rad)) {}

  // Matches of pixel row `row`; `reference` (may be null) holds the chain
  // disparity of each left point for the continuity term.
  void MatchRow(int row, const std::vector<double>* reference,
                std::vector<EdgeMatch>* matches) {
    lefts_.clear();
    rights_.clear();
    for (int p = left_.row_begin[row]; p < left_.row_begin[row + 1]; ++p) {
      if (Matchable(left_.points[p], min_sin_)) lefts_.push_back(p);
    }
    for (int p = right_.row_begin[row]; p < right_.row_begin[row + 1]; ++p) {
      if (Matchable(right_.points[p], min_sin_)) rights_.push_back(p);
    }
    if (lefts_.empty() || rights_.empty()) return;
    if (reference == nullptr) {
      FindCandidates(row);
    } else {
      WeighWithContinuity(row, *reference);
    }
    for (int c :
         BestOrderedMatching(candidates_, static_cast<int>(rights_.size()))) {
      const Candidate& candidate = candidates_[c];
      EdgeMatch match;
      match.left = lefts_[candidate.i];
      match.right = rights_[candidate.j];
      match.x_left = left_.points[match.left].x;
      match.y = left_.points[match.left].y;
      match.x_right = candidate.x_right;
      match.ncc = candidate.ncc;
      matches->push_back(match);
    }
  }

 private:
  // Pass 1: the candidates of the row (lefts_, rights_), weighed without
  // continuity, into candidates_; they are also kept for pass 2, whose
  // candidates are among them (its cost only adds the continuity term), so
  // that their correlation windows are computed once.
  void FindCandidates(int row) {
    candidates_.clear();
    const double twice_occlusion = 2.0 * options_.occlusion_cost;
    for (int i = 0; i < static_cast<int>(lefts_.size()); ++i) {
      const EdgePoint& l = left_.points[lefts_[i]];
      double d_min, d_max;
      if (!range_(l.x, l.y, &d_min, &d_max)) continue;
      // Right points are sorted by x: scan the window x_l - d_max - 2 ..
      // x_l - d_min + 2 (the chain crossing moves x by < 2 px).
      const double x_low = l.x - d_max - 2.0;
      const double x_high = l.x - d_min + 2.0;
      auto first = std::lower_bound(
          rights_.begin(), rights_.end(), x_low,
          [&](int p, double x) { return right_.points[p].x < x; });
      for (auto it = first; it != rights_.end(); ++it) {
        const EdgePoint& r = right_.points[*it];
        if (r.x > x_high) break;
        if (l.gx * r.gx + l.gy * r.gy < min_cos_ * l.norm * r.norm) continue;
        const double x_right = ChainCrossing(right_, *it, l.y);
        const double d = l.x - x_right;
        if (d < d_min || d > d_max) continue;
        const double ncc = WindowNcc(left_image_, right_image_, l.x, x_right,
                                     row, options_.window_radius_px);
        if (ncc < options_.min_ncc) continue;
        const double cost = 1.0 - ncc;
        const double weight = twice_occlusion - cost;
        if (weight <= 0.0) continue;
        Candidate c;
        c.i = i;
        c.j = static_cast<int>(it - rights_.begin());
        c.x_right = x_right;
        c.ncc = ncc;
        c.weight = weight;
        candidates_.push_back(c);
      }
    }
    first_pass_.emplace_back(row, candidates_);
  }

  // Pass 2: the row's pass-1 candidates (rows come in the same order)
  // weighed again with the continuity term, into candidates_.
  void WeighWithContinuity(int row, const std::vector<double>& reference) {
    candidates_.clear();
    while (next_row_ < first_pass_.size() &&
           first_pass_[next_row_].first < row) {
      ++next_row_;
    }
    if (next_row_ == first_pass_.size() ||
        first_pass_[next_row_].first != row) {
      return;
    }
    const double twice_occlusion = 2.0 * options_.occlusion_cost;
    for (const Candidate& found : first_pass_[next_row_].second) {
      const double d = left_.points[lefts_[found.i]].x - found.x_right;
      double cost = 1.0 - found.ncc;
      const double ref = reference[lefts_[found.i]];
      const double deviation =
          std::isnan(ref) ? 0.5
                          : std::min(1.0, std::abs(d - ref) /
                                              options_.continuity_tolerance_px);
      cost += options_.continuity_weight * deviation;
      const double weight = twice_occlusion - cost;
      if (weight <= 0.0) continue;
      Candidate c = found;
      c.weight = weight;
      candidates_.push_back(c);
    }
  }

  const cv::Mat& left_image_;
  const cv::Mat& right_image_;
  const EdgeMap& left_;
  const EdgeMap& right_;
  const DisparityRange& range_;
  const MatchingOptions& options_;
  const double min_sin_;
  const double min_cos_;
  std::vector<int> lefts_;
  std::vector<int> rights_;
  std::vector<Candidate> candidates_;
  // Pass 1's candidates of each row that had some, in row order.
  std::vector<std::pair<int, std::vector<Candidate>>> first_pass_;
  size_t next_row_ = 0;
};

}  // namespace

std::string MatchingOptions::Check() const {
  OptionCheck check;
  OPTION_IN(check, window_radius_px, "[", 1, 15, "]");
  OPTION_IN(check, min_ncc, "(", -1.0, 1.0, ")");
  OPTION_GT(check, occlusion_cost, 0.0);
  OPTION_IN(check, max_gradient_angle_rad, "(", 0.0, 1.6, ")");
  OPTION_IN(check, min_epipolar_angle_rad, "[", 0.0, 1.5, ")");
  OPTION_GE(check, continuity_weight, 0.0);
  OPTION_GT(check, continuity_tolerance_px, 0.0);
  OPTION_GE(check, continuity_half_window, 1);
  OPTION_GE(check, min_matches_per_chain, 1);
  return check.problem();
}

double ChainCrossing(const EdgeMap& edges, int j, double y) {
  const EdgePoint& e = edges.points[j];
  if (std::abs(e.y - y) < 1e-6) return e.x;
  if (e.chain >= 0) {
    const std::vector<int>& chain = edges.chains[e.chain];
    const int k = e.index_in_chain;
    const int order[4] = {k - 1, k, k - 2, k + 1};
    for (int s : order) {
      if (s < 0 || s + 1 >= static_cast<int>(chain.size())) continue;
      const EdgePoint& a = edges.points[chain[s]];
      const EdgePoint& b = edges.points[chain[s + 1]];
      if (a.y == b.y || (a.y - y) * (b.y - y) > 0.0) continue;
      const double t = (y - a.y) / (b.y - a.y);
      return a.x + t * (b.x - a.x);
    }
  }
  if (std::abs(e.gx) > 1e-6) return e.x - e.gy / e.gx * (y - e.y);
  return e.x;
}

std::vector<EdgeMatch> MatchEdges(const cv::Mat& left_image,
                                  const cv::Mat& right_image,
                                  const EdgeMap& left, const EdgeMap& right,
                                  const DisparityRange& range,
                                  const MatchingOptions& options) {
  RowMatcher matcher(left_image, right_image, left, right, range, options);
  const int rows = std::min(left.height, right.height);
  // Pass 1: rows independently.
  std::vector<EdgeMatch> first;
  for (int row = 0; row < rows; ++row) matcher.MatchRow(row, nullptr, &first);
  std::vector<double> disparity(left.points.size(), kNaN);
  for (const EdgeMatch& m : first) disparity[m.left] = m.x_left - m.x_right;
  const std::vector<double> reference =
      ChainDisparities(left, disparity, options.continuity_half_window);

  // Pass 2: with figural continuity along the left chains.
  std::vector<EdgeMatch> second;
  for (int row = 0; row < rows; ++row) {
    matcher.MatchRow(row, &reference, &second);
  }
  std::fill(disparity.begin(), disparity.end(), kNaN);
  for (const EdgeMatch& m : second) disparity[m.left] = m.x_left - m.x_right;
  const std::vector<double> local =
      ChainDisparities(left, disparity, options.continuity_half_window);

  // Keep matches that agree with their chain, on chains with enough of them.
  std::vector<int> per_chain(left.chains.size(), 0);
  std::vector<char> keep(second.size(), 0);
  for (size_t k = 0; k < second.size(); ++k) {
    const EdgeMatch& m = second[k];
    const double ref = local[m.left];
    if (std::isnan(ref) || std::abs(m.x_left - m.x_right - ref) >
                               options.continuity_tolerance_px) {
      continue;
    }
    keep[k] = 1;
    ++per_chain[left.points[m.left].chain];
  }
  std::vector<EdgeMatch> result;
  for (size_t k = 0; k < second.size(); ++k) {
    if (keep[k] && per_chain[left.points[second[k].left].chain] >=
                       options.min_matches_per_chain) {
      result.push_back(second[k]);
    }
  }
  return result;
}

}  // namespace zebrageo
