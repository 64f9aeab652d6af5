#include "geodata/text_input.h"

#include <array>
#include <cstring>
#include <fstream>
#include <sstream>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

std::string Article(const std::string& what) {
  const bool vowel = !what.empty() && std::strchr("aeiouAEIOU", what[0]);
  return vowel ? "an " : "a ";
}

std::string SizeText(uint64_t bytes) {
  std::ostringstream text;
  if (bytes >= (uint64_t{1} << 30)) {
    text << (bytes >> 30) << " GiB";
  } else if (bytes >= (uint64_t{1} << 20)) {
    text << (bytes >> 20) << " MiB";
  } else {
    text << bytes << " bytes";
  }
  return text.str();
}

[[noreturn]] void NotA(const std::string& path, int line,
                       const std::string& what, const std::string& why) {
  throw InputError(path, line, "not " + Article(what) + what + ": " + why);
}

[[noreturn]] void BinaryData(const std::string& path, int line,
                             const std::string& what, uint64_t offset) {
  NotA(path, line, what,
       "binary data (a NUL byte at byte " + std::to_string(offset) + ")");
}

[[noreturn]] void TooLong(const std::string& path, const std::string& what,
                          uint64_t max_bytes) {
  NotA(path, 0, what, "longer than " + SizeText(max_bytes));
}

}  // namespace

std::string ReadTextInput(const std::string& path, const std::string& what,
                          uint64_t max_bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot read the " + what);
  std::string text;
  std::array<char, 1 << 16> chunk;
  while (in) {
    in.read(chunk.data(), chunk.size());
    const std::streamsize got = in.gcount();
    if (got <= 0) break;
    const void* nul = std::memchr(chunk.data(), '\0', got);
    if (nul != nullptr) {
      BinaryData(path, 0, what,
                 text.size() + (static_cast<const char*>(nul) - chunk.data()));
    }
    if (text.size() + static_cast<uint64_t>(got) > max_bytes) {
      TooLong(path, what, max_bytes);
    }
    text.append(chunk.data(), got);
  }
  if (in.bad()) throw InputError(path, 0, "read error in the " + what);
  return text;
}

BoundedLineReader::BoundedLineReader(std::istream* in, std::string path,
                                     std::string what, uint64_t max_bytes,
                                     size_t max_line_bytes)
    : in_(in),
      path_(std::move(path)),
      what_(std::move(what)),
      max_bytes_(max_bytes),
      max_line_bytes_(max_line_bytes) {}

bool BoundedLineReader::Next(std::string* line) {
  line->clear();
  bool any = false;
  while (true) {
    if (position_ == buffer_.size()) {
      buffer_.resize(1 << 16);
      in_->read(buffer_.data(), buffer_.size());
      buffer_.resize(static_cast<size_t>(in_->gcount()));
      position_ = 0;
      if (buffer_.empty()) break;
    }
    const size_t end = buffer_.find('\n', position_);
    const size_t stop = end == std::string::npos ? buffer_.size() : end;
    const size_t taken = stop - position_;
    const size_t nul = buffer_.find('\0', position_);
    if (nul < stop) {
      BinaryData(path_, line_number_ + 1, what_, bytes_read_ + nul - position_);
    }
    any = true;
    bytes_read_ += taken + (end == std::string::npos ? 0 : 1);
    if (bytes_read_ > max_bytes_) TooLong(path_, what_, max_bytes_);
    if (line->size() + taken > max_line_bytes_) {
      NotA(path_, line_number_ + 1, what_,
           "a line longer than " + SizeText(max_line_bytes_));
    }
    line->append(buffer_, position_, taken);
    position_ = stop;
    if (end != std::string::npos) {
      ++position_;
      break;
    }
  }
  if (!any) return false;
  ++line_number_;
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return true;
}

}  // namespace zebrageo
