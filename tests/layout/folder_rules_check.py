#!/usr/bin/env python3
"""Every folder under host/src says what lives there and what it may include.

Each folder has a README.md that opens with a paragraph of what lives there, and a line
  May include: a, b, c            (other host/src folders; or "nothing but the SDK")
with, where its tests need more, a line
  Its tests may also include: d
The SDK (tessera/...) may always be included. Every `#include "folder/..."` of a
host/src folder in the folder's sources must be allowed by those lines, so that a new
dependency between folders is a decision written in a README, not an accident.

usage: folder_rules_check.py SOURCE_DIR
"""
import os
import re
import sys

TEST_FILE = re.compile(r"(_test|_benchmark|_fixture)\.(cc|h)$|_test_")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([a-z_0-9]+)/')


def allowed_lists(readme_path):
    """(allowed, allowed in tests) from a README, or a problem string."""
    text = open(readme_path, encoding="utf-8").read()
    paragraphs = [p for p in text.split("\n\n") if p.strip() and not p.lstrip().startswith("#")]
    if not paragraphs:
        return "has no paragraph saying what lives there"
    match = re.search(r"^May include: (.+)$", text, re.MULTILINE)
    if not match:
        return "has no 'May include:' line"

    def names(value):
        value = value.strip()
        return set() if value == "nothing but the SDK" else {n.strip() for n in value.split(",")}

    allowed = names(match.group(1))
    tests = re.search(r"^Its tests may also include: (.+)$", text, re.MULTILINE)
    return allowed, allowed | (names(tests.group(1)) if tests else set())


def main():
    source = sys.argv[1] if len(sys.argv) > 1 else "."
    root = os.path.join(source, "host", "src")
    folders = sorted(d for d in os.listdir(root) if os.path.isdir(os.path.join(root, d)))
    problems = []
    for folder in folders:
        readme = os.path.join(root, folder, "README.md")
        if not os.path.isfile(readme):
            problems.append(f"host/src/{folder}/README.md: missing")
            continue
        rules = allowed_lists(readme)
        if isinstance(rules, str):
            problems.append(f"host/src/{folder}/README.md: {rules}")
            continue
        allowed, allowed_in_tests = rules
        for name in sorted((allowed_in_tests) - set(folders)):
            problems.append(f"host/src/{folder}/README.md: names '{name}', not a folder of host/src")
        for directory, _, files in os.walk(os.path.join(root, folder)):
            for file in sorted(files):
                if not file.endswith((".cc", ".h")):
                    continue
                path = os.path.join(directory, file)
                permitted = allowed_in_tests if TEST_FILE.search(file) else allowed
                with open(path, encoding="utf-8", errors="replace") as lines:
                    for number, line in enumerate(lines, 1):
                        match = INCLUDE.match(line)
                        if not match or match.group(1) not in folders:
                            continue
                        included = match.group(1)
                        if included != folder and included not in permitted:
                            relative = os.path.relpath(path, source)
                            problems.append(
                                f"{relative}:{number}: includes {included}/, which "
                                f"host/src/{folder}/README.md does not allow")
    for problem in problems:
        print(problem)
    print(f"{len(folders)} folders under host/src, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
