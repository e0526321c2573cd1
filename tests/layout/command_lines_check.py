#!/usr/bin/env python3
"""Only one library file writes the command line of a `tessera` child process.

The processes Tessera starts of itself (bench's rows, the cluster processes of
`map --hierarchical`, the jobs in `tessera slurm`'s batch scripts) take their command
lines from host/src/util/tessera_commands.{h,cc}; cli/ parses and prints, and may name
verbs as it likes. Any other library source under host/src (tests aside) that assembles a
`tessera` command line itself is reported, with its line:
  - an argv: a verb literal followed by an option literal, `"map", "--cluster"`;
  - a script line: a literal that begins with a verb and an option and goes on with a
    value appended, `"extract --images " + images`.
Messages that name a verb (`"map --hierarchical: ..."`, "for merge --stage map", and
`"map --cluster " + k + ": no model ..."`, whose next literal begins with a colon) are
not command lines and pass.

usage: command_lines_check.py SOURCE_DIR
"""
import os
import re
import sys

VERBS = ("run|extract|match|map|merge|partition|export|plugins|eval|bench|vocab|slurm|gui|"
         "quarantine")
ARGV = re.compile(r'"(%s)"\s*,\s*"--[a-z]' % VERBS)
SCRIPT = re.compile(r'"(%s) --[a-z][a-z-]* [^"\n]*"\s*\+' % VERBS)
DESIGNATED = {os.path.join("util", "tessera_commands.h"), os.path.join("util", "tessera_commands.cc")}
TEST_FILE = re.compile(r"(_test|_benchmark|_fixture)\.(cc|h)$|_test_")


def without_comments(text):
    """The text with // comments blanked (kept line for line), string literals kept."""
    lines = []
    for line in text.split("\n"):
        stripped = line.lstrip()
        lines.append("" if stripped.startswith("//") else line)
    return "\n".join(lines)


NEXT_LITERAL = re.compile(r'[^";]*?"([^"\n]*)"')


def names_a_message(text, end):
    """Whether the expression that a script-line literal starts, at `end`, goes on with a
    literal that begins with a colon: `"map --cluster " + k + ": no model"`, a message."""
    following = NEXT_LITERAL.match(text, end)
    return bool(following) and following.group(1).startswith(":")


def problems_in(path, relative):
    text = without_comments(open(path, encoding="utf-8").read())
    found = []
    for pattern, what in ((ARGV, "an argv"), (SCRIPT, "a script line")):
        for match in pattern.finditer(text):
            if pattern is SCRIPT and names_a_message(text, match.end()):
                continue
            line = text.count("\n", 0, match.start()) + 1
            words = " ".join(match.group(0).split())
            found.append(f"host/src/{relative}:{line}: assembles {what} of `tessera "
                         f"{match.group(1)}` ({words}); build it in util/tessera_commands.h")
    return found


def main():
    source = sys.argv[1] if len(sys.argv) > 1 else "."
    root = os.path.join(source, "host", "src")
    problems = []
    checked = 0
    for directory, _, files in os.walk(root):
        for file in sorted(files):
            if not file.endswith((".cc", ".h")) or TEST_FILE.search(file):
                continue
            relative = os.path.relpath(os.path.join(directory, file), root)
            if relative.startswith("cli" + os.sep) or relative in DESIGNATED:
                continue
            checked += 1
            problems += problems_in(os.path.join(directory, file), relative)
    if checked == 0:
        problems.append(f"{root}: no source files found")
    for problem in problems:
        print(problem)
    if problems:
        return 1
    print(f"{checked} library files: no `tessera` command line outside util/tessera_commands")
    return 0


if __name__ == "__main__":
    sys.exit(main())
