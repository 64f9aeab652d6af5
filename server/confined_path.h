// Paths from requests, confined to the server's data root.
//
// A server never trusts a path from a request: a folder job names its
// survey relative to the data root, an archive names its entries, a client
// names a result file. Each is checked as text first (relative, no "..",
// no empty or "." component, no control character), then resolved with
// every symbolic link followed (realpath(3)) and required to stay inside
// the root; a survey folder is walked for links and special files that
// point out of it before a job is accepted. The child that processes the
// survey confines the survey's own file names again (survey/survey_paths.h).
#ifndef ZEBRAGEO_SERVER_CONFINED_PATH_H_
#define ZEBRAGEO_SERVER_CONFINED_PATH_H_

#include <optional>
#include <string>

namespace zebrageo {

// "" when `path` is a safe relative path: not empty, not absolute, at most
// 4096 bytes, components of 1-255 bytes none of which is "." or "..", no
// backslash and no control character. Otherwise what is wrong with it.
std::string RelativePathProblem(const std::string& path);

// The canonical (realpath) form of `root`/`relative` when it exists and
// resolves inside `canonical_root` (itself canonical); otherwise nullopt
// with the reason in `problem`.
std::optional<std::string> ResolveInside(const std::string& canonical_root,
                                         const std::string& relative,
                                         std::string* problem);

// True when canonical `path` is `canonical_root` or below it.
bool IsInside(const std::string& canonical_root, const std::string& path);

// "" when no entry below `folder` (at most `max_entries` of them) is a
// symbolic link that resolves outside `canonical_root` (or dangles), a
// device, FIFO or socket; otherwise the first such entry and why.
std::string FolderEscapeProblem(const std::string& folder,
                                const std::string& canonical_root,
                                int max_entries = 200000);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_CONFINED_PATH_H_
