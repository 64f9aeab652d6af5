#!/usr/bin/env bash
# ctest server_page and server_openapi: the npm checks of the server
# (tests/server/js). Exit 77 (skipped) when Node.js, the npm packages
# (scripts/setup.sh: npm ci) or Chromium are missing.
# Usage: server_page_test.sh page|openapi ZEBRAGEO_BINARY SOURCE_DIR OUT_DIR
set -euo pipefail
what="$1" zebrageo="$2" source_dir="$3" out="$4"
js="$source_dir/tests/server/js"
if ! command -v node >/dev/null || [ ! -d "$js/node_modules" ]; then
  echo "SKIP: node or tests/server/js/node_modules missing (scripts/setup.sh)"
  exit 77
fi
work="$(mktemp -d "${TMPDIR:-/tmp}/zebrageo-server-$what.XXXXXX")"
trap 'rm -rf "$work"' EXIT
if [ "$what" = openapi ]; then
  # The file, and the document a running server serves.
  mkdir "$work/root"
  "$zebrageo" serve --data-root "$work/root" --port 0 >"$work/serve.out" 2>&1 &
  pid=$!
  for _ in $(seq 100); do
    grep -q "listening on" "$work/serve.out" && break
    sleep 0.1
  done
  url="$(grep -o 'http://127.0.0.1:[0-9]*' "$work/serve.out")"
  curl -sf "$url/openapi.json" -o "$work/served.json"
  kill "$pid"
  wait "$pid" || true
  exec node "$js/check_openapi.mjs" "$source_dir/server/openapi.json" \
    "$work/served.json"
fi
if [ ! -x /usr/bin/chromium ]; then
  echo "SKIP: /usr/bin/chromium missing (scripts/setup.sh installs it)"
  exit 77
fi
mkdir -p "$out"
node "$js/check_page.mjs" "$zebrageo" "$work" "$out/server-page.png"
