#include "reconstruction/band_modeling.h"

#include <glog/logging.h>

#include <cmath>

#include "reconstruction/band_pairs.h"
#include "reconstruction/crossing_regularity.h"
#include "reconstruction/hidden_ends.h"
#include "reconstruction/transversal_search.h"

namespace zebrageo {
namespace {

void LogBandPairs(const PlaneFrame& frame, const BandPairs& bands) {
  const int m_all = static_cast<int>(bands.pairs.size());
  for (int i = 0; i < m_all && VLOG_IS_ON(2); ++i) {
    const BandCandidate& pair = bands.pairs[i];
    const LongSide& lo = bands.sides[pair.lo];
    const LongSide& hi = bands.sides[pair.hi];
    const Eigen::Vector3d centre_body =
        frame.To3d(0.5 * (pair.begin + pair.end) * lo.direction_2d +
                   0.5 * (lo.lateral_m + hi.lateral_m) * lo.Normal2d());
    VLOG(2) << "band " << i << ": sides " << pair.lo << " " << pair.hi
            << " set " << lo.direction_set << " lateral " << lo.lateral_m << " "
            << hi.lateral_m << " extent " << pair.begin << " " << pair.end
            << " crossing " << bands.crossing_of[i] << " centre_body "
            << centre_body.transpose();
  }
}

// Whether a band direction (body frame) runs along the track, within 45
// degrees of the vehicle's forward axis.
bool AlongTrack(const Eigen::Vector3d& direction_body) {
  return std::abs(direction_body.normalized().x()) >= std::sqrt(0.5);
}

// Which seen pairs span more than their crossing's other seen pairs
// (LongerThanTheirCrossings): far away a band's long sides run on across the
// short stretch of road to a bicycle square in line with it, and the
// crossing's other bands, which may fail their own checks at that range,
// still show the crossing's length.
std::vector<char> OverlongPairs(const BandPairs& bands,
                                const BandOptions& options) {
  const std::vector<int> crossing_of(bands.crossing_of.begin(),
                                     bands.crossing_of.begin() + bands.seen);
  std::vector<double> length_m;
  for (int i = 0; i < bands.seen; ++i) {
    length_m.push_back(bands.pairs[i].end - bands.pairs[i].begin);
  }
  std::vector<char> overlong =
      LongerThanTheirCrossings(crossing_of, length_m, options);
  overlong.resize(bands.pairs.size(), 0);
  for (int i = 0; i < bands.seen; ++i) {
    // Only bands along the track (the road driven's crossings, where the
    // paint beside is): a side street's bands, across it and monoplotted
    // far aside, are cut by the image's edge in ways no other band
    // confirms (side_street_bands_test lost one).
    if (!AlongTrack(bands.sides[bands.pairs[i].lo].direction_body)) {
      overlong[i] = 0;
    }
    VLOG_IF(2, overlong[i]) << "band " << i << ": longer than its crossing's";
  }
  return overlong;
}

}  // namespace

std::vector<Band> ModelBands(const LongSideDetection& detection,
                             const PlaneFrame& frame,
                             const RoadRectification& rectification,
                             const EdgeMap edges[2],
                             const ZebraSpecification& zebra,
                             const BandOptions& options,
                             BandModelingDebug* debug) {
  // 1-2. Pairs of long sides, grouped into crossings and completed.
  const BandPairs bands = FindBandPairs(detection, frame, rectification, edges,
                                        zebra, options, debug);
  LogBandPairs(frame, bands);
  const std::vector<char> overlong =
      options.drop_overlong_bands ? OverlongPairs(bands, options)
                                  : std::vector<char>(bands.pairs.size(), 0);
  const int crossings = bands.crossings;
  const int m_all = static_cast<int>(bands.pairs.size());
  // 3. Approximate transversal sides of each crossing: regression on the
  // extremities of its longer long sides (seen bands only).
  const TransversalSearch search =
      ApproximateTransversalSides(bands, options, overlong);
  const BandContext context{detection, frame, rectification, edges, zebra,
                            options,   bands, search,        debug};

  // 4. Each band: plane, transversal sides, vertices; the directions of
  // the ends seen in this first pass.
  std::vector<EndDirectionObservation> observations;
  const KnownEnd none[2];
  std::vector<BandOutcome> outcomes(m_all);
  std::vector<Band> first(m_all);
  // A band whose ends are no paint ends may join a ladder's bars (issue
  // 52): modelled again with both ends taken on the bars' inner edges.
  std::vector<char> ladder(m_all, 0);
  for (int i = 0; i < m_all; ++i) {
    outcomes[i] = ModelBand(
        context, i, none,
        options.crossing_end_direction ? &observations : nullptr, &first[i]);
    if (outcomes[i] != BandOutcome::kBand && options.ladder_ends) {
      KnownEnd bars[2];
      for (KnownEnd& k : bars) k.ladder = true;
      Band band;
      if (ModelBand(context, i, bars,
                    options.crossing_end_direction ? &observations : nullptr,
                    &band) == BandOutcome::kBand) {
        outcomes[i] = BandOutcome::kBand;
        first[i] = band;
        ladder[i] = 1;
      }
    }
  }
  // 4b. The ends of a crossing's bands are parallel: the direction of its
  // ends, from every band seen in both images and weighted by range, is
  // far more precise than a far band's own (a 0.5 m end at 15 m spans a
  // few original pixels: its angle is noisy, and its two vertices move
  // apart, one forward, one back). Each band is modelled again with its
  // ends fitted along that direction.
  std::vector<Eigen::Vector2d> crossing_direction(crossings);
  std::vector<char> has_direction(crossings, 0);
  for (int c = 0; c < crossings && options.crossing_end_direction; ++c) {
    has_direction[c] = CrossingEndDirection(
        observations, c, options.min_end_direction_observations,
        &crossing_direction[c]);
  }
  std::vector<Band> result;
  std::vector<int> without_transversal;
  for (int i = 0; i < m_all; ++i) {
    Band band = first[i];
    BandOutcome outcome = outcomes[i];
    const int c = bands.crossing_of[i];
    if (has_direction[c]) {
      KnownEnd along_crossing[2];
      for (KnownEnd& k : along_crossing) {
        k.direction = &crossing_direction[c];
        k.ladder = ladder[i];
      }
      outcome = ModelBand(context, i, along_crossing, nullptr, &band);
    }
    if (overlong[i]) continue;
    if (outcome == BandOutcome::kBand) result.push_back(band);
    if (outcome == BandOutcome::kNoTransversal ||
        outcome == BandOutcome::kDisagreement) {
      without_transversal.push_back(i);
    }
  }
  if (options.infer_hidden_ends && !without_transversal.empty()) {
    // 5. Hidden ends: a vehicle parked before a crossing hides the end of
    // its outer bands; the crossing's end lines give them.
    InferHiddenEnds(context, without_transversal, crossing_direction,
                    has_direction, &result);
  }
  // 6. A band longer than its crossing's others runs on into paint beside.
  if (options.drop_overlong_bands) {
    std::vector<Band> along, across;
    for (Band& band : result) {
      (AlongTrack(band.vertices_body[3] - band.vertices_body[0]) ? along
                                                                 : across)
          .push_back(std::move(band));
    }
    result = WithoutOverlongBands(std::move(along), options);
    result.insert(result.end(), across.begin(), across.end());
  }
  return result;
}

}  // namespace zebrageo
