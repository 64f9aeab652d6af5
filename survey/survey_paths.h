// The files a survey names (survey.yaml, exposures.csv), resolved and
// confined to the survey folder.
//
// SURVEY_FORMAT.md: every file a survey names is a path relative to the
// survey folder and resolves inside it, symbolic links included; an absolute
// path or one that leaves the folder is an input error. A service that
// processes surveys from others must not be made to read /etc/shadow, or
// another customer's images, through a survey's file names. Resolution
// follows every symbolic link (std::filesystem::weakly_canonical), so a link
// inside the folder that points out of it is refused like "../x".
#ifndef ZEBRAGEO_SURVEY_SURVEY_PATHS_H_
#define ZEBRAGEO_SURVEY_SURVEY_PATHS_H_

#include <filesystem>
#include <string>

namespace zebrageo {

struct SurveyPathOptions {
  // Accept absolute paths and paths that resolve outside the survey folder
  // (`--allow-outside-paths`): for trusted surveys on one's own machine,
  // e.g. images linked from a shared pool. Never for surveys from others.
  bool allow_outside_paths = false;
};

// What a file name of a survey resolves to.
enum class SurveyFileState {
  kFile,         // a regular file inside the folder (or allowed outside)
  kMissing,      // nothing there
  kFolder,       // a folder where a file is expected
  kSymlinkLoop,  // symbolic links that point at each other
  kNotAFile,     // a FIFO, device or socket: reading it could block forever
  kAbsolute,     // an absolute path (refused unless allowed)
  kOutside,      // resolves outside the survey folder (refused unless allowed)
};

struct SurveyFile {
  SurveyFileState state = SurveyFileState::kMissing;
  std::string name;      // as the survey names it
  std::string path;      // survey folder / name: what readers open
  std::string resolved;  // symbolic links and ".." resolved ("" for a loop)

  bool ok() const { return state == SurveyFileState::kFile; }
  // Refused whatever else holds: absolute or outside the folder.
  bool escapes() const {
    return state == SurveyFileState::kAbsolute ||
           state == SurveyFileState::kOutside;
  }
  // What is wrong, as the end of a sentence about the file: "does not
  // exist", "is a folder, not a file", "resolves to /etc/passwd, outside the
  // survey folder ..."; "" when ok().
  std::string Problem() const;
};

class SurveyPaths {
 public:
  // `survey_folder` as given on the command line. Throws InputError when it
  // is not an existing folder.
  SurveyPaths(const std::string& survey_folder,
              const SurveyPathOptions& options);

  // Resolves `name` (relative to the survey folder). Never throws; the
  // caller decides whether a state is an error (a manifest file) or a
  // warning (a missing image).
  SurveyFile Resolve(const std::string& name) const;

  const SurveyPathOptions& options() const { return options_; }

 private:
  bool Inside(const std::filesystem::path& resolved) const;

  std::string folder_;
  std::filesystem::path root_;  // canonical survey folder
  SurveyPathOptions options_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_SURVEY_PATHS_H_
