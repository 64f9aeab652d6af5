// One command's use of a results folder: exclusive, and clean on error.
//
// Two zebrageo processes writing one results folder would interleave their
// stages (the slower overwrites the faster, with different options): a
// command that writes takes an exclusive flock(2) on RESULTS/.zebrageo.lock
// (the file holds the owner's pid, for the message; it stays, as removing
// it would race with a process that has just opened it). The kernel
// releases the lock when the process ends, even by SIGKILL.
//
// SURVEY_FORMAT.md: a survey that cannot be processed leaves no
// trajectory_corrected.csv, poses.csv, bands.geojson, gcp_residuals.csv or
// report.json. A session that ends without Succeeded() (an exception on any
// path: bad input, a failed stage, disk full while writing) removes them,
// with report.html, from the folder, but only once it holds the lock: a
// command refused because another one runs there never touches its files.
// Stage outputs (reconstructed_bands.csv...) stay, so a fixed survey
// resumes.
#ifndef ZEBRAGEO_PIPELINE_RESULTS_SESSION_H_
#define ZEBRAGEO_PIPELINE_RESULTS_SESSION_H_

#include <string>

namespace zebrageo {

inline constexpr char kResultsLockFile[] = ".zebrageo.lock";

class ResultsSession {
 public:
  enum class OnError { kRemoveContractOutputs, kKeepOutputs };

  // Locks `folder` now if it exists (so an earlier run's outputs can be
  // removed safely if this one fails); otherwise the folder is left
  // untouched until Open(). Throws UsageError when `folder` is a file or
  // another zebrageo process holds it.
  ResultsSession(std::string folder, OnError on_error);
  ~ResultsSession();
  ResultsSession(const ResultsSession&) = delete;
  ResultsSession& operator=(const ResultsSession&) = delete;

  // Creates the folder if needed and locks it (nothing when already
  // locked). Throws UsageError as the constructor, or when the folder
  // cannot be created.
  void Open();
  // Throws InputError naming the first stage file of the folder that
  // belongs to another survey than `survey_identity`'s
  // (survey/results_survey.h). Such a folder is not this command's to
  // clean: it is left untouched, whatever `on_error`.
  void RefuseAnotherSurvey(const std::string& survey_identity);
  // The command finished: its outputs stay.
  void Succeeded() { succeeded_ = true; }

 private:
  void Lock();

  std::string folder_;
  OnError on_error_;
  int lock_fd_ = -1;
  bool succeeded_ = false;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_RESULTS_SESSION_H_
