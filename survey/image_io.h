// Reading survey images: 8-bit grey or colour, 16-bit grey, PNG or TIFF.
#ifndef ZEBRAGEO_SURVEY_IMAGE_IO_H_
#define ZEBRAGEO_SURVEY_IMAGE_IO_H_

#include <opencv2/core.hpp>
#include <string>

namespace zebrageo {

// Reads `path` as a single-channel CV_32F image with values on a 0..255
// scale (16-bit images are scaled by 255/65535, colour is converted to
// luminance). Throws InputError naming `display_name` when the file is
// missing, unreadable or not the expected size (when expected_width > 0).
cv::Mat ReadGrayImage(const std::string& path, const std::string& display_name,
                      int expected_width = 0, int expected_height = 0);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_IMAGE_IO_H_
