// Output files that are never seen half-written.
//
// AtomicFile writes to "<path>.tmp-<pid>" in the same folder and renames it
// onto `path` in Commit(); rename(2) is atomic within a file system, so a
// reader (or a rerun after a kill) sees either the old file, the complete new
// one, or none. If Commit() is never reached (an exception, a crash handled
// by the destructor), the temporary file is removed.
//
// Fault injection, for tests only: when the environment variable
// ZEBRAGEO_FAIL_WRITE names a file (its name without folder, e.g.
// "poses.csv"), Commit() of that file fails as on a full disk. A tmpfs
// filled to the brim would need root; this seam shows what every command
// leaves behind when the disk fills up at a given file.
#ifndef ZEBRAGEO_SURVEY_ATOMIC_FILE_H_
#define ZEBRAGEO_SURVEY_ATOMIC_FILE_H_

#include <fstream>
#include <functional>
#include <string>

namespace zebrageo {

class AtomicFile {
 public:
  // Opens the temporary file; throws std::runtime_error if it cannot.
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return out_; }
  // Flushes, checks that every write succeeded, and renames into place.
  // Throws std::runtime_error on any failure (disk full...).
  void Commit();

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string temp_path_;
  std::ofstream out_;
  bool committed_ = false;
};

// Convenience: writes a whole file through `write` atomically.
void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write);

// Removes the temporary files AtomicFile may have left in `folder` when a
// process was killed (SIGKILL gives no chance to clean up).
void RemoveStaleTemporaries(const std::string& folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_ATOMIC_FILE_H_
