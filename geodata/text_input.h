// Reading another tool's text file (a calibration, a trajectory export)
// without trusting it to be one: the path may name a device (/dev/zero
// never ends), a binary file or something huge. What is read is capped,
// and binary data (a NUL byte, never in these text formats) is refused as
// soon as it is seen, with a message saying what the file is not.
#ifndef ZEBRAGEO_GEODATA_TEXT_INPUT_H_
#define ZEBRAGEO_GEODATA_TEXT_INPUT_H_

#include <cstdint>
#include <istream>
#include <string>

namespace zebrageo {

// A calibration file (Kalibr camchain, ROS camera_info, a mount) is a few
// kilobytes.
inline constexpr uint64_t kMaxCalibrationFileBytes = 1 << 20;
// A trajectory export: 200 Hz for 10 hours at ~150 bytes a line is 1 GB.
inline constexpr uint64_t kMaxTrajectoryTextBytes = uint64_t{4} << 30;

// The whole of `path` as text. Throws InputError naming `path`: it cannot
// be read, it holds a NUL byte ("not a <what>: binary data ...") or it is
// longer than `max_bytes` ("not a <what>: more than ...").
std::string ReadTextInput(const std::string& path, const std::string& what,
                          uint64_t max_bytes);

// Reads lines of a text stream with the same guards: a line longer than
// `max_line_bytes`, a NUL byte or more than `max_bytes` in all is an
// InputError naming `path` (and the line).
class BoundedLineReader {
 public:
  BoundedLineReader(std::istream* in, std::string path, std::string what,
                    uint64_t max_bytes, size_t max_line_bytes);
  // The next line without its '\n' (and '\r'); false at the end.
  bool Next(std::string* line);
  int line_number() const { return line_number_; }

 private:
  std::istream* in_;
  std::string path_;
  std::string what_;
  uint64_t max_bytes_;
  size_t max_line_bytes_;
  std::string buffer_;
  size_t position_ = 0;
  uint64_t bytes_read_ = 0;
  int line_number_ = 0;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_TEXT_INPUT_H_
