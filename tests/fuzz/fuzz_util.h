// Shared by the libFuzzer targets: run a parser on arbitrary bytes. An
// InputError is the expected answer to garbage; any other exception, a
// crash or a sanitizer report is a bug and stops the fuzzer.
#ifndef ZEBRAGEO_TESTS_FUZZ_FUZZ_UTIL_H_
#define ZEBRAGEO_TESTS_FUZZ_FUZZ_UTIL_H_

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "survey/input_error.h"

namespace zebrageo {

template <typename Parse>
void FuzzParser(const uint8_t* data, size_t size, Parse parse) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    parse(text);
  } catch (const InputError&) {
    // Rejected with a message: the behaviour we want.
  }
}

// For readers that take a path: writes the bytes to a per-process file.
inline std::string WriteFuzzFile(const std::string& name,
                                 const std::string& text) {
  const std::string path =
      "/tmp/zebrageo-fuzz-" + std::to_string(::getpid()) + "-" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_FUZZ_FUZZ_UTIL_H_
