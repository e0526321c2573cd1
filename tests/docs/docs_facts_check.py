#!/usr/bin/env python3
"""The paths and versions that the docs name are checked against the tree, without a build.

Every Markdown file of the repository (README.md, docs/, each folder's README.md):
- each code span or link target that names a file or folder of the repository
  (`host/src/sfm/global_mapper.cc`, `plugins/mappers/global/README.md`,
  `tests/end_to_end/partition_test.sh:80`, `io/names.h` inside host/src/) exists; a
  `{h,cc}` pair is checked as its two files, and spans with placeholders (`<kind>`, `N`,
  `*`, `...`) are left alone; `examples/NAME` in a guide may be the installed examples
  (tests/third_party_plugin/);
- each `libtessera_NAME.so.N` names the plugin ABI version of host/include/tessera/plugin.h;
- README.md's status (the quoted block that starts "> Status:") is at most ten lines.
The `tessera` commands the docs give are checked against the binary by
docs_commands_test.py.

usage: docs_facts_check.py SOURCE_DIR
"""
import glob
import os
import re
import sys

TOP = ("host/", "plugins/", "docs/", "tests/", "scripts/", "manifests/", "benchmarks/",
       "python/", "examples/", "cmake/", ".ci/")
CODE_SPAN = re.compile(r"`([^`\n]+)`")
SONAME = re.compile(r"libtessera_[a-z_]+\.so\.(\d+)\b")
MAX_STATUS_LINES = 10
PLACEHOLDER = re.compile(r"[<>*$]|\.\.\.|(^|/)[A-Z][A-Z_0-9]*(/|$|\.)")
# The installed doc tree puts tests/third_party_plugin/ at examples/ beside the guides.
INSTALLED_AS = {"examples/": "tests/third_party_plugin/"}


def markdown_files(source):
    skip = {"build", "build-asan", ".git", "node_modules"}
    for directory, folders, files in os.walk(source):
        folders[:] = sorted(f for f in folders if f not in skip and not f.startswith("build"))
        for file in sorted(files):
            if file.endswith(".md"):
                yield os.path.join(directory, file)


def candidates(span):
    """The repository paths a code span names: '' where it names none."""
    token = span.strip().split()[0] if span.strip() else ""
    token = re.sub(r":\d+(-\d+)?$", "", token).rstrip(".,;)")
    if not token or PLACEHOLDER.search(token) or "://" in token:
        return []
    braces = re.match(r"^(.*)\{([^}]*)\}(.*)$", token)
    if braces:
        return [braces.group(1) + part + braces.group(3) for part in braces.group(2).split(",")]
    return [token]


def exists(source, document, path):
    if path.startswith(TOP):
        if os.path.exists(os.path.join(source, path)):
            return True
        return any(path.startswith(installed) and
                   os.path.exists(os.path.join(source, repository + path[len(installed):]))
                   for installed, repository in INSTALLED_AS.items())
    # A path relative to host/src (`io/names.h`) or to the document's own folder.
    return (os.path.exists(os.path.join(source, "host", "src", path)) or
            os.path.exists(os.path.join(os.path.dirname(document), path)))


def looks_like_repository_path(path):
    if path.startswith(TOP):
        return True
    first = path.split("/")[0]
    return ("/" in path and re.match(r"^[a-z_]+/[a-z_0-9./]+\.(h|cc|md|sh|py|json)$", path) and
            first in HOST_FOLDERS)


HOST_FOLDERS = set()


def status_lines(readme):
    """The number of lines of README.md's status block ('> Status:' and the '>' lines after)."""
    lines = open(readme, encoding="utf-8").read().splitlines()
    starts = [k for k, line in enumerate(lines) if line.startswith("> Status:")]
    if not starts:
        return 0
    end = starts[0]
    while end < len(lines) and lines[end].startswith(">"):
        end += 1
    return end - starts[0]


def main():
    source = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
    HOST_FOLDERS.update(os.listdir(os.path.join(source, "host", "src")))
    plugin_h = open(os.path.join(source, "host/include/tessera/plugin.h"), encoding="utf-8").read()
    abi = re.search(r"TESSERA_PLUGIN_ABI_VERSION\s*=?\s*(\d+)", plugin_h).group(1)
    problems = []
    documents = list(markdown_files(source))
    for document in documents:
        relative = os.path.relpath(document, source)
        in_fence = False
        for number, line in enumerate(open(document, encoding="utf-8"), 1):
            if line.lstrip().startswith("```"):
                in_fence = not in_fence
                continue
            for version in SONAME.findall(line):
                if version != abi:
                    problems.append(f"{relative}:{number}: names libtessera_*.so.{version}; "
                                    f"the ABI of plugin.h is {abi}")
            if in_fence:
                continue
            for span in CODE_SPAN.findall(line):
                for path in candidates(span):
                    if looks_like_repository_path(path) and not exists(source, document, path):
                        problems.append(f"{relative}:{number}: `{path}` is not in the repository")
    status = status_lines(os.path.join(source, "README.md"))
    if status == 0:
        problems.append("README.md: no status block (a quoted block starting '> Status:')")
    elif status > MAX_STATUS_LINES:
        problems.append(f"README.md: the status is {status} lines; at most {MAX_STATUS_LINES}")
    for problem in problems:
        print(problem)
    print(f"{len(documents)} documents, ABI {abi}, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
