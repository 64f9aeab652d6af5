#include "server/confined_path.h"

#include <limits.h>
#include <stdlib.h>

#include <filesystem>
#include <memory>

namespace zebrageo {

namespace fs = std::filesystem;

std::string RelativePathProblem(const std::string& path) {
  if (path.empty()) return "is empty";
  if (path.size() > 4096) return "is longer than 4096 bytes";
  if (path.front() == '/') return "is absolute";
  for (char c : path) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) return "has a control character";
    if (c == '\\') return "has a backslash";
  }
  // Archives name folders with a trailing slash ("survey/").
  const std::string trimmed =
      path.back() == '/' ? path.substr(0, path.size() - 1) : path;
  size_t start = 0;
  while (start <= trimmed.size()) {
    const size_t end = std::min(trimmed.find('/', start), trimmed.size());
    const std::string part = trimmed.substr(start, end - start);
    if (part.empty()) return "has an empty component";
    if (part == "..") return "leaves its folder (\"..\")";
    if (part == ".") return "has a \".\" component";
    if (part.size() > 255) return "has a component longer than 255 bytes";
    start = end + 1;
  }
  return "";
}

bool IsInside(const std::string& canonical_root, const std::string& path) {
  if (path == canonical_root) return true;
  const std::string prefix =
      canonical_root == "/" ? canonical_root : canonical_root + "/";
  return path.compare(0, prefix.size(), prefix) == 0;
}

std::optional<std::string> ResolveInside(const std::string& canonical_root,
                                         const std::string& relative,
                                         std::string* problem) {
  const std::string text_problem = RelativePathProblem(relative);
  if (!text_problem.empty()) {
    *problem = text_problem;
    return std::nullopt;
  }
  const std::string joined = canonical_root + "/" + relative;
  std::unique_ptr<char, decltype(&free)> resolved(
      realpath(joined.c_str(), nullptr), &free);
  if (resolved == nullptr) {
    *problem = "does not exist";
    return std::nullopt;
  }
  const std::string canonical = resolved.get();
  if (!IsInside(canonical_root, canonical)) {
    *problem = "resolves outside the data root";
    return std::nullopt;
  }
  return canonical;
}

std::string FolderEscapeProblem(const std::string& folder,
                                const std::string& canonical_root,
                                int max_entries) {
  std::error_code error;
  int count = 0;
  fs::recursive_directory_iterator it(folder, fs::directory_options::none,
                                      error);
  if (error) return folder + ": " + error.message();
  for (; it != fs::recursive_directory_iterator(); it.increment(error)) {
    if (error) return folder + ": " + error.message();
    if (++count > max_entries) {
      return "more than " + std::to_string(max_entries) + " entries";
    }
    const fs::path& path = it->path();
    const std::string name = fs::relative(path, folder, error).string();
    const fs::file_status status = it->symlink_status(error);
    if (error) return name + ": " + error.message();
    if (fs::is_symlink(status)) {
      std::unique_ptr<char, decltype(&free)> target(
          realpath(path.c_str(), nullptr), &free);
      if (target == nullptr) return name + ": a symbolic link that dangles";
      if (!IsInside(canonical_root, target.get())) {
        return name + ": a symbolic link to " + target.get() +
               ", outside the data root";
      }
      // Not followed: recursive_directory_iterator does not descend into
      // linked folders, and the target is inside the root.
      continue;
    }
    if (!fs::is_regular_file(status) && !fs::is_directory(status)) {
      return name + ": not a file or folder (a device, FIFO or socket)";
    }
  }
  return "";
}

}  // namespace zebrageo
