// libFuzzer target: rig.yaml.
#include "survey/rig.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  zebrageo::FuzzParser(data, size, [](const std::string& text) {
    zebrageo::ParseRig(text, "rig.yaml");
  });
  return 0;
}
