#include "survey/atomic_file.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

namespace zebrageo {
namespace {

constexpr char kTempMarker[] = ".tmp-";

// The fault-injection seam of atomic_file.h.
bool InjectedWriteFailure(const std::string& path) {
  const char* name = std::getenv("ZEBRAGEO_FAIL_WRITE");
  return name != nullptr && *name != '\0' &&
         std::filesystem::path(path).filename() == name;
}

}  // namespace

AtomicFile::AtomicFile(const std::string& path)
    : path_(path), temp_path_(path + kTempMarker + std::to_string(::getpid())) {
  out_.open(temp_path_, std::ios::binary | std::ios::trunc);
  if (!out_) {
    throw std::runtime_error("cannot create " + temp_path_ +
                             " (does the folder exist and is it writable?)");
  }
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::remove(temp_path_.c_str());
  }
}

void AtomicFile::Commit() {
  out_.flush();
  const bool written = static_cast<bool>(out_) && !InjectedWriteFailure(path_);
  out_.close();
  if (!written || out_.fail()) {
    std::remove(temp_path_.c_str());
    committed_ = true;  // nothing left to clean
    throw std::runtime_error("cannot write " + path_ + " (disk full?)");
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    std::remove(temp_path_.c_str());
    committed_ = true;
    throw std::runtime_error("cannot rename " + temp_path_ + " to " + path_);
  }
  committed_ = true;
}

void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write) {
  AtomicFile file(path);
  write(file.stream());
  file.Commit();
}

void RemoveStaleTemporaries(const std::string& folder) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    if (entry.path().filename().string().find(kTempMarker) !=
        std::string::npos) {
      std::filesystem::remove(entry.path(), error);
    }
  }
}

}  // namespace zebrageo
