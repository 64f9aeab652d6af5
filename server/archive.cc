#include "server/archive.h"

#include <archive.h>
#include <archive_entry.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "server/confined_path.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

using ReadArchive = std::unique_ptr<archive, decltype(&archive_read_free)>;
using WriteArchive = std::unique_ptr<archive, decltype(&archive_write_free)>;

// A reader for every format and filter libarchive knows; raw data (a file
// that is no archive) is not one of them.
ReadArchive OpenArchive(const std::string& path) {
  ReadArchive reader(archive_read_new(), &archive_read_free);
  if (!reader) throw std::runtime_error("out of memory");
  archive_read_support_filter_all(reader.get());
  archive_read_support_format_tar(reader.get());
  archive_read_support_format_gnutar(reader.get());
  archive_read_support_format_zip(reader.get());
  if (archive_read_open_filename(reader.get(), path.c_str(), 1 << 16) !=
      ARCHIVE_OK) {
    throw std::runtime_error(std::string("not a tar or zip archive (") +
                             archive_error_string(reader.get()) + ")");
  }
  return reader;
}

// The entry's name without leading "./" (tar -C dir . writes them); "" for
// the archive's root itself.
std::string EntryName(archive_entry* entry) {
  const char* raw = archive_entry_pathname(entry);
  std::string name = raw == nullptr ? "" : raw;
  while (name.compare(0, 2, "./") == 0) name.erase(0, 2);
  if (name == ".") name.clear();
  return name;
}

// "" or why `entry` may not be extracted.
std::string EntryProblem(archive_entry* entry, const std::string& name) {
  const char* raw = archive_entry_pathname(entry);
  if (raw == nullptr) return "an entry without a name";
  const std::string quoted = "entry '" + std::string(raw) + "'";
  if (archive_entry_hardlink(entry) != nullptr) {
    return quoted + ": a hard link (refused)";
  }
  const mode_t type = archive_entry_filetype(entry);
  if (type == AE_IFLNK) return quoted + ": a symbolic link (refused)";
  if (type != AE_IFREG && type != AE_IFDIR) {
    return quoted + ": not a file or folder (a device, FIFO or socket)";
  }
  if (name.empty()) return "";
  const std::string problem = RelativePathProblem(name);
  if (!problem.empty()) return quoted + ": " + problem;
  if (archive_entry_size_is_set(entry) && archive_entry_size(entry) < 0) {
    return quoted + ": a negative size";
  }
  return "";
}

}  // namespace

std::string ArchiveProblem(const std::string& path,
                           const ArchiveLimits& limits) {
  try {
    ReadArchive reader = OpenArchive(path);
    std::set<std::string> names;
    int64_t entries = 0;
    int64_t bytes = 0;
    archive_entry* entry = nullptr;
    for (;;) {
      const int code = archive_read_next_header(reader.get(), &entry);
      if (code == ARCHIVE_EOF) break;
      if (code != ARCHIVE_OK) {
        return std::string("unreadable archive: ") +
               archive_error_string(reader.get());
      }
      const std::string name = EntryName(entry);
      const std::string problem = EntryProblem(entry, name);
      if (!problem.empty()) return problem;
      if (!name.empty()) {
        std::string key = name;
        if (key.back() == '/') key.pop_back();
        if (!names.insert(key).second) {
          return "entry '" + name + "': in the archive twice";
        }
      }
      if (++entries > limits.max_entries) {
        return "more than " + std::to_string(limits.max_entries) + " entries";
      }
      if (archive_entry_size_is_set(entry)) {
        bytes += archive_entry_size(entry);
      }
      if (bytes > limits.max_total_bytes) {
        return "extracts to more than " +
               std::to_string(limits.max_total_bytes) + " bytes";
      }
      // Reading the data (not skipping it) checks its compression too.
      if (archive_read_data_skip(reader.get()) != ARCHIVE_OK) {
        return "entry '" + name + "': " + archive_error_string(reader.get());
      }
    }
    if (entries == 0) return "an empty archive";
    return "";
  } catch (const std::exception& error) {
    return error.what();
  }
}

void ExtractArchive(const std::string& path, const std::string& folder,
                    const ArchiveLimits& limits) {
  if (!fs::create_directory(folder)) {
    throw std::runtime_error(folder + ": exists already");
  }
  ReadArchive reader = OpenArchive(path);
  WriteArchive writer(archive_write_disk_new(), &archive_write_free);
  archive_write_disk_set_options(writer.get(),
                                 ARCHIVE_EXTRACT_SECURE_NODOTDOT |
                                     ARCHIVE_EXTRACT_SECURE_SYMLINKS |
                                     ARCHIVE_EXTRACT_NO_OVERWRITE);
  int64_t bytes = 0;
  archive_entry* entry = nullptr;
  std::vector<char> buffer(1 << 16);
  for (;;) {
    const int code = archive_read_next_header(reader.get(), &entry);
    if (code == ARCHIVE_EOF) break;
    if (code != ARCHIVE_OK) {
      throw std::runtime_error(std::string("unreadable archive: ") +
                               archive_error_string(reader.get()));
    }
    const std::string name = EntryName(entry);
    const std::string problem = EntryProblem(entry, name);
    if (!problem.empty()) throw std::runtime_error(problem);
    if (name.empty()) continue;
    const bool is_folder = archive_entry_filetype(entry) == AE_IFDIR;
    // The checked name under the new folder; plain permissions, no owner.
    archive_entry_set_pathname(entry, (folder + "/" + name).c_str());
    archive_entry_set_perm(entry, is_folder ? 0755 : 0644);
    if (archive_write_header(writer.get(), entry) != ARCHIVE_OK) {
      throw std::runtime_error("entry '" + name +
                               "': " + archive_error_string(writer.get()));
    }
    for (;;) {
      const la_ssize_t read =
          archive_read_data(reader.get(), buffer.data(), buffer.size());
      if (read < 0) {
        throw std::runtime_error("entry '" + name +
                                 "': " + archive_error_string(reader.get()));
      }
      if (read == 0) break;
      bytes += read;
      if (bytes > limits.max_total_bytes) {
        throw std::runtime_error("extracts to more than " +
                                 std::to_string(limits.max_total_bytes) +
                                 " bytes");
      }
      if (archive_write_data(writer.get(), buffer.data(), read) != read) {
        throw std::runtime_error("entry '" + name +
                                 "': " + archive_error_string(writer.get()));
      }
    }
    if (archive_write_finish_entry(writer.get()) != ARCHIVE_OK) {
      throw std::runtime_error("entry '" + name +
                               "': " + archive_error_string(writer.get()));
    }
  }
  if (archive_write_close(writer.get()) != ARCHIVE_OK) {
    throw std::runtime_error(archive_error_string(writer.get()));
  }
}

void WriteZipOfFolder(const std::string& folder, const std::string& prefix,
                      const std::function<bool(const std::string&)>& include,
                      const std::string& zip_path) {
  const std::string temp =
      zip_path + ".tmp-" + std::to_string(getpid()) + "-" +
      std::to_string(std::hash<std::thread::id>()(std::this_thread::get_id()));
  try {
    WriteArchive writer(archive_write_new(), &archive_write_free);
    archive_write_set_format_zip(writer.get());
    if (archive_write_open_filename(writer.get(), temp.c_str()) != ARCHIVE_OK) {
      throw std::runtime_error(temp + ": " +
                               archive_error_string(writer.get()));
    }
    std::vector<std::string> names;
    for (const auto& item : fs::recursive_directory_iterator(folder)) {
      if (!item.is_regular_file() || item.is_symlink()) continue;
      const std::string name = fs::relative(item.path(), folder).string();
      if (include(name)) names.push_back(name);
    }
    std::sort(names.begin(), names.end());
    std::vector<char> buffer(1 << 16);
    for (const std::string& name : names) {
      const std::string file = folder + "/" + name;
      std::ifstream in(file, std::ios::binary);
      if (!in) throw std::runtime_error(file + ": cannot be read");
      std::unique_ptr<archive_entry, decltype(&archive_entry_free)> entry(
          archive_entry_new(), &archive_entry_free);
      archive_entry_set_pathname(entry.get(), (prefix + "/" + name).c_str());
      archive_entry_set_filetype(entry.get(), AE_IFREG);
      archive_entry_set_perm(entry.get(), 0644);
      archive_entry_set_size(entry.get(),
                             static_cast<la_int64_t>(fs::file_size(file)));
      archive_entry_set_mtime(
          entry.get(),
          std::chrono::duration_cast<std::chrono::seconds>(
              fs::last_write_time(file) - fs::file_time_type::clock::now() +
              std::chrono::system_clock::now().time_since_epoch())
              .count(),
          0);
      if (archive_write_header(writer.get(), entry.get()) != ARCHIVE_OK) {
        throw std::runtime_error(name + ": " +
                                 archive_error_string(writer.get()));
      }
      while (in) {
        in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
        const std::streamsize got = in.gcount();
        if (got > 0 &&
            archive_write_data(writer.get(), buffer.data(), got) != got) {
          throw std::runtime_error(name + ": " +
                                   archive_error_string(writer.get()));
        }
      }
    }
    if (archive_write_close(writer.get()) != ARCHIVE_OK) {
      throw std::runtime_error(archive_error_string(writer.get()));
    }
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
  fs::rename(temp, zip_path);
}

}  // namespace zebrageo
