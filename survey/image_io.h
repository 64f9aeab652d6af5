// Reading survey images: 8-bit grey or colour, 16-bit grey, PNG or TIFF;
// 8-bit grey or colour JPEG (baseline or progressive, as mobile-mapping
// cameras deliver them).
//
// An image's header is read first (libpng, libtiff, libjpeg: no pixel is
// decoded),
// and an image larger than kMaxImagePixels or than its camera is refused
// before the decoder allocates anything: a 400 KB PNG can claim 20000x20000
// pixels, 400 MB to decode and 1.6 GB as floats.
#ifndef ZEBRAGEO_SURVEY_IMAGE_IO_H_
#define ZEBRAGEO_SURVEY_IMAGE_IO_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace zebrageo {

// The largest image zebrageo decodes: 64 megapixels (8000x8000), more than
// any mobile-mapping camera; decoded and converted to float it takes about
// 400 MB.
inline constexpr int64_t kMaxImagePixels = 64'000'000;

struct ImageHeader {
  enum class Format { kPng, kTiff, kJpeg };
  Format format = Format::kPng;
  int width = 0;
  int height = 0;
  int64_t pixels() const { return static_cast<int64_t>(width) * height; }
};

// Reads the header of a PNG, TIFF or JPEG file without decoding its pixels.
// Throws InputError naming `display_name`: unreadable, not PNG, TIFF or JPEG
// ("cannot decode image ..."), or a corrupt header.
ImageHeader ReadImageHeader(const std::string& path,
                            const std::string& display_name);

// Reads `path` as a single-channel CV_32F image with values on a 0..255
// scale (16-bit images are scaled by 255/65535, colour is converted to
// luminance). Throws InputError naming `display_name` when the file is
// missing, unreadable, larger than kMaxImagePixels or, when
// expected_width > 0, not the expected size: both size checks read the
// header only, before decoding.
cv::Mat ReadGrayImage(const std::string& path, const std::string& display_name,
                      int expected_width = 0, int expected_height = 0);

// Builds OpenCV's image codec registry now. Call it on the thread that is
// about to start threads which decode or encode images: OpenCV builds the
// registry on first use behind a function-local static, and the guard's
// fast-path check sits in uninstrumented code, so ThreadSanitizer sees the
// second thread read the codecs' strings the first one wrote with nothing
// ordering them. Built before the threads start, thread creation orders it.
void PrepareImageCodecs();

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_IMAGE_IO_H_
