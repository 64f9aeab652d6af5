// Survey uploads (tar, tar.gz/bz2/xz, zip) and the zip of a results
// folder, through libarchive.
//
// An upload is checked whole before anything is extracted: every entry a
// regular file or a folder (no symbolic or hard link, device, FIFO or
// socket), its name a safe relative path (server/confined_path.h; leading
// "./" allowed), no name twice, and the counts and sizes its headers claim
// within the limits. Extraction then writes it with libarchive's disk
// writer into a new empty folder (no "..", never through a symbolic link,
// no overwrite, no owner or special permission bits) and counts the bytes
// it really writes against the same limits, so an archive whose headers
// lie is stopped as well.
#ifndef ZEBRAGEO_SERVER_ARCHIVE_H_
#define ZEBRAGEO_SERVER_ARCHIVE_H_

#include <cstdint>
#include <functional>
#include <string>

namespace zebrageo {

struct ArchiveLimits {
  int64_t max_entries = 200000;
  int64_t max_total_bytes = int64_t{64} << 30;  // extracted
};

// "" when the archive at `path` may be extracted; otherwise what is wrong,
// naming the entry ("entry '../x': leaves its folder").
std::string ArchiveProblem(const std::string& path,
                           const ArchiveLimits& limits);

// Extracts the checked archive into `folder` (created; must not exist).
// Throws std::runtime_error naming the entry when anything fails.
void ExtractArchive(const std::string& path, const std::string& folder,
                    const ArchiveLimits& limits);

// Writes a zip of the regular files under `folder` for which `include`
// (relative name) is true, as `prefix`/name, to `zip_path` atomically.
// Throws std::runtime_error on failure.
void WriteZipOfFolder(const std::string& folder, const std::string& prefix,
                      const std::function<bool(const std::string&)>& include,
                      const std::string& zip_path);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_ARCHIVE_H_
