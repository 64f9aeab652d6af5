#include "survey/image_io.h"

#include <png.h>
#include <tiffio.h>

#include <csetjmp>
#include <cstdio>
// jpeglib.h needs FILE and size_t declared before it.
#include <jpeglib.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

// libtiff's own allocations while reading a header (its directory): a
// crafted file cannot make it take more.
constexpr tmsize_t kMaxTiffHeaderAllocation = 16 << 20;

bool StartsWith(const char* bytes, size_t size, const char* prefix,
                size_t prefix_size) {
  return size >= prefix_size &&
         std::char_traits<char>::compare(bytes, prefix, prefix_size) == 0;
}

// libpng reports errors by longjmp: this function keeps only trivially
// destructible locals between setjmp and the libpng calls, as longjmp skips
// destructors. Returns false on a corrupt header.
bool ReadPngSize(FILE* file, png_uint_32* width, png_uint_32* height) {
  png_structp png = png_create_read_struct(
      PNG_LIBPNG_VER_STRING, nullptr,
      [](png_structp p, png_const_charp) { png_longjmp(p, 1); },
      [](png_structp, png_const_charp) {});
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_chunk_malloc_max(png, 8 << 20);  // text or profile chunks
  png_init_io(png, file);
  png_read_info(png, info);  // the chunks before the image data, no pixel
  *width = png_get_image_width(png, info);
  *height = png_get_image_height(png, info);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

ImageHeader PngHeader(const std::string& path,
                      const std::string& display_name) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"),
                                             &std::fclose);
  if (!file) throw InputError(display_name, 0, "cannot open image file");
  png_uint_32 width = 0, height = 0;
  if (!ReadPngSize(file.get(), &width, &height) || width == 0 || height == 0 ||
      width > 1000000 || height > 1000000) {
    throw InputError(display_name, 0,
                     "cannot decode image: corrupt PNG header");
  }
  ImageHeader header;
  header.format = ImageHeader::Format::kPng;
  header.width = static_cast<int>(width);
  header.height = static_cast<int>(height);
  return header;
}

ImageHeader TiffHeader(const std::string& path,
                       const std::string& display_name) {
  // Errors stay quiet (libtiff would print them): the InputError says it.
  auto quiet = [](TIFF*, void*, const char*, const char*, va_list) {
    return 1;
  };
  std::unique_ptr<TIFFOpenOptions, void (*)(TIFFOpenOptions*)> options(
      TIFFOpenOptionsAlloc(), &TIFFOpenOptionsFree);
  TIFFOpenOptionsSetErrorHandlerExtR(options.get(), quiet, nullptr);
  TIFFOpenOptionsSetWarningHandlerExtR(options.get(), quiet, nullptr);
  TIFFOpenOptionsSetMaxSingleMemAlloc(options.get(), kMaxTiffHeaderAllocation);
  // "rm": read the first directory only, without mapping the file.
  std::unique_ptr<TIFF, void (*)(TIFF*)> tiff(
      TIFFOpenExt(path.c_str(), "rm", options.get()), &TIFFClose);
  uint32_t width = 0, height = 0;
  if (!tiff || !TIFFGetField(tiff.get(), TIFFTAG_IMAGEWIDTH, &width) ||
      !TIFFGetField(tiff.get(), TIFFTAG_IMAGELENGTH, &height) || width == 0 ||
      height == 0 || width > 1000000 || height > 1000000) {
    throw InputError(display_name, 0,
                     "cannot decode image: corrupt TIFF header");
  }
  ImageHeader header;
  header.format = ImageHeader::Format::kTiff;
  header.width = static_cast<int>(width);
  header.height = static_cast<int>(height);
  return header;
}

// libjpeg reports errors through error_exit, which must not return: it
// longjmps back here. As for libpng, only trivially destructible locals live
// between setjmp and the libjpeg calls. Returns false on a corrupt header.
struct JpegErrorManager {
  jpeg_error_mgr base;
  std::jmp_buf jump;
};

bool ReadJpegSize(FILE* file, JDIMENSION* width, JDIMENSION* height) {
  jpeg_decompress_struct info;
  JpegErrorManager error;
  info.err = jpeg_std_error(&error.base);
  error.base.error_exit = [](j_common_ptr common) {
    std::longjmp(reinterpret_cast<JpegErrorManager*>(common->err)->jump, 1);
  };
  error.base.output_message = [](j_common_ptr) {};  // the InputError says it
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  // Markers before the frame header are not kept (EXIF, ICC profiles):
  // libjpeg skips them without allocating.
  jpeg_stdio_src(&info, file);
  jpeg_read_header(&info, TRUE);  // up to the frame header: no pixel
  *width = info.image_width;
  *height = info.image_height;
  jpeg_destroy_decompress(&info);
  return true;
}

// Decodes a JPEG of `width` x `height` as 8-bit luminance (libjpeg's
// grayscale output: the Y of YCbCr, BT.601 as cv::cvtColor's) into
// `pixels` (width * height bytes). Returns false on an error or a warning:
// libjpeg only warns on truncated or corrupt data and fills the rest with
// grey, which must not pass for an image. Only trivially destructible
// locals between setjmp and longjmp.
bool DecodeJpegGray(FILE* file, int width, int height, unsigned char* pixels) {
  jpeg_decompress_struct info;
  JpegErrorManager error;
  info.err = jpeg_std_error(&error.base);
  error.base.error_exit = [](j_common_ptr common) {
    std::longjmp(reinterpret_cast<JpegErrorManager*>(common->err)->jump, 1);
  };
  error.base.output_message = [](j_common_ptr) {};
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_stdio_src(&info, file);
  jpeg_read_header(&info, TRUE);
  info.out_color_space = JCS_GRAYSCALE;
  jpeg_start_decompress(&info);
  if (static_cast<int>(info.output_width) != width ||
      static_cast<int>(info.output_height) != height ||
      info.output_components != 1) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = pixels + static_cast<size_t>(info.output_scanline) * width;
    if (jpeg_read_scanlines(&info, &row, 1) != 1) break;
  }
  const bool complete = info.output_scanline == info.output_height;
  if (complete) jpeg_finish_decompress(&info);
  const bool clean = complete && error.base.num_warnings == 0;
  jpeg_destroy_decompress(&info);
  return clean;
}

ImageHeader JpegHeader(const std::string& path,
                       const std::string& display_name) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"),
                                             &std::fclose);
  if (!file) throw InputError(display_name, 0, "cannot open image file");
  JDIMENSION width = 0, height = 0;
  if (!ReadJpegSize(file.get(), &width, &height) || width == 0 || height == 0) {
    throw InputError(display_name, 0,
                     "cannot decode image: corrupt JPEG header");
  }
  ImageHeader header;
  header.format = ImageHeader::Format::kJpeg;
  header.width = static_cast<int>(width);
  header.height = static_cast<int>(height);
  return header;
}

const char* FormatName(ImageHeader::Format format) {
  switch (format) {
    case ImageHeader::Format::kPng:
      return "PNG";
    case ImageHeader::Format::kTiff:
      return "TIFF";
    case ImageHeader::Format::kJpeg:
      return "JPEG";
  }
  return "image";
}

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace

ImageHeader ReadImageHeader(const std::string& path,
                            const std::string& display_name) {
  char magic[8] = {};
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(display_name, 0, "cannot open image file");
    in.read(magic, sizeof(magic));
  }
  const size_t size = sizeof(magic);
  if (StartsWith(magic, size, "\x89PNG\r\n\x1a\n", 8)) {
    return PngHeader(path, display_name);
  }
  // Little- and big-endian TIFF, and BigTIFF.
  if (StartsWith(magic, size, "II*\0", 4) ||
      StartsWith(magic, size, "MM\0*", 4) ||
      StartsWith(magic, size, "II+\0", 4) ||
      StartsWith(magic, size, "MM\0+", 4)) {
    return TiffHeader(path, display_name);
  }
  // JPEG: a start-of-image marker, then any marker.
  if (StartsWith(magic, size, "\xff\xd8\xff", 3)) {
    return JpegHeader(path, display_name);
  }
  throw InputError(display_name, 0,
                   "cannot decode image (not a PNG, TIFF or JPEG file)");
}

cv::Mat ReadGrayImage(const std::string& path, const std::string& display_name,
                      int expected_width, int expected_height) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw InputError(display_name, 0, "image file does not exist");
  }
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(display_name, 0, "image path is not a file");
  }
  const ImageHeader header = ReadImageHeader(path, display_name);
  if (header.pixels() > kMaxImagePixels) {
    throw InputError(display_name, 0,
                     "image is " + SizeText(header.width, header.height) +
                         " pixels, more than the limit of " +
                         std::to_string(kMaxImagePixels / 1000000) +
                         " megapixels (from its header; not decoded)");
  }
  if (expected_width > 0 &&
      (header.width != expected_width || header.height != expected_height)) {
    throw InputError(display_name, 0,
                     "image is " + SizeText(header.width, header.height) +
                         " pixels but the rig's camera is " +
                         SizeText(expected_width, expected_height) +
                         " (from its header; not decoded)");
  }
  if (header.format == ImageHeader::Format::kJpeg) {
    cv::Mat pixels(header.height, header.width, CV_8UC1);
    std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"),
                                               &std::fclose);
    if (!file ||
        !DecodeJpegGray(file.get(), header.width, header.height, pixels.data)) {
      throw InputError(display_name, 0,
                       "cannot decode image (corrupt or truncated JPEG data, "
                       "or a CMYK JPEG)");
    }
    cv::Mat gray;
    pixels.convertTo(gray, CV_32F);
    return gray;
  }
  cv::Mat raw;
  try {
    // ANYDEPTH keeps 16-bit images 16-bit (the default would cut them to 8).
    raw = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
  } catch (const cv::Exception&) {
    raw.release();  // some decoders throw on corrupt data instead of failing
  }
  if (raw.empty()) {
    throw InputError(display_name, 0,
                     "cannot decode image (corrupt or truncated " +
                         std::string(FormatName(header.format)) + " data)");
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

void PrepareImageCodecs() {
  // Any lookup builds the whole registry (decoders and encoders alike).
  static_cast<void>(cv::haveImageWriter(".png"));
}

}  // namespace zebrageo
