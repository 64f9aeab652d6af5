// libFuzzer target: the stage outputs a later stage reads
// (reconstructed_bands.csv, matches.csv), through their file readers.
#include <cstdio>

#include "survey/results.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  zebrageo::FuzzParser(data, size, [](const std::string& text) {
    const std::string path = zebrageo::WriteFuzzFile("stage.csv", text);
    try {
      zebrageo::ReadReconstructedBands(path, "reconstructed_bands.csv");
    } catch (const zebrageo::InputError&) {
    }
    try {
      zebrageo::ReadMatches(path, "matches.csv");
    } catch (const zebrageo::InputError&) {
    }
    std::remove(path.c_str());
  });
  return 0;
}
