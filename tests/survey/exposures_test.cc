#include "survey/exposures.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "survey/input_error.h"
#include "tests/survey/damaged_input.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

const char kHeader[] = "exposure_id,time,camera,image\n";

Rig StereoRig() {
  Rig rig;
  for (const char* name : {"left", "right"}) {
    RigCamera camera;
    camera.camera = Camera(name, 640, 480, 500, 500, 319.5, 239.5, {});
    rig.cameras.push_back(camera);
  }
  rig.stereo_pairs = {{0, 1}};
  return rig;
}

std::string ErrorOf(const std::string& text) {
  try {
    ParseExposures(text, "exposures.csv", StereoRig());
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

TEST(Exposures, GroupsImagesByExposureSortedByTime) {
  const std::string text = std::string("# written by a test\n") + kHeader +
                           "17,100.5,left,images/l17.png\n"
                           "17,100.5,right,images/r17.png\n"
                           "3,100.2,right,images/r3.png\n"
                           "9,100.5,left,images/l9.png\n";
  const ExposureTable table =
      ParseExposures(text, "exposures.csv", StereoRig());
  ASSERT_EQ(table.images.size(), 4u);
  EXPECT_EQ(table.images[0].exposure_id, 17);
  EXPECT_EQ(table.images[0].camera, 0);
  EXPECT_EQ(table.images[1].camera, 1);
  EXPECT_EQ(table.images[2].image, "images/r3.png");
  EXPECT_EQ(table.images[2].line, 5);
  ASSERT_EQ(table.exposures.size(), 3u);
  // By time, then id for equal times.
  EXPECT_EQ(table.exposures[0].exposure_id, 3);
  EXPECT_EQ(table.exposures[1].exposure_id, 9);
  EXPECT_EQ(table.exposures[2].exposure_id, 17);
  EXPECT_EQ(table.exposures[0].time, 100.2);
  EXPECT_EQ(table.exposures[0].image_of_camera, (std::vector<int>{-1, 2}));
  EXPECT_EQ(table.exposures[1].image_of_camera, (std::vector<int>{3, -1}));
  EXPECT_EQ(table.exposures[2].image_of_camera, (std::vector<int>{0, 1}));
}

TEST(Exposures, WriteThenReadIsExact) {
  TemporaryFolder folder;
  const Rig rig = StereoRig();
  const std::string text = std::string(kHeader) +
                           "1000001,345678.123456789,left,a/l.png\n"
                           "1000001,345678.123456789,right,a/r.png\n"
                           "-5,0.1,right,b.tif\n";
  const ExposureTable table = ParseExposures(text, "exposures.csv", rig);
  WriteExposures(table, rig, folder.Path("exposures.csv"));
  EXPECT_EQ(folder.CountEntries(), 1);  // no temporary file left
  const ExposureTable read =
      ReadExposures(folder.Path("exposures.csv"), "exposures.csv", rig);
  ASSERT_EQ(read.images.size(), table.images.size());
  for (size_t i = 0; i < table.images.size(); ++i) {
    EXPECT_EQ(read.images[i].exposure_id, table.images[i].exposure_id);
    EXPECT_EQ(read.images[i].time, table.images[i].time);
    EXPECT_EQ(read.images[i].camera, table.images[i].camera);
    EXPECT_EQ(read.images[i].image, table.images[i].image);
  }
  ASSERT_EQ(read.exposures.size(), 2u);
  EXPECT_EQ(read.exposures[0].exposure_id, -5);
}

TEST(Exposures, WriteToAMissingFolderThrowsAndLeavesNothing) {
  TemporaryFolder folder;
  const Rig rig = StereoRig();
  const ExposureTable table = ParseExposures(
      std::string(kHeader) + "1,2,left,x.png\n", "exposures.csv", rig);
  EXPECT_ANY_THROW(WriteExposures(table, rig, folder.Path("no/e.csv")));
  EXPECT_EQ(folder.CountEntries(), 0);
}

TEST(Exposures, RejectsUnknownCameraNamingTheRigsCameras) {
  EXPECT_THAT(ErrorOf(std::string(kHeader) + "1,2.0,left,a.png\n" +
                      "1,2.0,centre,b.png\n"),
              HasSubstr("exposures.csv:3: camera 'centre' is not in the rig "
                        "(cameras: left, right)"));
}

TEST(Exposures, RejectsNonFiniteTimes) {
  EXPECT_THAT(ErrorOf(std::string(kHeader) + "1,nan,left,a.png\n"),
              HasSubstr("exposures.csv:2: column 'time': \"nan\" is not "
                        "finite"));
  EXPECT_THAT(
      ErrorOf(std::string(kHeader) + "1,2,left,a.png\n" + "2,inf,left,a.png\n"),
      HasSubstr("exposures.csv:3: column 'time': \"inf\" is not "
                "finite"));
}

TEST(Exposures, RejectsMalformedRows) {
  EXPECT_THAT(ErrorOf(std::string(kHeader) + "1,2.0,left\n"),
              HasSubstr("exposures.csv:2: truncated row"));
  EXPECT_THAT(ErrorOf(std::string(kHeader) + "1.5,2.0,left,a.png\n"),
              HasSubstr("exposures.csv:2: column 'exposure_id': \"1.5\" is "
                        "not an integer"));
  EXPECT_THAT(ErrorOf(std::string(kHeader) + "1,2.0,left,\"a.png\"\n"),
              HasSubstr("exposures.csv:2: quoted fields are not supported"));
  EXPECT_THAT(ErrorOf("exposure_id,time,image\n1,2,a.png\n"),
              HasSubstr("exposures.csv:1: header lacks required column "
                        "'camera'"));
  EXPECT_THAT(ErrorOf(std::string(kHeader) + "1,2.0,left, \n"),
              HasSubstr("exposures.csv:2: empty image path"));
  EXPECT_THAT(ErrorOf(std::string("# only a header\n") + kHeader),
              HasSubstr("exposures.csv: no exposures"));
}

TEST(Exposures, RejectsImagesOfOneExposureAtDifferentTimes) {
  EXPECT_THAT(ErrorOf(std::string(kHeader) + "7,2.0,left,a.png\n" +
                      "7,2.001,right,b.png\n"),
              HasSubstr("exposures.csv:3: exposure 7 has time 2.001 here but "
                        "2 on line 2"));
}

TEST(Exposures, RejectsTwoImagesOfOneCameraInAnExposure) {
  EXPECT_THAT(ErrorOf(std::string(kHeader) + "7,2.0,left,a.png\n" +
                      "7,2.0,left,b.png\n"),
              HasSubstr("exposures.csv:3: exposure 7 has two images of camera "
                        "'left' (the other on line 2)"));
}

// Damaged files are refused naming exposures.csv, the line and the problem,
// or still parse to what their rows say: at most the three images, each of
// a camera of the rig, two per exposure at most.
TEST(Exposures, TruncatedOrCorruptedFilesAreRefusedByLineOrReadSoundly) {
  const std::string text = std::string(kHeader) +
                           "1,100.25,left,images/l1.png\n"
                           "1,100.25,right,images/r1.png\n"
                           "2,100.5,left,images/l2.png\n";
  const Rig rig = StereoRig();
  const DamageCounts counts = ParseDamagedCopies(
      text, "exposures.csv", {'\0', ',', '\n', '"', 'e', '\xff'},
      [&](const std::string& damaged) {
        const ExposureTable table =
            ParseExposures(damaged, "exposures.csv", rig);
        EXPECT_GE(table.images.size(), 1u);
        EXPECT_LE(table.images.size(), 3u);
        EXPECT_LE(table.exposures.size(), table.images.size());
        for (const ExposureImage& image : table.images) {
          EXPECT_TRUE(image.camera == 0 || image.camera == 1);
          EXPECT_FALSE(image.image.empty());
        }
        for (size_t k = 1; k < table.exposures.size(); ++k) {
          EXPECT_LE(table.exposures[k - 1].time, table.exposures[k].time);
        }
      });
  EXPECT_GT(counts.refused, 0);
  EXPECT_GT(counts.parsed, 0);
  // Cut after the first data row: one exposure with its left image only.
  const ExposureTable first = ParseExposures(
      text.substr(0, text.find("1,100.25,right")), "exposures.csv", rig);
  ASSERT_EQ(first.exposures.size(), 1u);
  EXPECT_EQ(first.exposures[0].image_of_camera, (std::vector<int>{0, -1}));
  // Cut inside the header: the missing column is named on line 1.
  EXPECT_THAT(ErrorOf(text.substr(0, 20)),
              HasSubstr("exposures.csv:1: header lacks required column"));
}

}  // namespace
}  // namespace zebrageo
