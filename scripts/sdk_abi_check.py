#!/usr/bin/env python3
"""Fails when the plugin SDK's headers changed but TESSERA_PLUGIN_ABI_VERSION did not.

host/include/tessera/abi_headers.sha256 records the ABI version (plugin.h) and a SHA-256
of every file under host/include/tessera (io/ included). This script recomputes them:
  - same version, same hashes: exit 0;
  - same version, other hashes: exit 1 naming the files changed, added or removed
    ("bump it and run scripts/sdk_abi_check.py --update");
  - another version: exit 1 until --update records it;
  - docs/plugin_authors_guide.md not stating the version, its SONAME and a changelog
    entry for it: exit 1 naming what it lacks.
--update rewrites the record, and refuses (exit 1) when the headers changed but the
version did not, or when the version went down.

The hash is of each file's tokens, not its bytes: comments are dropped and whitespace only
separates tokens, so an edit of comments, indentation or line breaks needs no bump. A
preprocessor directive stays one unit (its line end ends it), and `#define F(x)` and
`#define F (x)` hash differently, as the preprocessor reads them differently.

usage: sdk_abi_check.py [--update] [--include-dir DIR]   (default: the repository's
host/include/tessera)
"""

import argparse
import hashlib
import re
import sys
from pathlib import Path

RECORD_NAME = "abi_headers.sha256"
VERSION_PATTERN = re.compile(r"^\s*#\s*define\s+TESSERA_PLUGIN_ABI_VERSION\s+(\d+)\s*$", re.M)
# Strings and character literals whole, then numbers, identifiers and single punctuation
# characters.
TOKEN_PATTERN = re.compile(
    r'"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'|\.?[0-9][A-Za-z0-9_.]*|[A-Za-z_]\w*|\S')
FUNCTION_LIKE_DEFINE = re.compile(r"^\s*#\s*define\s+[A-Za-z_]\w*\(")


def strip_comments(text):
    """Replaces every comment with a space, leaving string and character literals alone."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(text[i : j + 1])
            i = j + 1
        elif text.startswith("//", i):
            end = text.find("\n", i)
            i = n if end < 0 else end
            out.append(" ")
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            if end < 0:
                raise ValueError("unterminated /* comment")
            i = end + 2
            out.append(" ")
        else:
            out.append(c)
            i += 1
    return "".join(out)


def normalise(text):
    """The file as a token stream: one line per preprocessor directive, one line for the
    code between two directives, tokens separated by one space."""
    text = strip_comments(text.replace("\r\n", "\n")).replace("\\\n", "")
    units, code = [], []
    for line in text.split("\n"):
        if line.lstrip().startswith("#"):
            if code:
                units.append(" ".join(code))
                code = []
            tokens = TOKEN_PATTERN.findall(line)
            if FUNCTION_LIKE_DEFINE.match(line):
                tokens[3] = "(<function-like>"  # "# define NAME (" -> a marked parenthesis
            units.append(" ".join(tokens))
        else:
            code.extend(TOKEN_PATTERN.findall(line))
    if code:
        units.append(" ".join(code))
    return "\n".join(units) + "\n"


def normalised_headers(include_dir):
    """{path relative to include_dir: normalised text}, every file but the record."""
    headers = {}
    for path in sorted(include_dir.rglob("*")):
        relative = path.relative_to(include_dir).as_posix()
        if not path.is_file() or relative == RECORD_NAME:
            continue
        try:
            headers[relative] = normalise(path.read_text(encoding="utf-8"))
        except (UnicodeDecodeError, ValueError) as error:
            raise SystemExit(f"sdk_abi_check: {path}: {error}")
    return headers


def sha256(text):
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def total_hash(headers):
    """sha256 of the concatenated normalised contents, each after its path, in path order."""
    return sha256("".join(f"{relative}\n{headers[relative]}" for relative in sorted(headers)))


def abi_version(include_dir):
    plugin_h = include_dir / "plugin.h"
    try:
        match = VERSION_PATTERN.search(plugin_h.read_text(encoding="utf-8"))
    except OSError as error:
        raise SystemExit(f"sdk_abi_check: cannot read {plugin_h}: {error.strerror}")
    if not match:
        raise SystemExit(f"sdk_abi_check: {plugin_h}: no '#define TESSERA_PLUGIN_ABI_VERSION N'")
    return int(match.group(1))


def read_record(record_path):
    """(version, total, {path: sha256}) from the record, or None when there is none."""
    try:
        lines = record_path.read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        return None
    lines = [line for line in lines if line.strip() and not line.startswith("#")]
    fields = lines[0].split() if lines else []
    if len(fields) != 3 or fields[0] != "ABI" or not fields[1].isdigit():
        raise SystemExit(
            f"sdk_abi_check: {record_path}: first line is not 'ABI <version> <sha256>'")
    files = {}
    for number, line in enumerate(lines[1:], start=2):
        parts = line.split(maxsplit=1)
        if len(parts) != 2:
            raise SystemExit(
                f"sdk_abi_check: {record_path}: line {number} is not '<sha256> <path>'")
        files[parts[1]] = parts[0]
    return int(fields[1]), fields[2], files


def write_record(record_path, version, total, hashes):
    lines = [
        "# The plugin SDK's ABI version and the hashes of its headers (comments and whitespace",
        "# excluded), written by scripts/sdk_abi_check.py --update; checked by the test",
        "# sdk_abi_check. Change a header, bump TESSERA_PLUGIN_ABI_VERSION, run --update.",
        f"ABI {version} {total}",
    ]
    lines += [f"{hashes[relative]} {relative}" for relative in sorted(hashes)]
    record_path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def differences(recorded, current):
    """'changed: a.h, io/b.h; added: c.h; removed: d.h' between two {path: sha256}."""
    changed = [p for p in sorted(current) if p in recorded and recorded[p] != current[p]]
    added = [p for p in sorted(current) if p not in recorded]
    removed = [p for p in sorted(recorded) if p not in current]
    parts = [f"{what}: {', '.join(paths)}"
             for what, paths in (("changed", changed), ("added", added), ("removed", removed))
             if paths]
    return "; ".join(parts)


def guide_problem(guide, version):
    """What the plugin author's guide says of the ABI that plugin.h contradicts, or None:
    its current number, the SONAME it names, and a changelog entry for the version."""
    try:
        text = guide.read_text(encoding="utf-8")
    except OSError as error:
        return f"cannot read {guide}: {error.strerror}"
    for expected in (f"It is now {version}", f"libtessera_io.so.{version}`", f"  - {version}: "):
        if expected not in text:
            return (f"{guide.name} does not say '{expected.strip()}' (plugin.h's "
                    f"TESSERA_PLUGIN_ABI_VERSION is {version}): update its ABI paragraph")
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--update", action="store_true", help="rewrite the record")
    repository = Path(__file__).resolve().parent.parent
    parser.add_argument("--include-dir", type=Path,
                        default=repository / "host" / "include" / "tessera")
    args = parser.parse_args()
    include_dir = args.include_dir
    # Named relative to the repository ("host/include/tessera") when inside it.
    display_dir = include_dir.as_posix()
    if include_dir.resolve().is_relative_to(repository):
        display_dir = include_dir.resolve().relative_to(repository).as_posix()
    if not include_dir.is_dir():
        raise SystemExit(f"sdk_abi_check: {display_dir} is not a folder")
    record_path = include_dir / RECORD_NAME
    display_record = f"{display_dir}/{RECORD_NAME}"
    version = abi_version(include_dir)
    headers = normalised_headers(include_dir)
    hashes = {relative: sha256(text) for relative, text in headers.items()}
    total = total_hash(headers)
    record = read_record(record_path)
    command = "scripts/sdk_abi_check.py --update"

    if record is None:
        if not args.update:
            print(f"sdk_abi_check: {display_record} is missing: run {command}")
            return 1
    else:
        recorded_version, recorded_total, recorded_hashes = record
        what = differences(recorded_hashes, hashes) or "no file differs from the record's list"
        if version == recorded_version and total != recorded_total:
            refused = "not updating the record: " if args.update else ""
            print(f"sdk_abi_check: {refused}{display_dir} changed but TESSERA_PLUGIN_ABI_VERSION "
                  f"is still {version} ({what}): bump it and run {command}")
            return 1
        if version < recorded_version:
            print(f"sdk_abi_check: TESSERA_PLUGIN_ABI_VERSION went down from {recorded_version} "
                  f"to {version} in {display_dir}/plugin.h; it only goes up")
            return 1
        if version == recorded_version:
            guide = repository / "docs" / "plugin_authors_guide.md"
            problem = guide_problem(guide, version) if include_dir.resolve() == (
                repository / "host" / "include" / "tessera").resolve() else None
            if problem:
                print(f"sdk_abi_check: docs/{problem}")
                return 1
            print(f"sdk_abi_check: ABI {version}, {len(hashes)} headers as recorded; "
                  "the plugin author's guide states it")
            return 0
        if not args.update:
            print(f"sdk_abi_check: TESSERA_PLUGIN_ABI_VERSION is {version} but {display_record} "
                  f"records {recorded_version}: run {command}")
            return 1
    write_record(record_path, version, total, hashes)
    print(f"sdk_abi_check: recorded ABI {version} for {len(hashes)} headers in {display_record}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
