#include "geodata/exposure_times.h"

#include <libexif/exif-data.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include "geodata/gps_time.h"
#include "survey/csv.h"
#include "survey/input_error.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// POSIX seconds of the GPS epoch, 1980-01-06 00:00:00 UTC.
constexpr double kGpsEpochUnixSeconds = 315964800.0;
// Exposures this far outside the trajectory cannot be a clock's rounding.
constexpr double kOutsideMarginS = 1.0;

bool IsImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".tif" || ext == ".tiff" || ext == ".jpg" ||
         ext == ".jpeg";
}

std::string Fixed(double value, int decimals) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(decimals);
  text << value;
  return text.str();
}

bool ParseNumber(const std::string& text, double* value) {
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() &&
         std::isfinite(*value);
}

// One image found under the images folder.
struct FoundImage {
  std::string path;  // relative to the images folder, '/' separated
  int camera = -1;
  std::string key;  // the path without the camera's pattern
  double time = 0.0;
};

std::regex Compile(const std::string& pattern, const std::string& what) {
  try {
    return std::regex(pattern, std::regex::ECMAScript);
  } catch (const std::regex_error& error) {
    throw std::invalid_argument(
        what + " '" + pattern +
        "' is not a regular expression: " + error.what());
  }
}

// The number a file name holds, in the name's unit: group 1 of `pattern`,
// or the last number of the name without its extension.
double NumberInName(const std::string& path, const std::string& pattern,
                    const std::string& display_name) {
  const std::string stem = fs::path(path).stem().string();
  std::string number;
  if (!pattern.empty()) {
    std::smatch match;
    const std::regex regex = Compile(pattern, "--time-regex");
    if (std::regex_search(stem, match, regex) && match.size() > 1) {
      number = match[1].str();
    }
  } else {
    static const std::regex kNumber("[0-9]+(\\.[0-9]+)?");
    for (auto it = std::sregex_iterator(stem.begin(), stem.end(), kNumber);
         it != std::sregex_iterator(); ++it) {
      number = it->str();
    }
  }
  double value = 0.0;
  if (number.empty() || !ParseNumber(number, &value)) {
    throw InputError(display_name, 0,
                     "no time in the file name '" + stem +
                         "' (the last number of the name, or --time-regex's "
                         "group 1)");
  }
  return value;
}

std::string ExifText(ExifData* data, ExifIfd ifd, ExifTag tag) {
  ExifEntry* entry = exif_content_get_entry(data->ifd[ifd], tag);
  if (entry == nullptr || entry->data == nullptr) return "";
  std::string text(reinterpret_cast<const char*>(entry->data), entry->size);
  const size_t nul = text.find('\0');
  if (nul != std::string::npos) text.resize(nul);
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

// "+02:00" -> 2.0 hours; false when not an offset.
bool ParseUtcOffset(const std::string& text, double* hours) {
  int h = 0, m = 0;
  char sign = 0;
  if (text.size() != 6 ||
      std::sscanf(text.c_str(), "%c%2d:%2d", &sign, &h, &m) != 3 ||
      (sign != '+' && sign != '-') || h > 14 || m > 59) {
    return false;
  }
  *hours = (sign == '-' ? -1.0 : 1.0) * (h + m / 60.0);
  return true;
}

// The raw time of each image, in seconds on `options.clock` (file names,
// times file) or POSIX seconds on the camera's clock (EXIF).
double RawTime(const FoundImage& image, const std::string& images_folder,
               const ExposureTimeOptions& options,
               const std::map<std::string, double>& times_file) {
  const std::string full = (fs::path(images_folder) / image.path).string();
  switch (options.source) {
    case ExposureTimeSource::kFileName:
      return NumberInName(image.path, options.name_regex, full) *
             options.name_unit_s;
    case ExposureTimeSource::kTimesFile: {
      const auto it = times_file.find(image.path);
      if (it == times_file.end()) {
        throw InputError(options.times_file, 0,
                         "no row for image '" + image.path + "'");
      }
      return it->second;
    }
    case ExposureTimeSource::kExif:
      return ExifOriginalTime(full, options.exif_utc_offset_h);
  }
  return 0.0;
}

std::map<std::string, double> ReadTimesFile(const std::string& path) {
  const CsvTable table = CsvTable::Read(path, path, {"image", "time"});
  std::map<std::string, double> times;
  for (int row = 0; row < table.NumRows(); ++row) {
    const std::string image = table.GetString(row, "image");
    if (!times.emplace(image, table.GetDouble(row, "time")).second) {
      table.Fail(row, "image '" + image + "' is listed twice");
    }
  }
  return times;
}

// Seconds of the GPS week, on the trajectory's week count, of an absolute
// GPS time: the week that puts it nearest the trajectory.
double OnTrajectoryWeek(double gps_seconds, const TimeSpan& trajectory) {
  const double middle = 0.5 * (trajectory.start + trajectory.end);
  const double weeks = std::round((gps_seconds - middle) / kSecondsPerGpsWeek);
  return gps_seconds - weeks * kSecondsPerGpsWeek;
}

// The image's time on the trajectory's clock.
double TrajectoryClockTime(double raw, bool from_exif,
                           const ExposureTimeOptions& options,
                           const LeapSeconds* leap_seconds,
                           const TimeSpan& trajectory) {
  if (from_exif) {
    const double gps = options.exif_clock_gps
                           ? raw - kGpsEpochUnixSeconds
                           : GpsSecondsFromUnix(raw, *leap_seconds);
    return OnTrajectoryWeek(gps, trajectory);
  }
  switch (options.clock) {
    case ImageClock::kGpsWeekSeconds:
      // Seconds of a week: unwrap onto the trajectory's (which may run past
      // 604800 across a week's end).
      return OnTrajectoryWeek(raw, trajectory);
    case ImageClock::kGpsSeconds:
      return OnTrajectoryWeek(raw, trajectory);
    case ImageClock::kUnixUtc:
      return OnTrajectoryWeek(GpsSecondsFromUnix(raw, *leap_seconds),
                              trajectory);
  }
  return raw;
}

// How many images lie inside the trajectory's span once shifted by `shift`.
size_t CountInside(const std::vector<FoundImage>& images,
                   const TimeSpan& trajectory, double shift) {
  size_t inside = 0;
  for (const FoundImage& image : images) {
    const double t = image.time + shift;
    inside += t >= trajectory.start - kOutsideMarginS &&
              t <= trajectory.end + kOutsideMarginS;
  }
  return inside;
}

// Refuses exposures that mostly miss the trajectory, naming the clock
// mix-up a shift would undo: GPS - UTC (18 s), whole hours (local time).
void CheckAgainstTrajectory(const std::vector<FoundImage>& images,
                            const TimeSpan& trajectory,
                            const std::string& images_folder) {
  const size_t inside = CountInside(images, trajectory, 0.0);
  if (inside * 2 > images.size()) return;
  double first = images.front().time, last = images.front().time;
  for (const FoundImage& image : images) {
    first = std::min(first, image.time);
    last = std::max(last, image.time);
  }
  std::ostringstream problem;
  problem << images.size() - inside << " of " << images.size()
          << " images were taken outside the trajectory's time span ["
          << Fixed(trajectory.start, 3) << ", " << Fixed(trajectory.end, 3)
          << "] (GPS seconds of week): they span [" << Fixed(first, 3) << ", "
          << Fixed(last, 3) << "]. ";
  // The shift that puts most images inside, among the usual mix-ups.
  std::string cause;
  for (int hours = -14; hours <= 14 && cause.empty(); ++hours) {
    for (double leap : {0.0, 18.0, -18.0}) {
      const double shift = 3600.0 * hours + leap;
      if (shift == 0.0 ||
          CountInside(images, trajectory, shift) * 2 <= images.size()) {
        continue;
      }
      std::ostringstream text;
      text << Fixed(std::abs(shift), 0) << " s "
           << (shift > 0 ? "later" : "earlier") << " they would be inside: ";
      if (hours == 0) {
        text << "18 s is GPS - UTC, the camera clock is GPS time taken for "
                "UTC or the reverse (--exif-clock, --time-clock)";
      } else {
        text << "a camera clock in local time (--exif-utc-offset) "
             << (leap != 0.0 ? "and GPS - UTC (--exif-clock)" : "");
      }
      cause = text.str();
      break;
    }
  }
  problem << (cause.empty() ? "Check the images' clock (--time-clock, "
                              "--time-unit, --exif-clock) against the "
                              "trajectory's"
                            : cause);
  throw InputError(images_folder, 0, problem.str());
}

std::vector<FoundImage> FindImages(const std::string& images_folder,
                                   const Rig& rig,
                                   const PairingOptions& pairing,
                                   int* skipped) {
  std::vector<std::regex> patterns;
  for (const RigCamera& camera : rig.cameras) {
    const auto it = pairing.camera_patterns.find(camera.camera.name());
    patterns.push_back(
        Compile(it != pairing.camera_patterns.end() && !it->second.empty()
                    ? it->second
                    : "^" + camera.camera.name() + "/",
                "the pattern of camera " + camera.camera.name()));
  }
  std::error_code error;
  if (!fs::is_directory(images_folder, error)) {
    throw InputError(images_folder, 0, "not a folder of images");
  }
  std::vector<FoundImage> images;
  for (auto it = fs::recursive_directory_iterator(
           images_folder, fs::directory_options::skip_permission_denied, error);
       it != fs::recursive_directory_iterator(); it.increment(error)) {
    if (error) break;
    if (!it->is_regular_file(error) || !IsImageFile(it->path())) {
      if (it->is_regular_file(error)) ++*skipped;
      continue;
    }
    FoundImage image;
    image.path = fs::relative(it->path(), images_folder).generic_string();
    for (size_t c = 0; c < patterns.size(); ++c) {
      std::smatch match;
      if (!std::regex_search(image.path, match, patterns[c])) continue;
      if (image.camera >= 0) {
        throw InputError(images_folder + "/" + image.path, 0,
                         "the image matches the patterns of cameras " +
                             rig.cameras[image.camera].camera.name() + " and " +
                             rig.cameras[c].camera.name());
      }
      image.camera = static_cast<int>(c);
      image.key = match.prefix().str() + match.suffix().str();
    }
    if (image.camera < 0) {
      ++*skipped;
      continue;
    }
    images.push_back(image);
  }
  if (error) {
    throw InputError(images_folder, 0,
                     "cannot list the folder: " + error.message());
  }
  std::sort(
      images.begin(), images.end(),
      [](const FoundImage& a, const FoundImage& b) { return a.path < b.path; });
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    const bool any = std::any_of(
        images.begin(), images.end(),
        [c](const FoundImage& image) { return image.camera == int(c); });
    if (!any) {
      throw InputError(images_folder, 0,
                       "no image of camera '" + rig.cameras[c].camera.name() +
                           "' (PNG, TIFF or JPEG files whose path matches " +
                           "its pattern; by default a subfolder '" +
                           rig.cameras[c].camera.name() + "/')");
    }
  }
  return images;
}

// Pairs of image indices (left, right) of one stereo pair.
std::vector<std::pair<int, int>> PairByName(
    const std::vector<FoundImage>& images, int left, int right) {
  std::map<std::string, int> right_by_key;
  for (size_t i = 0; i < images.size(); ++i) {
    if (images[i].camera == right) right_by_key[images[i].key] = int(i);
  }
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < images.size(); ++i) {
    if (images[i].camera != left) continue;
    const auto it = right_by_key.find(images[i].key);
    if (it != right_by_key.end()) pairs.emplace_back(int(i), it->second);
  }
  return pairs;
}

std::vector<std::pair<int, int>> PairByTime(
    const std::vector<FoundImage>& images, int left, int right,
    double tolerance) {
  std::vector<int> rights;
  for (size_t i = 0; i < images.size(); ++i) {
    if (images[i].camera == right) rights.push_back(int(i));
  }
  std::sort(rights.begin(), rights.end(),
            [&](int a, int b) { return images[a].time < images[b].time; });
  std::set<int> used;
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < images.size(); ++i) {
    if (images[i].camera != left) continue;
    const double t = images[i].time;
    auto it = std::lower_bound(
        rights.begin(), rights.end(), t,
        [&](int r, double time) { return images[r].time < time; });
    int best = -1;
    for (auto candidate : {it, it == rights.begin() ? it : std::prev(it)}) {
      if (candidate == rights.end() || used.count(*candidate)) continue;
      if (std::abs(images[*candidate].time - t) <= tolerance &&
          (best < 0 || std::abs(images[*candidate].time - t) <
                           std::abs(images[best].time - t))) {
        best = *candidate;
      }
    }
    if (best >= 0) {
      used.insert(best);
      pairs.emplace_back(int(i), best);
    }
  }
  return pairs;
}

}  // namespace

std::string ExposureTimeOptions::Check() const {
  if (!(name_unit_s > 0.0) || !std::isfinite(name_unit_s)) {
    return "the time unit must be > 0";
  }
  if (source == ExposureTimeSource::kTimesFile && times_file.empty()) {
    return "a times file is needed";
  }
  if (std::isfinite(exif_utc_offset_h) && std::abs(exif_utc_offset_h) > 14.0) {
    return "the UTC offset must be within [-14, 14] hours";
  }
  return "";
}

double ExifOriginalTime(const std::string& path, double utc_offset_h) {
  std::unique_ptr<ExifData, void (*)(ExifData*)> data(
      exif_data_new_from_file(path.c_str()), &exif_data_unref);
  if (!data) throw InputError(path, 0, "no EXIF data (DateTimeOriginal)");
  const std::string date =
      ExifText(data.get(), EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL);
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  if (date.size() != 19 ||
      std::sscanf(date.c_str(), "%4d:%2d:%2d %2d:%2d:%2d", &year, &month, &day,
                  &hour, &minute, &second) != 6) {
    throw InputError(path, 0,
                     "no EXIF DateTimeOriginal (\"YYYY:MM:DD HH:MM:SS\"), "
                     "found '" +
                         date + "'");
  }
  char iso[32];
  std::snprintf(iso, sizeof(iso), "%04d-%02d-%02dT%02d:%02d:%02d", year, month,
                day, hour, minute, second);
  double seconds = 0.0;
  if (!ParseUtcTimestamp(iso, &seconds)) {
    throw InputError(
        path, 0,
        "EXIF DateTimeOriginal '" + date + "' is not a valid date and time");
  }
  const std::string subsec =
      ExifText(data.get(), EXIF_IFD_EXIF, EXIF_TAG_SUB_SEC_TIME_ORIGINAL);
  if (!subsec.empty()) {
    if (subsec.size() > 9 ||
        subsec.find_first_not_of("0123456789") != std::string::npos) {
      throw InputError(
          path, 0, "EXIF SubSecTimeOriginal '" + subsec + "' is not digits");
    }
    seconds += std::stod(subsec) / std::pow(10.0, double(subsec.size()));
  }
  // OffsetTimeOriginal (EXIF 2.31, tag 0x9011) wins over the option.
  const std::string offset_text =
      ExifText(data.get(), EXIF_IFD_EXIF, static_cast<ExifTag>(0x9011));
  double offset_h = std::isfinite(utc_offset_h) ? utc_offset_h : 0.0;
  if (!offset_text.empty() && !ParseUtcOffset(offset_text, &offset_h)) {
    throw InputError(
        path, 0, "EXIF OffsetTimeOriginal '" + offset_text + "' is not +HH:MM");
  }
  return seconds - 3600.0 * offset_h;
}

ExposureListing ListExposures(const std::string& images_folder, const Rig& rig,
                              const TimeSpan& trajectory,
                              const ExposureTimeOptions& times,
                              const PairingOptions& pairing) {
  const std::string problem = times.Check();
  if (!problem.empty()) throw std::invalid_argument(problem);
  ExposureListing listing;
  std::vector<FoundImage> images =
      FindImages(images_folder, rig, pairing, &listing.skipped_files);
  const bool exif = times.source == ExposureTimeSource::kExif;
  std::optional<LeapSeconds> leap_seconds;
  if ((exif && !times.exif_clock_gps) ||
      (!exif && times.clock == ImageClock::kUnixUtc)) {
    leap_seconds = LeapSeconds::Load(times.leap_seconds_file);
  }
  std::map<std::string, double> times_file;
  if (times.source == ExposureTimeSource::kTimesFile) {
    times_file = ReadTimesFile(times.times_file);
  }
  for (FoundImage& image : images) {
    const double raw = RawTime(image, images_folder, times, times_file);
    image.time = TrajectoryClockTime(
        raw, exif, times, leap_seconds ? &*leap_seconds : nullptr, trajectory);
  }
  CheckAgainstTrajectory(images, trajectory, images_folder);

  // Exposures: pairs of each stereo pair, then every image left alone.
  std::vector<std::vector<int>> groups;
  std::vector<bool> grouped(images.size(), false);
  bool by_names = pairing.by != ImagePairing::kTime;
  for (const std::array<int, 2>& pair : rig.stereo_pairs) {
    std::vector<std::pair<int, int>> pairs;
    if (pairing.by != ImagePairing::kTime) {
      pairs = PairByName(images, pair[0], pair[1]);
    }
    int lefts = 0, rights = 0;
    for (const FoundImage& image : images) {
      lefts += image.camera == pair[0];
      rights += image.camera == pair[1];
    }
    if (pairing.by == ImagePairing::kTime ||
        (pairing.by == ImagePairing::kAuto &&
         pairs.size() * 10 < size_t(std::min(lefts, rights)) * 9)) {
      pairs = PairByTime(images, pair[0], pair[1],
                         pairing.max_pair_time_difference_s);
      by_names = false;
    }
    for (const auto& [l, r] : pairs) {
      const double difference = std::abs(images[l].time - images[r].time);
      if (difference > pairing.max_pair_time_difference_s) {
        throw InputError(images_folder + "/" + images[r].path, 0,
                         "paired by name with " + images[l].path +
                             " but taken " + Fixed(difference, 6) +
                             " s apart (more than --pair-max-dt " +
                             Fixed(pairing.max_pair_time_difference_s, 6) +
                             " s): pair by time, or check the times");
      }
      groups.push_back({l, r});
      grouped[l] = grouped[r] = true;
    }
  }
  for (size_t i = 0; i < images.size(); ++i) {
    if (grouped[i]) continue;
    groups.push_back({int(i)});
    for (const std::array<int, 2>& pair : rig.stereo_pairs) {
      if (images[i].camera == pair[0] || images[i].camera == pair[1]) {
        ++listing.unpaired_images;
        break;
      }
    }
  }
  listing.pairing = by_names ? "names" : "times";
  auto time_of = [&](const std::vector<int>& group) {
    double sum = 0.0;
    for (int i : group) sum += images[i].time;
    return sum / group.size();
  };
  std::sort(groups.begin(), groups.end(),
            [&](const std::vector<int>& a, const std::vector<int>& b) {
              return time_of(a) < time_of(b);
            });
  int64_t id = 1;
  for (const std::vector<int>& group : groups) {
    const double time = time_of(group);
    for (int i : group) {
      ExposureImage row;
      row.exposure_id = id;
      row.time = time;
      row.camera = images[i].camera;
      row.image = images[i].path;
      listing.table.images.push_back(row);
    }
    ++id;
  }
  return listing;
}

}  // namespace zebrageo
