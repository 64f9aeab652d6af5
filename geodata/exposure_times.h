// exposures.csv from a folder of images (zebrageo init): which camera took
// each image, when, and which images form one stereo exposure.
//
// Cameras. An image belongs to the camera whose pattern (an ECMAScript
// regex) it matches, searched in its path relative to the images folder;
// by default the pattern of camera NAME is "^NAME/" (a subfolder per
// camera: images/left/..., images/right/...). A pattern such as "_L(?=\.)"
// picks "000001_L.jpg" out of one folder.
//
// Times, on the trajectory's clock (GPS seconds of week of the trajectory's
// first week, as every trajectory import writes it):
//  - kFileName: a number in the file name (by default the last one, e.g.
//    "313427.741682.jpg" or ROS's "1714731330123456789.png"; or group 1 of
//    a regex), times a unit (1e-9 for nanoseconds), on a stated clock;
//  - kExif: EXIF DateTimeOriginal with SubSecTimeOriginal, a calendar time:
//    UTC, or the offset of OffsetTimeOriginal or of the options, or GPS
//    time when the camera clock was set to it (no leap seconds);
//  - kTimesFile: a CSV with columns image (the path relative to the images
//    folder) and time, on a stated clock.
// UTC is turned into GPS time with the IERS leap seconds (GPS - UTC = 18 s
// since 2017); absolute GPS time into seconds of the week that puts the
// exposures inside the trajectory. Exposures outside the trajectory's time
// span (beyond a margin) are an error naming the offset, the usual symptom
// of a clock mix-up (18 s: UTC against GPS; whole hours: local time).
//
// Pairing. Images of the cameras of a stereo pair form one exposure when
// their names match once the camera's pattern is removed
// ("left/000001.jpg" and "right/000001.jpg"), or when their times are
// within max_pair_time_difference_s; kAuto takes names when they pair
// (nearly) all images. An image without a partner stays an exposure of one
// image (its pose is still computed), and is counted in the warnings.
#ifndef ZEBRAGEO_GEODATA_EXPOSURE_TIMES_H_
#define ZEBRAGEO_GEODATA_EXPOSURE_TIMES_H_

#include <map>
#include <string>
#include <vector>

#include "survey/exposures.h"
#include "survey/rig.h"

namespace zebrageo {

enum class ExposureTimeSource { kFileName, kExif, kTimesFile };
// The clock of times in file names and times files.
enum class ImageClock {
  kGpsWeekSeconds,  // seconds of the GPS week, as trajectory.csv
  kGpsSeconds,      // seconds since 1980-01-06 (GPS)
  kUnixUtc,         // POSIX seconds (UTC), as ROS stamps and most loggers
};
enum class ImagePairing { kAuto, kName, kTime };

struct ExposureTimeOptions {
  ExposureTimeSource source = ExposureTimeSource::kFileName;
  ImageClock clock = ImageClock::kGpsWeekSeconds;
  // kFileName: regex whose group 1 is the number ("": the last number).
  std::string name_regex;
  double name_unit_s = 1.0;
  // kTimesFile.
  std::string times_file;
  // kExif: the camera's clock is GPS time, not UTC.
  bool exif_clock_gps = false;
  // kExif: hours to subtract from a local EXIF time when the file has no
  // OffsetTimeOriginal (NaN: none; the time is UTC).
  double exif_utc_offset_h = std::numeric_limits<double>::quiet_NaN();
  std::string leap_seconds_file = "/usr/share/zoneinfo/leap-seconds.list";

  std::string Check() const;
};

struct PairingOptions {
  ImagePairing by = ImagePairing::kAuto;
  double max_pair_time_difference_s = 0.002;
  // Camera name -> pattern ("": "^NAME/").
  std::map<std::string, std::string> camera_patterns;
};

// The trajectory's time span (its clock), for the week and the check.
struct TimeSpan {
  double start = 0.0;
  double end = 0.0;
};

struct ExposureListing {
  ExposureTable table;  // images: paths relative to the images folder
  int unpaired_images = 0;
  int skipped_files = 0;  // files of no camera or not an image
  std::string pairing;    // "names" or "times"
};

// Lists the images under `images_folder` (PNG, TIFF, JPEG by extension),
// gives each its camera and time, and pairs them into exposures numbered
// from 1 in time order. Throws InputError naming the image (or the times
// file and line), or the folder when a camera has no image.
ExposureListing ListExposures(const std::string& images_folder, const Rig& rig,
                              const TimeSpan& trajectory,
                              const ExposureTimeOptions& times,
                              const PairingOptions& pairing);

// EXIF DateTimeOriginal (+ SubSecTimeOriginal, OffsetTimeOriginal) of a
// JPEG or TIFF, as POSIX seconds on the camera's clock taken as UTC unless
// the file gives an offset. Throws InputError naming `path` when absent.
double ExifOriginalTime(const std::string& path, double utc_offset_h);

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_EXPOSURE_TIMES_H_
