#include "pipeline/results_session.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>

#include "pipeline/exit_codes.h"
#include "pipeline/stage_results.h"
#include "survey/results.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// What the lock file says about its owner ("pid 1234"), or "".
std::string OwnerOf(int fd) {
  char buffer[64] = {};
  const ssize_t size = ::pread(fd, buffer, sizeof(buffer) - 1, 0);
  if (size <= 0) return "";
  std::string text(buffer, static_cast<size_t>(size));
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) {
    text.pop_back();
  }
  return text;
}

void RemoveContractOutputs(const std::string& folder) {
  for (const char* name :
       {kTrajectoryCorrectedFile, kPosesFile, kBandsGeoJsonFile,
        kGcpResidualsFile, kReportJsonFile, kReportHtmlFile}) {
    std::error_code ignored;
    fs::remove(fs::path(folder) / name, ignored);
  }
}

}  // namespace

ResultsSession::ResultsSession(std::string folder, OnError on_error)
    : folder_(std::move(folder)), on_error_(on_error) {
  std::error_code error;
  const fs::file_status status = fs::status(folder_, error);
  if (fs::exists(status) && !fs::is_directory(status)) {
    throw UsageError("results folder " + folder_ +
                     " is a file, not a folder: choose another -o");
  }
  if (fs::is_directory(status)) Lock();
}

ResultsSession::~ResultsSession() {
  if (lock_fd_ < 0) return;
  if (!succeeded_ && on_error_ == OnError::kRemoveContractOutputs) {
    RemoveContractOutputs(folder_);
  }
  ::close(lock_fd_);  // releases the flock
}

void ResultsSession::Open() {
  if (lock_fd_ >= 0) return;
  std::error_code error;
  fs::create_directories(folder_, error);
  if (error || !fs::is_directory(folder_)) {
    throw UsageError("cannot create the results folder " + folder_ + ": " +
                     (error ? error.message() : "not a folder"));
  }
  Lock();
}

void ResultsSession::RefuseAnotherSurvey(const std::string& survey_identity) {
  std::error_code error;
  if (!fs::is_directory(folder_, error)) return;
  try {
    CheckStageFilesBelongTo(folder_, survey_identity);
  } catch (...) {
    on_error_ = OnError::kKeepOutputs;
    throw;
  }
}

void ResultsSession::Lock() {
  const std::string path = (fs::path(folder_) / kResultsLockFile).string();
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw UsageError("cannot write to the results folder " + folder_ + ": " +
                     path + ": " + std::strerror(errno));
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int lock_errno = errno;
    const std::string owner = OwnerOf(fd);
    ::close(fd);
    if (lock_errno == EWOULDBLOCK) {
      throw UsageError("results folder " + folder_ +
                       " is in use by another zebrageo process" +
                       (owner.empty() ? "" : " (" + owner + ")") +
                       ": wait for it to finish or choose another -o");
    }
    throw UsageError("cannot lock the results folder " + folder_ + ": " +
                     std::strerror(lock_errno));
  }
  // The owner's pid, for the message of a process refused the lock.
  const std::string owner = "pid " + std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, owner.data(), owner.size(), 0) !=
                                     static_cast<ssize_t>(owner.size())) {
    // Disk full: the lock holds all the same; only the message loses the pid.
  }
  lock_fd_ = fd;
}

}  // namespace zebrageo
