# Installing zebrageo (`cmake --install BUILD --prefix PREFIX`) and a Debian
# package (`cpack -G DEB` in the build folder): docs/install.md.
#
# The command is one executable: the project's libraries are static, so
# what it needs at run time is Debian's shared libraries (found by
# dpkg-shlibdeps from the binary: Ceres, OpenCV, GDAL, PROJ, yaml-cpp, ...)
# and two data packages it reads by path: proj-data (PROJ's grids, EGM96)
# and tzdata (/usr/share/zoneinfo/leap-seconds.list, GPS - UTC).
include(GNUInstallDirs)

install(TARGETS zebrageo RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}
        FILES_MATCHING PATTERN "*.md" PATTERN "*.png")

set(CPACK_PACKAGE_NAME zebrageo)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "zebrageo")
set(CPACK_PACKAGE_CONTACT "zebrageo maintainers <zebrageo@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "centimetre georeferencing of mobile-mapping surveys with zebra crossings as ground control")
set(CPACK_PACKAGE_DESCRIPTION
    "Reconstructs zebra-crossing bands from a vehicle's stereo images, matches them to a road-mark database and corrects the GNSS/INS trajectory in a bundle adjustment.")
set(CPACK_GENERATOR DEB)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# The shared libraries the binary links, as dpkg-shlibdeps finds them.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# Data read by path at run time (no library links to them).
set(CPACK_DEBIAN_PACKAGE_DEPENDS "proj-data, tzdata")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "gdal-bin, proj-bin")
set(CPACK_STRIP_FILES ON)
include(CPack)
