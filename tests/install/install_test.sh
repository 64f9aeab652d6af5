#!/usr/bin/env bash
# ctest install: `cmake --install` of the build into a temporary prefix, then
# `zebrageo --version` run from there, from another folder, with the
# prefix's bin/ alone on PATH; and `cpack -G DEB`: a package holding
# usr/bin/zebrageo and declaring its shared libraries and data packages.
# Exit 77 (skipped) when cpack or dpkg-deb is absent.
# Usage: install_test.sh BUILD_DIR EXPECTED_VERSION
set -euo pipefail
build="$(cd "$1" && pwd)"
version="$2"
work="$(mktemp -d "${TMPDIR:-/tmp}/zebrageo-install-test.XXXXXX")"
trap 'rm -rf "$work"' EXIT

cmake --install "$build" --prefix "$work/prefix" >/dev/null
test -x "$work/prefix/bin/zebrageo" || { echo "FAIL: no bin/zebrageo"; exit 1; }
test -f "$work/prefix/share/doc/zebrageo/README.md" || { echo "FAIL: no README"; exit 1; }
mkdir "$work/elsewhere"
got="$(cd "$work/elsewhere" && env PATH="$work/prefix/bin:/usr/bin:/bin" zebrageo --version)"
if [ "$got" != "zebrageo $version" ]; then
  echo "FAIL: zebrageo --version printed '$got', expected 'zebrageo $version'"
  exit 1
fi
echo "installed: $got"

if ! command -v cpack >/dev/null || ! command -v dpkg-deb >/dev/null; then
  echo "SKIP: cpack or dpkg-deb absent (the install passed)"
  exit 77
fi
(cd "$work" && cpack -G DEB --config "$build/CPackConfig.cmake" -B "$work/deb" >/dev/null)
deb="$(ls "$work"/deb/zebrageo_*.deb)"
listing="$(dpkg-deb -c "$deb")"
case "$listing" in
  *" ./usr/bin/zebrageo"*) ;;
  *) echo "FAIL: the package lacks usr/bin/zebrageo"; exit 1 ;;
esac
depends="$(dpkg-deb -f "$deb" Depends)"
echo "Depends: $depends"
# Ceres is linked statically (Debian ships libceres.a): its SuiteSparse
# libraries (libcholmod3...) appear instead.
for needed in libcholmod3 libopencv-core libgdal libproj libyaml-cpp libjpeg62-turbo libexif12 proj-data tzdata; do
  case "$depends" in
    *"$needed"*) ;;
    *) echo "FAIL: Depends lacks $needed"; exit 1 ;;
  esac
done
echo "package: $(basename "$deb")"
