// reconstructed_lines.csv, the road lines of reconstruct --lines
// (road_lines.h): its row type, its line types, its reader and writer.
// Kept apart from the extractor so that the results contract can take it
// whole.
//
// Frames: body (FRD) metres; image coordinates are pixels of the ORIGINAL
// (distorted) images, (0, 0) the centre of the top-left pixel.
#ifndef ZEBRAGEO_RECONSTRUCTION_ROAD_LINES_IO_H_
#define ZEBRAGEO_RECONSTRUCTION_ROAD_LINES_IO_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace zebrageo {

enum class RoadLineType { kLaneSolid, kLaneDashed, kStopLine };
const char* RoadLineTypeName(RoadLineType type);  // lane_solid, ...

// reconstructed_lines.csv: one row per vertex of a line seen in one pair.
struct ReconstructedLinePoint {
  int64_t exposure_id = 0;
  int pair = 0;
  int64_t line_id = 0;  // unique within the file
  RoadLineType type = RoadLineType::kLaneSolid;
  int point = 0;  // 0.. along the line
  Eigen::Vector3d p_body = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance_body = Eigen::Matrix3d::Zero();
  Eigen::Vector2d uv_left = Eigen::Vector2d::Zero();
  Eigen::Vector2d uv_right = Eigen::Vector2d::Zero();
};

inline constexpr char kReconstructedLinesFile[] = "reconstructed_lines.csv";

void WriteReconstructedLines(const std::vector<ReconstructedLinePoint>& points,
                             const std::vector<std::string>& comments,
                             const std::string& path);

// Throws InputError naming the file and line (missing column, bad number,
// unknown type, negative variance).
std::vector<ReconstructedLinePoint> ReadReconstructedLines(
    const std::string& path, const std::string& display_name);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_ROAD_LINES_IO_H_
