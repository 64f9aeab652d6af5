// adjustment_bench: scaling of the trajectory adjustment with survey length.
//
//   adjustment_bench [--threads N] [--sizes 1000,5000,20000]
//       Synthetic surveys (adjustment/synthetic_survey.h: 10 m/s, an
//       exposure every 0.3 s, a crossing every 80 m, 2 m drift, --ties N
//       ideal tie points per exposure) of each size; prints the adjustment
//       time (2 threads by default, covariance off so the figure is the
//       adjustment alone) and the pose errors against truth.
//   adjustment_bench --observe SURVEY RESULTS [--seed N]
//       Writes ideal reconstructed_bands.csv and matches.csv for a simulated
//       survey with truth/ (true poses, 0.3 px / 1.5 cm noise), so `zebrageo
//       adjust` can be scored before the reconstruction and registration
//       stages work.
#include <glog/logging.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "adjustment/synthetic_survey.h"
#include "adjustment/trajectory_adjuster.h"

namespace zebrageo {
namespace {

struct Errors {
  double h = 0.0, v = 0.0, att = 0.0;
};

Errors Score(const SyntheticSurvey& survey,
             const std::vector<CameraPose>& poses) {
  const Trajectory truth(survey.truth_samples, survey.frame);
  double h2 = 0.0, v2 = 0.0, a2 = 0.0;
  int n = 0;
  for (const CameraPose& p : poses) {
    Pose pose;
    if (!truth.InterpolatePose(p.time, &pose)) continue;
    const Eigen::Isometry3d T =
        pose.T_enu_body() *
        survey.rig.cameras[survey.rig.FindCamera(p.camera)].T_body_cam;
    const Eigen::Vector3d d = p.p_enu - T.translation();
    const double angle =
        Eigen::AngleAxisd(Eigen::Quaterniond(T.linear()).inverse() *
                          p.q_enu_cam)
            .angle() *
        180.0 / M_PI;
    h2 += d.head<2>().squaredNorm();
    v2 += d.z() * d.z();
    a2 += angle * angle;
    ++n;
  }
  Errors e;
  if (n > 0) {
    e.h = std::sqrt(h2 / n);
    e.v = std::sqrt(v2 / n);
    e.att = std::sqrt(a2 / n);
  }
  return e;
}

int Main(int argc, char** argv) {
  int threads = 2;
  int ties = 0;
  uint64_t seed = 1;
  std::vector<int> sizes = {1000, 5000, 20000};
  std::vector<std::string> positional;
  bool observe = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--threads" && i + 1 < argc) {
      threads = std::atoi(argv[++i]);
    } else if (arg == "--ties" && i + 1 < argc) {
      ties = std::atoi(argv[++i]);
    } else if (arg == "--seed" && i + 1 < argc) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg == "--sizes" && i + 1 < argc) {
      sizes.clear();
      std::stringstream list(argv[++i]);
      std::string item;
      while (std::getline(list, item, ',')) sizes.push_back(std::stoi(item));
    } else if (arg == "--observe") {
      observe = true;
    } else if (arg == "-h" || arg == "--help") {
      std::printf(
          "usage: adjustment_bench [--threads N] [--sizes 1000,5000,20000] "
          "[--ties N]\n"
          "       adjustment_bench --observe SURVEY RESULTS [--seed N]\n");
      return 0;
    } else {
      positional.push_back(arg);
    }
  }
  if (observe) {
    if (positional.size() != 2) {
      std::fprintf(stderr, "--observe needs SURVEY RESULTS\n");
      return 2;
    }
    IdealObservationOptions options;
    options.seed = seed;
    WriteIdealStageOutputs(options, positional[0], positional[1]);
    std::printf("wrote ideal reconstructed_bands.csv and matches.csv in %s\n",
                positional[1].c_str());
    return 0;
  }

  std::printf("%9s %7s %9s %10s %9s %10s | %8s %8s %9s\n", "exposures", "knots",
              "vertices", "residuals", "time s", "s/1k exp", "H cm", "V cm",
              "att deg");
  for (int size : sizes) {
    SyntheticSurveyOptions survey_options;
    survey_options.seed = seed;
    survey_options.num_exposures = size;
    survey_options.database_offset_m = 0.05;
    survey_options.tie_points_per_exposure = ties;
    const SyntheticSurvey survey = MakeSyntheticSurvey(survey_options);
    const Trajectory trajectory(survey.measured_samples, survey.frame);
    AdjustmentInput input;
    input.rig = &survey.rig;
    input.frame = &survey.frame;
    input.trajectory = &trajectory;
    input.exposures = &survey.exposures;
    input.roadmarks = &survey.database;
    input.vertices = &survey.vertices;
    input.matches = &survey.matches;
    if (!survey.tie_tracks.empty()) input.tie_tracks = &survey.tie_tracks;
    AdjustmentOptions options;
    options.solver.num_threads = threads;
    options.compute_covariance = false;
    const auto start = std::chrono::steady_clock::now();
    const AdjustmentResult result = AdjustTrajectory(options, input);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    if (!result.summary.IsUsable()) {
      std::printf("%9d: NOT usable: %s\n", size,
                  result.summary.message.c_str());
      return 1;
    }
    const Errors e = Score(survey, result.camera_poses);
    std::printf("%9d %7d %9zu %10d %9.2f %10.2f | %8.2f %8.2f %9.4f\n", size,
                result.summary.num_knots, survey.vertices.size(),
                result.summary.num_residuals, seconds, 1000.0 * seconds / size,
                100.0 * e.h, 100.0 * e.v, e.att);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace
}  // namespace zebrageo

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = 1;
  return zebrageo::Main(argc, argv);
}
