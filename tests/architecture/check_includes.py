#!/usr/bin/env python3
"""Holds the code to docs/architecture.md: which folder may include which.

Usage: check_includes.py SOURCE_DIR. Reads every #include "folder/file" of
the libraries and tools and fails (exit 1), naming file, line and include,
for an arrow docs/architecture.md does not allow: a stage library including
another, tools/ including a stage library, survey/ including anything of
ours, a library including tools/ or tests/.
"""

import os
import re
import sys

STAGES = {"reconstruction", "registration", "adjustment", "tiepoints"}
# folder -> the folders it may include (besides itself).
ALLOWED = {
    "survey": set(),
    "reconstruction": {"survey"},
    "registration": {"survey"},
    "adjustment": {"survey"},
    "tiepoints": {"survey"},
    "geodata": {"survey"},
    "simulator": {"survey"},
    "pipeline": {"survey", "geodata"} | STAGES,
    "server": {"pipeline", "survey"},
    "campaign": {"pipeline", "survey"},
    "tools": {"pipeline", "survey", "geodata", "simulator", "server",
              "campaign"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([a-z_]+)/[^"]+"')


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    problems = []
    files = 0
    for folder, allowed in ALLOWED.items():
        for dirpath, _, names in os.walk(os.path.join(root, folder)):
            for name in names:
                if not name.endswith((".h", ".cc")):
                    continue
                path = os.path.join(dirpath, name)
                files += 1
                with open(path, encoding="utf-8") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m or m.group(1) == folder:
                            continue
                        if m.group(1) not in allowed:
                            problems.append(
                                f"{os.path.relpath(path, root)}:{number}: "
                                f"{folder}/ must not include {m.group(1)}/ "
                                f"({line.strip()})")
    for p in problems:
        print(p)
    print(f"{files} files, {len(problems)} includes docs/architecture.md "
          "does not allow")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
