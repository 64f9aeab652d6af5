#!/usr/bin/env bash
# Installs the Debian packages zebrageo needs, when they are missing.
# Safe to run repeatedly: it only calls apt-get when something is absent.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"

PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config git clang libclang-rt-14-dev
  libeigen3-dev libceres-dev libsuitesparse-dev libgoogle-glog-dev libgflags-dev
  libopencv-dev libopencv-contrib-dev libgeographiclib-dev
  libyaml-cpp-dev nlohmann-json3-dev libsimdjson-dev libcli11-dev libbz2-dev
  libpng-dev libtiff-dev libjpeg-dev libexif-dev
  zlib1g-dev tzdata libgdal-dev gdal-bin
  libgtest-dev libgmock-dev libbenchmark-dev
  libboost-dev
  libproj-dev proj-bin proj-data
  postgresql postgresql-client postgresql-15-postgis-3
  python3 python3-numpy python3-opencv python3-yaml
  chromium
  libcpp-httplib-dev libsqlite3-dev libarchive-dev python3-prometheus-client
  slurm-wlm munge
)

# The npm tools of the server's tests (tests/server/js: an OpenAPI validator,
# puppeteer-core driving Debian's Chromium), exactly as package-lock.json
# pins them. Node.js and npm come with the machine; without them the tests
# that need them skip.
install_npm_tools() {
  local js="$here/tests/server/js"
  if ! command -v npm >/dev/null 2>&1 || [ ! -f "$js/package-lock.json" ]; then
    return 0
  fi
  if [ -f "$js/node_modules/.package-lock.json" ] &&
    [ "$js/node_modules/.package-lock.json" -nt "$js/package-lock.json" ]; then
    return 0
  fi
  echo "setup: npm ci in tests/server/js" >&2
  (cd "$js" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
}

missing=()
for package in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  install_npm_tools
  exit 0
fi

echo "setup: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "setup: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
install_npm_tools
echo "setup: done" >&2
