#!/usr/bin/env python3
"""Checks the plugin author's documentation of an installed prefix against its headers.

  - PREFIX/share/doc/tessera/plugin_authors_guide.md states the ABI version of the
    installed PREFIX/include/tessera/plugin.h ("It is now N") and has a changelog entry
    for it ("- N: ...");
  - every bundled plugin's options page is installed as plugins/<kind>/<name>.md (the
    global mapper's, plugins/mappers/global.md, at least; with --source DIR, one for each
    plugins/<kind>/<name>/README.md of that source tree);
  - every relative link of every installed .md page resolves to an installed file.
Exit 0 when all hold, else 1 with one line per problem.

usage: check_installed_docs.py PREFIX [--source SOURCE_DIR]
"""

import argparse
import re
import sys
from pathlib import Path

VERSION_PATTERN = re.compile(r"^\s*#\s*define\s+TESSERA_PLUGIN_ABI_VERSION\s+(\d+)\s*$", re.M)
# [text](target) outside code spans; images too. The target ends at ')' or a space (title).
LINK_PATTERN = re.compile(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
CODE_PATTERN = re.compile(r"```.*?```|`[^`\n]*`", re.S)


def abi_problems(prefix, docdir):
    plugin_h = prefix / "include" / "tessera" / "plugin.h"
    guide = docdir / "plugin_authors_guide.md"
    try:
        match = VERSION_PATTERN.search(plugin_h.read_text(encoding="utf-8"))
        text = guide.read_text(encoding="utf-8")
    except OSError as error:
        return [f"{error.filename}: cannot read: {error.strerror}"]
    if not match:
        return [f"{plugin_h}: no TESSERA_PLUGIN_ABI_VERSION"]
    version = match.group(1)
    problems = []
    if not re.search(rf"\bIt is now {version}\b", text):
        problems.append(f"{guide}: does not say 'It is now {version}' (plugin.h's ABI version)")
    if not re.search(rf"^\s*- {version}: ", text, re.M):
        problems.append(f"{guide}: no changelog entry '- {version}: ...' for ABI version {version}")
    return problems


def option_page_problems(docdir, source):
    expected = {("mappers", "global")}
    if source is not None:
        for readme in (source / "plugins").glob("*/*/README.md"):
            expected.add((readme.parent.parent.name, readme.parent.name))
    problems = []
    for kind, name in sorted(expected):
        page = docdir / "plugins" / kind / f"{name}.md"
        if not page.is_file() or page.stat().st_size == 0:
            problems.append(f"{page}: the options page of the bundled {kind} '{name}' is not installed")
    return problems


def link_problems(docdir):
    problems = []
    for page in sorted(docdir.rglob("*.md")):
        text = CODE_PATTERN.sub("", page.read_text(encoding="utf-8"))
        for target in LINK_PATTERN.findall(text):
            if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                continue  # a URL or an anchor in the page
            path = target.split("#", 1)[0]
            resolved = (page.parent / path).resolve()
            if not resolved.exists():
                problems.append(f"{page}: the link '{target}' does not resolve ({resolved})")
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("prefix", type=Path)
    parser.add_argument("--source", type=Path, default=None)
    args = parser.parse_args()
    docdir = args.prefix / "share" / "doc" / "tessera"
    if not docdir.is_dir():
        print(f"{docdir}: no installed documentation")
        return 1
    problems = abi_problems(args.prefix, docdir) + option_page_problems(docdir, args.source) + \
        link_problems(docdir)
    for problem in problems:
        print(problem)
    if problems:
        return 1
    pages = len(list(docdir.rglob("*.md")))
    print(f"{docdir}: {pages} pages, the guide states plugin.h's ABI, every link resolves")
    return 0


if __name__ == "__main__":
    sys.exit(main())
