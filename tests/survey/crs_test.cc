#include "survey/crs.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

// Where Debian's proj-data installs the EGM96 geoid (15' grid).
constexpr char kEgm96Grid[] = "/usr/share/proj/egm96_15.gtx";

bool HaveCs2cs() {
  return std::system("cs2cs >/dev/null 2>&1 </dev/null") != 127 * 256;
}

// PROJ's own command line on one WGS84 point, as the independent reference:
// `cs2cs EPSG:4979 TARGET` reads lat lon h and writes the target's axes in
// its authority's order (easting northing for the projected CRSs used here).
Eigen::Vector3d Cs2cs(const std::string& target, const Geodetic& wgs84) {
  std::ostringstream command;
  command.precision(15);
  command << "echo " << wgs84.lat_deg << " " << wgs84.lon_deg << " "
          << wgs84.h_m << " | cs2cs -d 6 EPSG:4979 '" << target << "'";
  FILE* pipe = popen(command.str().c_str(), "r");
  if (pipe == nullptr) return Eigen::Vector3d::Constant(NAN);
  double x = NAN, y = NAN, z = NAN;
  const int read = fscanf(pipe, "%lf %lf %lf", &x, &y, &z);
  pclose(pipe);
  return read == 3 ? Eigen::Vector3d(x, y, z) : Eigen::Vector3d::Constant(NAN);
}

const Geodetic kAmiens{49.8941, 2.2958, 60.0};

TEST(Crs, NamesACompoundCrsFromCodes) {
  const Crs crs("EPSG:2154+5720");
  EXPECT_EQ(crs.identifier(), "EPSG:2154+5720");
  EXPECT_THAT(crs.name(), HasSubstr("Lambert-93"));
  EXPECT_THAT(crs.name(), HasSubstr("NGF-IGN69"));
  EXPECT_TRUE(crs.has_vertical());
  EXPECT_FALSE(crs.is_geographic());
  EXPECT_EQ(crs.horizontal_unit(), "metre");
  EXPECT_THAT(crs.wkt(), HasSubstr("COMPOUNDCRS"));
  EXPECT_THAT(crs.Description(), HasSubstr("height: NGF-IGN69 height"));
}

TEST(Crs, ReadsProjStringsWithoutTypeCrs) {
  const Crs crs("+proj=utm +zone=31 +datum=WGS84 +units=m");
  EXPECT_FALSE(crs.is_geographic());
  EXPECT_FALSE(crs.has_vertical());
  EXPECT_THAT(crs.Description(), HasSubstr("height: ellipsoidal"));
  const Crs feet("EPSG:2263");  // NAD83 / New York Long Island (ftUS)
  EXPECT_THAT(feet.horizontal_unit(), HasSubstr("foot"));
}

TEST(Crs, UnknownCrsIsAClearError) {
  try {
    Crs crs("EPSG:999999");
    FAIL() << "no error";
  } catch (const CrsError& error) {
    EXPECT_THAT(error.what(), HasSubstr("EPSG:999999"));
  }
  EXPECT_THROW(Crs(""), CrsError);
  // A coordinate operation is not a CRS.
  EXPECT_THROW(Crs("EPSG:16031"), CrsError);
}

TEST(Crs, ContractCrsIsRecognised) {
  EXPECT_TRUE(IsContractCrs(""));
  EXPECT_TRUE(IsContractCrs("EPSG:4979"));
  EXPECT_FALSE(IsContractCrs("EPSG:2154"));
  EXPECT_FALSE(IsContractCrs("EPSG:4326+5773"));
}

TEST(CrsTransformer, UtmAgreesWithCs2csToAMillimetre) {
  if (!HaveCs2cs()) GTEST_SKIP() << "cs2cs (Debian proj-bin) is not installed";
  const CrsTransformer transformer{Crs("EPSG:32631")};
  const Eigen::Vector3d xyz = transformer.FromWgs84(kAmiens);
  const Eigen::Vector3d reference = Cs2cs("EPSG:32631", kAmiens);
  EXPECT_LT((xyz - reference).head<2>().norm(), 1e-3);
  EXPECT_NEAR(xyz.z(), kAmiens.h_m, 1e-9);  // no vertical CRS: ellipsoidal
}

TEST(CrsTransformer, Egm96HeightsAgreeWithCs2csToAMillimetre) {
  if (!std::filesystem::exists(kEgm96Grid)) {
    GTEST_SKIP() << kEgm96Grid << " (Debian proj-data) is not installed";
  }
  if (!HaveCs2cs()) GTEST_SKIP() << "cs2cs (Debian proj-bin) is not installed";
  const CrsTransformer transformer{Crs("EPSG:32631+5773")};
  for (const Geodetic& point :
       {kAmiens, Geodetic{49.9, 2.31, 75.5}, Geodetic{-34.6, -58.4, 20.0}}) {
    const Eigen::Vector3d xyz = transformer.FromWgs84(point);
    const Eigen::Vector3d reference = Cs2cs("EPSG:32631+5773", point);
    EXPECT_LT((xyz - reference).norm(), 1e-3)
        << transformer.LastOperationName();
  }
  // The geoid is about 45 m above the ellipsoid at Amiens: the height is not
  // the ellipsoidal one passed through.
  EXPECT_NEAR(kAmiens.h_m - transformer.FromWgs84(kAmiens).z(), 45.0, 3.0);
}

TEST(CrsTransformer, RoundTripsThroughAProjectedCompoundCrs) {
  if (!std::filesystem::exists(kEgm96Grid)) {
    GTEST_SKIP() << kEgm96Grid << " (Debian proj-data) is not installed";
  }
  const CrsTransformer transformer{Crs("EPSG:32631+5773")};
  const Geodetic back = transformer.ToWgs84(transformer.FromWgs84(kAmiens));
  EXPECT_NEAR(back.lat_deg, kAmiens.lat_deg, 1e-10);
  EXPECT_NEAR(back.lon_deg, kAmiens.lon_deg, 1e-10);
  EXPECT_NEAR(back.h_m, kAmiens.h_m, 1e-4);
}

TEST(CrsTransformer, GeographicCrsIsLongitudeFirstInDegrees) {
  const CrsTransformer transformer{Crs("EPSG:4326")};
  const Eigen::Vector3d xyz = transformer.FromWgs84(kAmiens);
  EXPECT_NEAR(xyz.x(), kAmiens.lon_deg, 1e-12);
  EXPECT_NEAR(xyz.y(), kAmiens.lat_deg, 1e-12);
}

TEST(CrsTransformer, MissingGeoidGridIsAnErrorNamingIt) {
  try {
    CrsTransformer transformer{Crs(
        "+proj=longlat +datum=WGS84 +geoidgrids=zebrageo_no_such_geoid.gtx")};
    FAIL() << "no error";
  } catch (const CrsError& error) {
    EXPECT_THAT(error.what(), HasSubstr("zebrageo_no_such_geoid.gtx"));
    EXPECT_THAT(error.what(), HasSubstr("missing"));
  }
}

TEST(CrsTransformer, NgfIgn69WithoutItsGridIsNeverEllipsoidal) {
  // Debian's proj-data does not ship the French RAF geoid grids; PROJ's
  // cs2cs then passes the ellipsoidal height through. Here: an error naming
  // the grid, or (when a grid is installed) a height ~45 m below.
  try {
    const CrsTransformer transformer{Crs("EPSG:2154+5720")};
    EXPECT_NEAR(kAmiens.h_m - transformer.FromWgs84(kAmiens).z(), 45.0, 3.0);
  } catch (const CrsError& error) {
    EXPECT_THAT(error.what(), HasSubstr("fr_ign_RAF"));
  }
}

TEST(CrsTransformer, UserGridFolderIsSearched) {
  if (!std::filesystem::exists(kEgm96Grid)) {
    GTEST_SKIP() << kEgm96Grid << " (Debian proj-data) is not installed";
  }
  TemporaryFolder folder;
  std::filesystem::copy_file(kEgm96Grid, folder.Path("my_geoid.gtx"));
  const std::string definition =
      "+proj=utm +zone=31 +datum=WGS84 +geoidgrids=my_geoid.gtx";
  EXPECT_THROW(CrsTransformer{Crs(definition)}, CrsError);
  CrsOptions options;
  options.grid_dirs = {folder.Path()};
  const CrsTransformer transformer(Crs(definition), options);
  const CrsTransformer debian{Crs("EPSG:32631+5773")};
  EXPECT_LT((transformer.FromWgs84(kAmiens) - debian.FromWgs84(kAmiens)).norm(),
            1e-3);
}

}  // namespace
}  // namespace zebrageo
