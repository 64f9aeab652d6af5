// Which survey a results folder's stage files belong to.
//
// A stage file (reconstructed_bands.csv, reconstructed_lines.csv,
// matches.csv, crossing_decisions.csv) names exposures by their
// exposure_id, a label that only means something in the survey whose
// exposures.csv wrote it: the stage files of another survey, or of the same
// drive with its exposures renumbered, read as this survey's would attach
// vertices to the wrong instants. So each stage writer puts the survey's
// identity (a hash of its exposures' ids and times, which is what the
// files' exposure_id refers to) in a leading comment, "# survey: HEX", and
// each command that reads a stage file with a survey compares it: another
// identity is an InputError naming the file. A file without one (written by
// a version before the identity) is read with a warning, as before.
#ifndef ZEBRAGEO_SURVEY_RESULTS_SURVEY_H_
#define ZEBRAGEO_SURVEY_RESULTS_SURVEY_H_

#include <string>
#include <vector>

#include "survey/exposures.h"

namespace zebrageo {

// 16 hex digits: a 64-bit FNV-1a hash of every exposure's id and exact
// time, in the table's order (sorted by time, then id). Image paths and
// cameras are not in it: moving the images keeps the survey's identity.
std::string SurveyIdentity(const ExposureTable& exposures);

// The comment a stage writer adds ("survey: HEX"; the writer adds "# ").
std::string SurveyIdentityComment(const std::string& identity);
// `comments` with the identity comment of `exposures`' survey first.
std::vector<std::string> WithSurveyIdentity(const ExposureTable& exposures,
                                            std::vector<std::string> comments);

struct StageFileSurvey {
  std::string identity;  // "" when the file names none
  int line = 0;          // of the comment, 1-based
};
// The identity a stage file's leading comment lines name. Reads the '#'
// lines before the header only, and at most 64 KiB. Throws InputError when
// the file cannot be opened.
StageFileSurvey ReadStageFileSurvey(const std::string& path,
                                    const std::string& display_name);

// Throws InputError("<path>:<line>: belongs to another survey ...") when
// the file names an identity other than `identity`; logs a warning when it
// names none. Nothing when `identity` is empty (no survey to compare with).
// The path is named in full: the results folder is what is wrong.
void CheckStageFileSurvey(const std::string& path, const std::string& identity);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_RESULTS_SURVEY_H_
