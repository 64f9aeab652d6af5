// The aerial-derived road-mark database (roadmarks.geojson, RFC 7946).
//
// One Polygon Feature per zebra band: a ring of 5 [lon, lat, h] positions
// (4 corners counter-clockwise seen from above, then the first again), with
// properties crossing_id (string), band (int, 1-based across the crossing),
// sigma_xy (m, per axis), sigma_z (m). LineString features with a `type`
// (lane_solid, lane_dashed, stop_line, ...) are road lines. Other features
// are ignored.
#ifndef ZEBRAGEO_SURVEY_ROADMARKS_H_
#define ZEBRAGEO_SURVEY_ROADMARKS_H_

#include <array>
#include <string>
#include <vector>

#include "survey/geodesy.h"

namespace zebrageo {

struct RoadmarkBand {
  std::string crossing_id;
  int band = 0;
  // In the file's ring order (db_vertex = index here); the format says
  // counter-clockwise from above, but the reader neither checks nor reorders.
  std::array<Geodetic, 4> corners;
  double sigma_xy_m = 0.0;
  double sigma_z_m = 0.0;
  // False for a band of a 2D layer (survey/roadmark_layer.h): its corners'
  // heights are a guess, with a wide sigma_z_m.
  bool height_known = true;
};

struct RoadmarkLine {
  std::string id;    // feature property "id" if any, else "line-<index>"
  std::string type;  // e.g. lane_solid, lane_dashed, stop_line
  std::vector<Geodetic> points;
  double sigma_xy_m = 0.0;
  double sigma_z_m = 0.0;
};

struct RoadmarkDatabase {
  std::vector<RoadmarkBand> bands;
  std::vector<RoadmarkLine> lines;
};

// Reads a GeoJSON FeatureCollection. Throws InputError with the line of the
// offending feature: malformed JSON (with its line), not a
// FeatureCollection, a band ring that is not 5 positions or not closed, a
// degenerate band (repeated corners, zero area, self-intersecting), missing
// or mistyped properties, non-finite coordinates, two bands with the same
// (crossing_id, band).
RoadmarkDatabase ReadRoadmarks(const std::string& path,
                               const std::string& display_name);
RoadmarkDatabase ParseRoadmarks(const std::string& text,
                                const std::string& display_name);
// Writes a database atomically: rings closed, corners in the stored order,
// one feature per line, numbers with every digit (round trip exact).
void WriteRoadmarks(const RoadmarkDatabase& database, const std::string& path);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_ROADMARKS_H_
