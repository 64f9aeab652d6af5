// The survey the per-stereo-pair benches time: a 60 m urban street with one
// zebra crossing, parked vehicles and facades (1280 x 960 images), simulated
// into a temporary folder (removed at exit) unless $ZEBRAGEO_BENCH_SURVEY
// names one. Its images are decoded up front, and the road plane estimated
// as the zebra stage does, so that only the stage under test is timed.
#ifndef ZEBRAGEO_BENCH_BENCH_SURVEY_H_
#define ZEBRAGEO_BENCH_BENCH_SURVEY_H_

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "reconstruction/road_rectification.h"
#include "simulator/simulator.h"
#include "survey/survey.h"

namespace zebrageo {

struct BenchSurvey {
  // `name` names the temporary folder; `customise` may change the
  // simulation (e.g. a stop line before the crossing).
  explicit BenchSurvey(
      const std::string& name,
      const std::function<void(SimulationOptions*)>& customise = nullptr);
  ~BenchSurvey();
  BenchSurvey(const BenchSurvey&) = delete;
  BenchSurvey& operator=(const BenchSurvey&) = delete;

  std::string folder;
  bool owns_folder = false;
  std::unique_ptr<Survey> survey;
  RoadPlane road;  // from the first 8 exposures, one thread
  std::vector<std::pair<cv::Mat, cv::Mat>> images;  // first stereo pair
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_BENCH_BENCH_SURVEY_H_
