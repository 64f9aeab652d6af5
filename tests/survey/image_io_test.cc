#include "survey/image_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <opencv2/imgcodecs.hpp>
#include <string>

#include "survey/input_error.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

// The chunks of a PNG up to its (empty) image data: the signature, an IHDR
// claiming width x height 8-bit grey pixels, and an IDAT of no bytes. What
// a header reader sees of any PNG of that size.
std::string PngHeaderClaiming(uint32_t width, uint32_t height) {
  auto big_endian = [](uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                       static_cast<char>(v >> 8), static_cast<char>(v)};
  };
  auto chunk = [&](const std::string& type, const std::string& data) {
    const std::string body = type + data;
    const uLong crc =
        crc32(crc32(0, nullptr, 0), reinterpret_cast<const Bytef*>(body.data()),
              static_cast<uInt>(body.size()));
    return big_endian(static_cast<uint32_t>(data.size())) + body +
           big_endian(static_cast<uint32_t>(crc));
  };
  const std::string ihdr = big_endian(width) + big_endian(height) +
                           std::string("\x08\x00\x00\x00\x00", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) +
         chunk("IDAT", "");
}

std::string ErrorOfRead(const std::string& path, int width = 0,
                        int height = 0) {
  try {
    ReadGrayImage(path, "images/x.png", width, height);
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

TEST(ReadGrayImage, Reads8BitGreyAsFloat) {
  TemporaryFolder folder;
  cv::Mat image(3, 4, CV_8UC1);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) image.at<uint8_t>(r, c) = 20 * r + c;
  }
  const std::string path = folder.Path("grey.png");
  ASSERT_TRUE(cv::imwrite(path, image));
  const cv::Mat read = ReadGrayImage(path, "grey.png", 4, 3);
  ASSERT_EQ(read.type(), CV_32FC1);
  EXPECT_EQ(read.cols, 4);
  EXPECT_EQ(read.rows, 3);
  EXPECT_EQ(read.at<float>(2, 3), 43.0f);
  EXPECT_EQ(read.at<float>(0, 0), 0.0f);
}

TEST(ReadGrayImage, Scales16BitTo255) {
  TemporaryFolder folder;
  cv::Mat image(2, 2, CV_16UC1, cv::Scalar(0));
  image.at<uint16_t>(0, 1) = 65535;
  image.at<uint16_t>(1, 0) = 257 * 100;
  for (const char* name : {"deep.png", "deep.tif"}) {
    const std::string path = folder.Path(name);
    ASSERT_TRUE(cv::imwrite(path, image));
    const cv::Mat read = ReadGrayImage(path, name);
    ASSERT_EQ(read.type(), CV_32FC1) << name;
    EXPECT_NEAR(read.at<float>(0, 1), 255.0f, 1e-4) << name;
    EXPECT_NEAR(read.at<float>(1, 0), 100.0f, 1e-4) << name;
    EXPECT_EQ(read.at<float>(0, 0), 0.0f) << name;
  }
}

TEST(ReadGrayImage, ConvertsColourToLuminance) {
  TemporaryFolder folder;
  // BGR: pure red, pure green, pure blue, white.
  cv::Mat image(1, 4, CV_8UC3);
  image.at<cv::Vec3b>(0, 0) = cv::Vec3b(0, 0, 200);
  image.at<cv::Vec3b>(0, 1) = cv::Vec3b(0, 200, 0);
  image.at<cv::Vec3b>(0, 2) = cv::Vec3b(200, 0, 0);
  image.at<cv::Vec3b>(0, 3) = cv::Vec3b(255, 255, 255);
  const std::string path = folder.Path("colour.png");
  ASSERT_TRUE(cv::imwrite(path, image));
  const cv::Mat read = ReadGrayImage(path, "colour.png");
  ASSERT_EQ(read.type(), CV_32FC1);
  // ITU-R BT.601 weights, as cv::cvtColor.
  EXPECT_NEAR(read.at<float>(0, 0), 0.299f * 200, 0.01);
  EXPECT_NEAR(read.at<float>(0, 1), 0.587f * 200, 0.01);
  EXPECT_NEAR(read.at<float>(0, 2), 0.114f * 200, 0.01);
  EXPECT_NEAR(read.at<float>(0, 3), 255.0f, 0.01);
}

TEST(ReadGrayImage, RejectsAMissingFile) {
  TemporaryFolder folder;
  EXPECT_THAT(ErrorOfRead(folder.Path("absent.png")),
              HasSubstr("images/x.png: image file does not exist"));
}

TEST(ReadGrayImage, RejectsGarbageBytes) {
  TemporaryFolder folder;
  const std::string path = folder.Write(
      "garbage.png", std::string("\x89PNG\r\n\x1a\n\x01\x02garbage", 18));
  EXPECT_THAT(ErrorOfRead(path),
              HasSubstr("images/x.png: cannot decode image: corrupt PNG "
                        "header"));
  const std::string text = folder.Write("text.png", "hello, world\n");
  EXPECT_THAT(ErrorOfRead(text),
              HasSubstr("cannot decode image (not a PNG, TIFF or JPEG file)"));
  // A valid header and nothing after it.
  const std::string truncated =
      folder.Write("truncated.png", PngHeaderClaiming(64, 48));
  EXPECT_THAT(ErrorOfRead(truncated),
              HasSubstr("cannot decode image (corrupt or truncated PNG "
                        "data)"));
  const std::string empty = folder.Write("empty.png", "");
  EXPECT_THAT(ErrorOfRead(empty), HasSubstr("cannot decode image"));
}

TEST(ReadImageHeader, GivesTheSizeOfPngAndTiffWithoutDecoding) {
  TemporaryFolder folder;
  const cv::Mat image(48, 64, CV_16UC1, cv::Scalar(7));
  for (const char* name : {"a.png", "a.tif"}) {
    ASSERT_TRUE(cv::imwrite(folder.Path(name), image));
    const ImageHeader header = ReadImageHeader(folder.Path(name), name);
    EXPECT_EQ(header.width, 64) << name;
    EXPECT_EQ(header.height, 48) << name;
    EXPECT_EQ(header.format, std::string(name) == "a.png"
                                 ? ImageHeader::Format::kPng
                                 : ImageHeader::Format::kTiff);
  }
  // Only the header is read: a 20000x20000 claim with no pixel data.
  const ImageHeader big = ReadImageHeader(
      folder.Write("big.png", PngHeaderClaiming(20000, 20000)), "big.png");
  EXPECT_EQ(big.pixels(), 400000000);
}

TEST(ReadGrayImage, RefusesAnImageOverTheLimitBeforeDecodingIt) {
  TemporaryFolder folder;
  // The old reader decoded first: 400 MB, then 1.6 GB as floats.
  const std::string path =
      folder.Write("big.png", PngHeaderClaiming(20000, 20000));
  for (const int width : {0, 1280}) {
    EXPECT_THAT(ErrorOfRead(path, width, 960),
                HasSubstr("images/x.png: image is 20000x20000 pixels, more "
                          "than the limit of 64 megapixels (from its header; "
                          "not decoded)"));
  }
  const std::string small =
      folder.Write("small.png", PngHeaderClaiming(1280, 960));
  EXPECT_THAT(ErrorOfRead(small, 640, 480),
              HasSubstr("image is 1280x960 pixels but the rig's camera is "
                        "640x480 (from its header; not decoded)"));
}

TEST(ReadGrayImage, RejectsAnImageOfTheWrongSize) {
  TemporaryFolder folder;
  const std::string path = folder.Path("small.png");
  ASSERT_TRUE(cv::imwrite(path, cv::Mat(48, 64, CV_8UC1, cv::Scalar(7))));
  EXPECT_THAT(ErrorOfRead(path, 1920, 1080),
              HasSubstr("images/x.png: image is 64x48 pixels but the rig's "
                        "camera is 1920x1080"));
  EXPECT_EQ(ReadGrayImage(path, "small.png", 64, 48).at<float>(0, 0), 7.0f);
}

// A small JPEG whose frame header (SOF) claims `width` x `height`: the
// header reader sees that size; the pixel data are the small image's.
std::string JpegClaiming(int width, int height) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(".jpg",
                           cv::Mat(48, 64, CV_8UC3, cv::Scalar(1, 2, 3)), bytes,
                           {cv::IMWRITE_JPEG_QUALITY, 95}));
  std::string jpeg(bytes.begin(), bytes.end());
  const size_t sof = jpeg.find("\xff\xc0");
  EXPECT_NE(sof, std::string::npos);
  jpeg[sof + 5] = static_cast<char>(height >> 8);
  jpeg[sof + 6] = static_cast<char>(height & 0xff);
  jpeg[sof + 7] = static_cast<char>(width >> 8);
  jpeg[sof + 8] = static_cast<char>(width & 0xff);
  return jpeg;
}

TEST(ReadGrayImage, ReadsJpegThroughTheSameHeaderFirstLimits) {
  TemporaryFolder folder;
  const cv::Mat colour(48, 64, CV_8UC3, cv::Scalar(40, 120, 200));
  ASSERT_TRUE(cv::imwrite(folder.Path("a.jpg"), colour,
                          {cv::IMWRITE_JPEG_QUALITY, 100}));
  const ImageHeader header = ReadImageHeader(folder.Path("a.jpg"), "a.jpg");
  EXPECT_EQ(header.format, ImageHeader::Format::kJpeg);
  EXPECT_EQ(header.width, 64);
  EXPECT_EQ(header.height, 48);
  // Luminance of BGR (40, 120, 200): 0.299 R + 0.587 G + 0.114 B = 134.8.
  const cv::Mat gray = ReadGrayImage(folder.Path("a.jpg"), "a.jpg", 64, 48);
  EXPECT_NEAR(gray.at<float>(24, 32), 134.8, 2.0);
  // 60000 x 60000 claimed: refused from the header, never decoded.
  const std::string big = folder.Write("big.jpg", JpegClaiming(60000, 60000));
  EXPECT_THAT(ErrorOfRead(big),
              HasSubstr("image is 60000x60000 pixels, more than the limit of "
                        "64 megapixels (from its header; not decoded)"));
  EXPECT_THAT(
      ErrorOfRead(folder.Write("wide.jpg", JpegClaiming(1280, 960)), 640, 480),
      HasSubstr("image is 1280x960 pixels but the rig's camera is "
                "640x480 (from its header; not decoded)"));
  // A start-of-image marker and garbage.
  EXPECT_THAT(ErrorOfRead(folder.Write("bad.jpg",
                                       std::string("\xff\xd8\xff\x01xx", 6))),
              HasSubstr("cannot decode image: corrupt JPEG header"));
  // The header and half of the data: libjpeg would fill the rest with grey
  // and only warn; that is refused.
  cv::Mat noise(480, 640, CV_8UC1);
  cv::randu(noise, 0, 255);
  std::vector<uchar> bytes;
  ASSERT_TRUE(cv::imencode(".jpg", noise, bytes));
  const std::string whole(bytes.begin(), bytes.end());
  EXPECT_THAT(
      ErrorOfRead(folder.Write("cut.jpg", whole.substr(0, whole.size() / 2))),
      HasSubstr("cannot decode image (corrupt or truncated JPEG "
                "data"));
}

}  // namespace
}  // namespace zebrageo
