// libFuzzer target: Kalibr camchain.yaml and ROS camera_info
// (geodata/calibration_import.h).
#include "geodata/calibration_import.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  zebrageo::FuzzParser(data, size, [](const std::string& text) {
    const std::string path = zebrageo::WriteFuzzFile("calibration.yaml", text);
    try {
      zebrageo::ImportKalibrCamchain(path, Eigen::Isometry3d::Identity(), {});
    } catch (const zebrageo::InputError&) {
    }
    zebrageo::ImportRosCameraInfoPair(path, path, Eigen::Isometry3d::Identity(),
                                      {});
  });
  return 0;
}
