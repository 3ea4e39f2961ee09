#!/usr/bin/env python3
"""Lists the longest functions and classes and fails on any above the limits.

A function that does not fit a screen and a half, or a class that does not
fit a few, is where a reader gets lost and where changes collide; the limits
hold for the project's own code in model/, hal/, firmware/ and tools/ (code
generated at build time lives in the build tree and is not read).

Universal Ctags finds the definitions and their last lines, so the count
is of source lines from a definition's first line to its closing brace,
comments and blank lines included.

Usage: check_function_lengths.py <source dir> [--top N]
"""

import argparse
import json
import re
import shutil
import subprocess
import sys

FOLDERS = ("model", "hal", "firmware", "tools")
FUNCTION_LIMIT = 120
CLASS_LIMIT = 400
CLASS_KINDS = ("class", "struct", "union")


def definitions(source_dir):
    ctags = shutil.which("ctags")
    if ctags is None:
        sys.exit("check_function_lengths: ctags not found; "
                 "run: sudo bash tools/install-deps.sh")
    result = subprocess.run(
        [ctags, "-R", "--languages=C,C++", "--kinds-C++=+fp", "--kinds-C=+fp",
         "--fields=+ne", "--extras=-F", "--output-format=json", "-f", "-",
         *FOLDERS],
        cwd=source_dir, capture_output=True, text=True, check=False)
    if result.returncode != 0:
        sys.exit(f"check_function_lengths: ctags failed: {result.stderr.strip()}")
    for line in result.stdout.splitlines():
        tag = json.loads(line)
        if tag.get("_type") != "tag" or "end" not in tag:
            continue
        kind = tag.get("kind")
        if kind == "function" or kind in CLASS_KINDS:
            scope = tag.get("scope", "")
            name = f"{scope}::{tag['name']}" if scope else tag["name"]
            name = re.sub(r"__anon[0-9a-f]+", "(anonymous)", name)
            yield (tag["end"] - tag["line"] + 1, kind, tag["path"], tag["line"], name)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source_dir")
    parser.add_argument("--top", type=int, default=10,
                        help="how many of the longest of each kind to list")
    args = parser.parse_args()

    found = list(definitions(args.source_dir))
    if not found:
        sys.exit("check_function_lengths: ctags found no definitions; "
                 "is it Universal Ctags with JSON output?")
    functions = sorted((d for d in found if d[1] == "function"), reverse=True)
    classes = sorted((d for d in found if d[1] in CLASS_KINDS), reverse=True)

    for title, rows, limit in (("functions", functions, FUNCTION_LIMIT),
                               ("classes", classes, CLASS_LIMIT)):
        print(f"longest {title} (limit {limit} lines):")
        for lines, _, path, first, name in rows[:args.top]:
            print(f"  {lines:5d}  {path}:{first}  {name}")

    too_long = [d for d in functions if d[0] > FUNCTION_LIMIT] + \
               [d for d in classes if d[0] > CLASS_LIMIT]
    for lines, kind, path, first, name in too_long:
        print(f"{path}:{first}: {kind} {name} has {lines} lines", file=sys.stderr)
    if too_long:
        print(f"check_function_lengths: {len(too_long)} definitions over the limits",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
