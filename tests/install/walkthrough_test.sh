#!/usr/bin/env bash
# ctest readme_walkthrough: the shell commands of README.md's walkthrough
# (the ```sh blocks after the line "<!-- walkthrough -->", up to the next
# "## " heading) run as written, in an empty folder outside the clone, with
# zebrageo installed (`cmake --install`) to a temporary prefix whose bin/
# alone is added to the system PATH. Any command failing fails the test.
# Exit 77 (skipped) when README.md has no such block.
# Usage: walkthrough_test.sh README BUILD_DIR
set -euo pipefail
readme="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
build="$(cd "$2" && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/zebrageo-walkthrough.XXXXXX")"
trap 'rm -rf "$work"' EXIT

awk '
  /<!-- walkthrough -->/ { on = 1; next }
  on && /^## / { exit }
  on && /^```sh[ \t]*$/ { code = 1; next }
  on && code && /^```[ \t]*$/ { code = 0; next }
  on && code { print }
' "$readme" > "$work/walkthrough.sh"
if [ ! -s "$work/walkthrough.sh" ]; then
  echo "SKIP: $readme has no \`\`\`sh block after <!-- walkthrough -->"
  exit 77
fi
echo "--- the walkthrough, as README.md writes it:"
cat "$work/walkthrough.sh"
echo "---"

cmake --install "$build" --prefix "$work/prefix" >/dev/null
mkdir "$work/home" "$work/user"
cd "$work/user"
env -i HOME="$work/home" TMPDIR="$work" LANG=C.UTF-8 \
  PATH="$work/prefix/bin:/usr/local/bin:/usr/bin:/bin" \
  bash -euo pipefail -x "$work/walkthrough.sh"
echo "the walkthrough ran: $(ls "$work/user" | tr '\n' ' ')"
