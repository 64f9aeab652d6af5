#include "geodata/survey_init.h"

#include <glog/logging.h>

#include <filesystem>
#include <stdexcept>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// What init created, removed again unless committed.
class Rollback {
 public:
  ~Rollback() {
    if (committed_) return;
    std::error_code ignored;
    for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
      // fs::remove leaves a folder that is not empty: never what the user
      // had put there.
      fs::remove(*it, ignored);
    }
  }
  void Created(const fs::path& path) { created_.push_back(path); }
  // Creates the missing folders of `folder`, recording them.
  void CreateFolders(const fs::path& folder) {
    std::vector<fs::path> missing;
    std::error_code error;
    for (fs::path p = folder; !p.empty() && !fs::exists(p, error);
         p = p.parent_path()) {
      missing.push_back(p);
      if (p == p.parent_path()) break;
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
      if (!fs::create_directory(*it, error) && error) {
        throw std::runtime_error("cannot create folder " + it->string() + ": " +
                                 error.message());
      }
      Created(*it);
    }
  }
  void Commit() { committed_ = true; }

 private:
  std::vector<fs::path> created_;
  bool committed_ = false;
};

// `path` relative to `folder` when it lies inside it (symbolic links
// resolved; "." for the folder itself), else "".
std::string InsideRelative(const fs::path& path, const fs::path& folder) {
  std::error_code error;
  const fs::path p = fs::weakly_canonical(path, error);
  const fs::path f = fs::weakly_canonical(folder, error);
  if (error) return "";
  const fs::path relative = p.lexically_relative(f);
  if (relative.empty() || *relative.begin() == "..") return "";
  return relative.generic_string();
}

// Hard-links `from` to `to` (a copy across file systems). Returns whether
// it copied.
bool LinkOrCopy(const fs::path& from, const fs::path& to, Rollback* rollback) {
  std::error_code error;
  fs::create_hard_link(from, to, error);
  bool copied = false;
  if (error) {
    if (!fs::copy_file(from, to, error) || error) {
      throw std::runtime_error("cannot link or copy " + from.string() + " to " +
                               to.string() + ": " + error.message());
    }
    copied = true;
  }
  rollback->Created(to);
  return copied;
}

}  // namespace

std::vector<std::string> SurveyInitFiles() {
  return {"survey.yaml", "rig.yaml", "trajectory.csv", "exposures.csv"};
}

SurveyInitSummary InitSurvey(
    const SurveyInitInputs& inputs,
    const std::function<void(const std::string&)>& check) {
  if (inputs.trajectory.size() < 2) {
    throw std::invalid_argument("InitSurvey: fewer than 2 trajectory samples");
  }
  const fs::path survey(inputs.survey_folder);
  SurveyInitSummary summary;
  TimeSpan span{inputs.trajectory.front().time, inputs.trajectory.back().time};
  summary.listing = ListExposures(inputs.images_folder, inputs.rig, span,
                                  inputs.times, inputs.pairing);

  Rollback rollback;
  rollback.CreateFolders(survey);
  // Images: named where they are when inside the survey, else linked in.
  summary.images_prefix = InsideRelative(inputs.images_folder, survey);
  const bool inside = !summary.images_prefix.empty();
  if (summary.images_prefix == ".") summary.images_prefix.clear();
  ExposureTable table = summary.listing.table;
  if (!inside) {
    summary.images_prefix = "images";
    for (const ExposureImage& image : table.images) {
      const fs::path to = survey / "images" / image.image;
      rollback.CreateFolders(to.parent_path());
      summary.images_copied += LinkOrCopy(
          fs::path(inputs.images_folder) / image.image, to, &rollback);
      ++summary.images_linked;
    }
  }
  if (!summary.images_prefix.empty()) {
    for (ExposureImage& image : table.images) {
      image.image = summary.images_prefix + "/" + image.image;
    }
  }

  SurveyManifest manifest = inputs.manifest;
  manifest.name = fs::absolute(survey).lexically_normal().filename().string();
  if (manifest.name.empty()) manifest.name = "survey";
  if (inputs.roadmarks.rfind("PG:", 0) == 0) {
    manifest.roadmarks = inputs.roadmarks;
  } else {
    std::error_code error;
    if (!fs::is_regular_file(inputs.roadmarks, error)) {
      throw InputError(inputs.roadmarks, 0,
                       "road-mark source is not a file (nor a PG: "
                       "connection string)");
    }
    manifest.roadmarks = InsideRelative(inputs.roadmarks, survey);
    if (manifest.roadmarks.empty()) {
      const fs::path from(inputs.roadmarks);
      manifest.roadmarks = from.filename().string();
      // A Shapefile is several files of one stem.
      std::vector<fs::path> files = {from};
      if (from.extension() == ".shp") {
        for (const char* ext : {".shx", ".dbf", ".prj", ".cpg"}) {
          fs::path sibling = from;
          sibling.replace_extension(ext);
          if (fs::exists(sibling, error)) files.push_back(sibling);
        }
      }
      for (const fs::path& file : files) {
        if (fs::exists(survey / file.filename(), error)) {
          throw std::runtime_error((survey / file.filename()).string() +
                                   " exists: not overwritten");
        }
        LinkOrCopy(file, survey / file.filename(), &rollback);
      }
    }
  }

  for (const std::string& name : SurveyInitFiles()) {
    rollback.Created(survey / name);
  }
  WriteRig(inputs.rig, (survey / manifest.rig).string());
  WriteTrajectorySamples(inputs.trajectory,
                         (survey / manifest.trajectory).string());
  WriteExposures(table, inputs.rig, (survey / manifest.exposures).string());
  WriteManifest(manifest, (survey / "survey.yaml").string());
  check(survey.string());
  rollback.Commit();
  return summary;
}

}  // namespace zebrageo
