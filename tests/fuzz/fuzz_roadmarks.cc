// libFuzzer target: roadmarks.geojson.
#include "survey/roadmarks.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  zebrageo::FuzzParser(data, size, [](const std::string& text) {
    zebrageo::ParseRoadmarks(text, "roadmarks.geojson");
  });
  return 0;
}
