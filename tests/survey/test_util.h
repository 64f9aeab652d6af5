// Helpers shared by the survey tests: temporary folders and the location of
// ../shared/datasets.
#ifndef ZEBRAGEO_TESTS_SURVEY_TEST_UTIL_H_
#define ZEBRAGEO_TESTS_SURVEY_TEST_UTIL_H_

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace zebrageo {

// A fresh folder under the system temporary directory, removed with its
// content when the object goes out of scope.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::random_device device;
    path_ = std::filesystem::temp_directory_path() /
            ("zebrageo-test-" + std::to_string(::getpid()) + "-" +
             std::to_string(device()));
    std::filesystem::create_directories(path_);
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  std::string Path(const std::string& name = "") const {
    return name.empty() ? path_.string() : (path_ / name).string();
  }
  // Writes `text` to `name` inside the folder and returns its path.
  std::string Write(const std::string& name, const std::string& text) const {
    const std::filesystem::path file = path_ / name;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << text;
    return file.string();
  }
  // Number of entries in the folder (to check nothing was left behind).
  int CountEntries() const {
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(path_)) {
      (void)entry;
      ++count;
    }
    return count;
  }

 private:
  std::filesystem::path path_;
};

// ../shared/datasets, or "" when it is absent (tests then GTEST_SKIP).
inline std::string SharedDatasetsFolder() {
  const std::string folder = std::string(ZEBRAGEO_SHARED_DIR) + "/datasets";
  return std::filesystem::is_directory(folder) ? folder : "";
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_SURVEY_TEST_UTIL_H_
