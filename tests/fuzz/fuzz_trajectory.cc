// libFuzzer target: trajectory.csv.
#include "survey/trajectory.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  zebrageo::FuzzParser(data, size, [](const std::string& text) {
    const auto samples =
        zebrageo::ParseTrajectorySamples(text, "trajectory.csv");
    // Valid samples must also build a trajectory (frames, interpolation).
    const zebrageo::Trajectory trajectory(
        samples, zebrageo::LocalFrame(samples.front().position));
    zebrageo::Pose pose;
    trajectory.InterpolatePose(
        0.5 * (trajectory.start_time() + trajectory.end_time()), &pose);
  });
  return 0;
}
