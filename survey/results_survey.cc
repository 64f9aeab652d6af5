#include "survey/results_survey.h"

#include <glog/logging.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <utility>

#include "survey/csv.h"
#include "survey/fnv_hash.h"
#include "survey/input_error.h"

namespace zebrageo {
namespace {

constexpr char kKey[] = "survey:";
// The leading comments of a stage file are a few lines; a file whose first
// 64 KiB are comments names no identity before its header.
constexpr std::streamsize kMaxCommentBytes = 64 * 1024;

std::string Trimmed(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const size_t end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

}  // namespace

std::string SurveyIdentity(const ExposureTable& exposures) {
  uint64_t hash = kFnv1aOffset;
  for (const Exposure& exposure : exposures.exposures) {
    hash = Fnv1a(std::to_string(exposure.exposure_id) + "@" +
                     FormatDouble(exposure.time) + ";",
                 hash);
  }
  return Hex16(hash);
}

std::string SurveyIdentityComment(const std::string& identity) {
  return std::string(kKey) + " " + identity;
}

std::vector<std::string> WithSurveyIdentity(const ExposureTable& exposures,
                                            std::vector<std::string> comments) {
  comments.insert(comments.begin(),
                  SurveyIdentityComment(SurveyIdentity(exposures)));
  return comments;
}

StageFileSurvey ReadStageFileSurvey(const std::string& path,
                                    const std::string& display_name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(display_name, 0, "cannot open " + path);
  std::string text(static_cast<size_t>(kMaxCommentBytes), '\0');
  in.read(&text[0], kMaxCommentBytes);
  text.resize(static_cast<size_t>(in.gcount()));
  // A UTF-8 byte-order mark, as the CSV reader allows.
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
  std::istringstream lines(text);
  std::string line;
  StageFileSurvey found;
  for (int number = 1; std::getline(lines, line); ++number) {
    const std::string trimmed = Trimmed(line);
    if (trimmed.empty()) continue;
    if (trimmed[0] != '#') break;  // the header: no more comments
    const std::string comment = Trimmed(trimmed.substr(1));
    if (comment.compare(0, sizeof(kKey) - 1, kKey) == 0) {
      found.identity = Trimmed(comment.substr(sizeof(kKey) - 1));
      found.line = number;
      break;
    }
  }
  return found;
}

void CheckStageFileSurvey(const std::string& path,
                          const std::string& identity) {
  if (identity.empty()) return;
  const StageFileSurvey file = ReadStageFileSurvey(path, path);
  if (file.identity.empty()) {
    LOG(WARNING) << path
                 << ": names no survey (written by an older zebrageo): "
                    "read as this survey's; rerun the stage if it is not";
    return;
  }
  if (file.identity != identity) {
    throw InputError(
        path, file.line,
        "belongs to another survey (survey " + file.identity +
            ", this survey's exposures are " + identity +
            "): its exposure ids would name other images. Write this "
            "survey's results into another folder, or rerun its stages "
            "from `zebrageo reconstruct`");
  }
}

}  // namespace zebrageo
