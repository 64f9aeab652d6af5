// FNV-1a, 64 bits: a hash that is the same on every compiler and run
// (std::hash is not), for fingerprints and identities written to files.
#ifndef ZEBRAGEO_SURVEY_FNV_HASH_H_
#define ZEBRAGEO_SURVEY_FNV_HASH_H_

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace zebrageo {

inline constexpr uint64_t kFnv1aOffset = 14695981039346656037ull;

// `hash` with `size` bytes of `data` mixed in (start from kFnv1aOffset).
inline uint64_t Fnv1a(const char* data, size_t size,
                      uint64_t hash = kFnv1aOffset) {
  constexpr uint64_t kPrime = 1099511628211ull;
  for (size_t i = 0; i < size; ++i) {
    hash = (hash ^ static_cast<unsigned char>(data[i])) * kPrime;
  }
  return hash;
}
inline uint64_t Fnv1a(const std::string& text, uint64_t hash = kFnv1aOffset) {
  return Fnv1a(text.data(), text.size(), hash);
}

// `hash` as 16 lower-case hex digits.
inline std::string Hex16(uint64_t hash) {
  char buffer[17];
  std::snprintf(buffer, sizeof(buffer), "%016llx",
                static_cast<unsigned long long>(hash));
  return buffer;
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_FNV_HASH_H_
