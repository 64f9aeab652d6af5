// libFuzzer target: exposures.csv, against a two-camera rig.
#include "survey/exposures.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const zebrageo::Rig* const rig = [] {
    auto* r = new zebrageo::Rig;
    r->cameras.resize(2);
    r->cameras[0].camera = zebrageo::Camera("left", 640, 480, 500, 500, 320,
                                            240, {0, 0, 0, 0, 0});
    r->cameras[1].camera = zebrageo::Camera("right", 640, 480, 500, 500, 320,
                                            240, {0, 0, 0, 0, 0});
    r->stereo_pairs.push_back({0, 1});
    return r;
  }();
  zebrageo::FuzzParser(data, size, [](const std::string& text) {
    zebrageo::ParseExposures(text, "exposures.csv", *rig);
  });
  return 0;
}
