#include "survey/image_io.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "survey/input_error.h"

namespace zebrageo {

cv::Mat ReadGrayImage(const std::string& path, const std::string& display_name,
                      int expected_width, int expected_height) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw InputError(display_name, 0, "image file does not exist");
  }
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(display_name, 0, "image path is not a file");
  }
  cv::Mat raw;
  try {
    // ANYDEPTH keeps 16-bit images 16-bit (the default would cut them to 8).
    raw = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
  } catch (const cv::Exception&) {
    raw.release();  // some decoders throw on corrupt data instead of failing
  }
  if (raw.empty()) {
    throw InputError(display_name, 0, "cannot decode image (not a PNG/TIFF?)");
  }
  double scale = 1.0;
  switch (raw.depth()) {
    case CV_8U:
      break;
    case CV_16U:
      scale = 255.0 / 65535.0;  // to the 0..255 scale of 8-bit images
      break;
    default:
      throw InputError(display_name, 0,
                       "unsupported pixel type (expected 8-bit or 16-bit "
                       "unsigned integers)");
  }
  cv::Mat scaled;
  raw.convertTo(scaled, CV_32F, scale);
  cv::Mat gray;
  switch (scaled.channels()) {
    case 1:
      gray = scaled;
      break;
    case 3:
      cv::cvtColor(scaled, gray, cv::COLOR_BGR2GRAY);
      break;
    case 4:
      cv::cvtColor(scaled, gray, cv::COLOR_BGRA2GRAY);
      break;
    default:
      throw InputError(display_name, 0,
                       "unsupported image with " +
                           std::to_string(scaled.channels()) + " channels");
  }
  if (expected_width > 0 &&
      (gray.cols != expected_width || gray.rows != expected_height)) {
    throw InputError(display_name, 0,
                     "image is " + std::to_string(gray.cols) + "x" +
                         std::to_string(gray.rows) +
                         " pixels but the rig's camera is " +
                         std::to_string(expected_width) + "x" +
                         std::to_string(expected_height));
  }
  return gray;
}

}  // namespace zebrageo
