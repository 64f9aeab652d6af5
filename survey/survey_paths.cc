#include "survey/survey_paths.h"

#include <algorithm>
#include <cerrno>
#include <system_error>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

constexpr char kOptOut[] =
    "(zebrageo --allow-outside-paths accepts it for a trusted survey)";

}  // namespace

std::string SurveyFile::Problem() const {
  switch (state) {
    case SurveyFileState::kFile:
      return "";
    case SurveyFileState::kMissing:
      return "does not exist";
    case SurveyFileState::kFolder:
      return "is a folder, not a file";
    case SurveyFileState::kSymlinkLoop:
      return "is a loop of symbolic links (too many levels of symbolic links)";
    case SurveyFileState::kNotAFile:
      return "is not a regular file (a FIFO, device or socket)";
    case SurveyFileState::kAbsolute:
      return std::string(
                 "is an absolute path: a survey names its files relative to "
                 "its folder ") +
             kOptOut;
    case SurveyFileState::kOutside:
      return "resolves to " + resolved +
             ", outside the survey folder: a survey names only files inside "
             "it, symbolic links included " +
             kOptOut;
  }
  return "";
}

SurveyPaths::SurveyPaths(const std::string& survey_folder,
                         const SurveyPathOptions& options)
    : folder_(survey_folder), options_(options) {
  std::error_code error;
  root_ = fs::canonical(survey_folder, error);
  if (error || !fs::is_directory(root_, error)) {
    throw InputError(survey_folder, 0,
                     error ? "cannot open the survey folder: " + error.message()
                           : "not a folder (a survey is a folder with "
                             "survey.yaml)");
  }
}

bool SurveyPaths::Inside(const fs::path& resolved) const {
  // Component by component: /data/survey2 is not inside /data/survey.
  auto r = resolved.begin();
  for (auto root = root_.begin(); root != root_.end(); ++root, ++r) {
    if (r == resolved.end() || *r != *root) return false;
  }
  return true;
}

SurveyFile SurveyPaths::Resolve(const std::string& name) const {
  SurveyFile file;
  file.name = name;
  const fs::path relative(name);
  // operator/ with an absolute right side gives the right side: an allowed
  // absolute path is read as it is.
  file.path = (fs::path(folder_) / relative).string();
  const bool allowed_anywhere = options_.allow_outside_paths;
  if (relative.is_absolute() && !allowed_anywhere) {
    file.state = SurveyFileState::kAbsolute;
    file.resolved = relative.lexically_normal().string();
    return file;
  }
  std::error_code error;
  const fs::path resolved = fs::weakly_canonical(root_ / relative, error);
  if (error) {
    file.state = error.value() == ELOOP ? SurveyFileState::kSymlinkLoop
                                        : SurveyFileState::kMissing;
    return file;
  }
  file.resolved = resolved.string();
  if (!allowed_anywhere && !Inside(resolved)) {
    file.state = SurveyFileState::kOutside;
    return file;
  }
  const fs::file_status status = fs::status(resolved, error);
  if (error || status.type() == fs::file_type::not_found) {
    file.state = error.value() == ELOOP ? SurveyFileState::kSymlinkLoop
                                        : SurveyFileState::kMissing;
  } else if (status.type() == fs::file_type::directory) {
    file.state = SurveyFileState::kFolder;
  } else if (status.type() != fs::file_type::regular) {
    file.state = SurveyFileState::kNotAFile;
  } else {
    file.state = SurveyFileState::kFile;
  }
  return file;
}

}  // namespace zebrageo
