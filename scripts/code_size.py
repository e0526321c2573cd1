#!/usr/bin/env python3
"""Reports the longest functions and files of host/, plugins/ and python/ and checks limits.

A function is a brace-delimited body opened at namespace or class scope whose header
has a parameter list; everything inside it (lambdas, local classes, blocks) counts as
part of it. Its length is the number of lines from the line of its name to the line of
its closing brace. Tests, benchmarks, fuzz targets and test data are not counted.

    scripts/code_size.py [--root DIR] [--top N] [--max-function N] [--max-file M]
                         [--exclude PATH ...]

With --max-function or --max-file it lists every violation and exits 1 if there is one.
"""

import argparse
import os
import re
import sys

SOURCE_FOLDERS = ("host", "plugins", "python")
SOURCE_SUFFIXES = (".cc", ".h")
SKIPPED_SUFFIXES = ("_test.cc", "_benchmark.cc")
SKIPPED_FOLDERS = ("fuzz", "testdata")


def strip_code(text):
    """Returns text with comments, literals and preprocessor lines blanked out.

    Newlines are kept, so offsets map to the same line numbers as in the original.
    """
    out = []
    i = 0
    n = len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if c == "\n":
            out.append(c)
            i += 1
            at_line_start = True
            continue
        if at_line_start and c in " \t":
            out.append(c)
            i += 1
            continue
        if at_line_start and c == "#":
            # A preprocessor directive, continued over escaped newlines.
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                out.append(" ")
                i += 1
            continue
        at_line_start = False
        if text.startswith("//", i):
            while i < n and text[i] != "\n":
                out.append(" ")
                i += 1
            continue
        if text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
            continue
        raw = re.match(r'(?:u8|u|U|L)?R"([^()\\\s]{0,16})\(', text[i:i + 24])
        if raw and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            terminator = ")" + raw.group(1) + '"'
            end = text.find(terminator, i + raw.end())
            end = n if end < 0 else end + len(terminator)
            out.append('""' + re.sub(r"[^\n]", " ", text[i:end])[2:])
            i = end
            continue
        if c == "'" and i > 0 and text[i - 1].isdigit() and i + 1 < n and text[i + 1].isalnum():
            out.append(c)  # a digit separator, as in 1'000'000
            i += 1
            continue
        if c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            end = min(j + 1, n)
            out.append(c + " " * (end - i - 2) + c if end - i >= 2 else c)
            i = end
            continue
        out.append(c)
        i += 1
    return "".join(out)


def remove_balanced(text, opener, closer, start):
    """Returns the index just past the group that opens at text[start] == opener."""
    depth = 0
    for k in range(start, len(text)):
        if text[k] == opener:
            depth += 1
        elif text[k] == closer:
            depth -= 1
            if depth == 0:
                return k + 1
    return len(text)


def without_template_prefix(header):
    """Drops a leading `template <...>` (nested any deep) from a declaration header."""
    header = header.lstrip()
    while True:
        match = re.match(r"template\s*<", header)
        if not match:
            return header
        header = header[remove_balanced(header, "<", ">", match.end() - 1):].lstrip()


def classify(header):
    """What a `{` at namespace or class scope opens, given the text before it."""
    h = without_template_prefix(header)
    h = re.sub(r"\balignas\s*\([^)]*\)", " ", h)
    h = re.sub(r"\[\[[^\]]*\]\]", " ", h)
    if re.match(r"(inline\s+)?namespace\b", h) or re.match(r'extern\s*"\s*"\s*$', h):
        return "namespace"
    if re.match(r"(typedef\s+)?(class|struct|union)\b", h) and "(" not in h:
        return "class"
    if re.match(r"(typedef\s+)?enum\b", h) and "(" not in h:
        return "other"
    paren = h.find("(")
    if paren < 0:
        return "other"  # a brace initializer or an enum
    before = h[:paren]
    if "=" in before and not re.search(r"\boperator\s*[^\s(]*=\s*$", before):
        return "other"  # a variable initialized with a call or a lambda: not a definition
    return "function"


def function_name(header):
    """The (qualified) name of the function whose header is given."""
    h = without_template_prefix(header)
    h = re.sub(r"\b__attribute__\s*\(\(.*?\)\)", " ", h)
    match = re.search(r"((?:[A-Za-z_]\w*\s*::\s*)*operator\s*(?:\(\s*\)|[^\s(]+))\s*\(", h)
    if match:
        return re.sub(r"operator(\w)", r"operator \1", re.sub(r"\s+", "", match.group(1)))
    paren = h.find("(")
    match = re.search(r"((?:[A-Za-z_~]\w*(?:<[^<>]*>)?\s*::\s*)*~?[A-Za-z_]\w*)\s*$", h[:paren])
    return re.sub(r"\s+", "", match.group(1)) if match else h[:paren].strip()


def in_initializer_list(header):
    """True if the header ends inside a constructor's member initializer list.

    `Foo::Foo(int a) : a_(a), b_` is about to open `b_{...}`, not the body.
    """
    paren = header.find("(")
    if paren < 0:
        return False
    after = header[remove_balanced(header, "(", ")", paren):]
    if not re.match(r"\s*(?:const\s*|noexcept\s*)*:(?!:)", after):
        return False
    stripped = header.rstrip()
    return bool(stripped) and (stripped[-1].isalnum() or stripped[-1] in "_>")


def find_functions(code):
    """Yields (name, start offset, end offset) of each function body in stripped code."""
    scopes = ["namespace"]  # kinds of the open scopes at namespace or class level
    header_start = 0
    i = 0
    n = len(code)
    while i < n:
        c = code[i]
        if c == "{":
            header = code[header_start:i]
            if header.count("(") > header.count(")") or in_initializer_list(header):
                # A default argument `= {}` or a member initializer `b_{b}`: not a body.
                i = remove_balanced(code, "{", "}", i)
                continue
            kind = classify(header)
            if kind in ("namespace", "class"):
                scopes.append(kind)
                header_start = i + 1
                i += 1
                continue
            end = remove_balanced(code, "{", "}", i)
            if kind == "function":
                name_start = header_start + len(header) - len(header.lstrip())
                yield function_name(header), name_start, end
            header_start = end
            i = end
            continue
        if c == "}":
            if len(scopes) > 1:
                scopes.pop()
            header_start = i + 1
        elif c == ";":
            header_start = i + 1
        elif c == ":" and scopes[-1] == "class":
            # `public:` and the like end a header inside a class.
            if re.search(r"\b(public|private|protected)\s*$", code[header_start:i]):
                header_start = i + 1
        i += 1


def source_files(root, excludes):
    for folder in SOURCE_FOLDERS:
        for directory, subdirs, files in os.walk(os.path.join(root, folder)):
            subdirs[:] = sorted(d for d in subdirs if d not in SKIPPED_FOLDERS)
            for file_name in sorted(files):
                if not file_name.endswith(SOURCE_SUFFIXES) or file_name.endswith(
                        SKIPPED_SUFFIXES):
                    continue
                path = os.path.relpath(os.path.join(directory, file_name), root)
                if any(path == e or path.startswith(e.rstrip("/") + "/") for e in excludes):
                    continue
                yield path


def measure(root, excludes):
    """Returns ([(lines, path, line, name)] of functions, [(lines, path)] of files)."""
    functions = []
    files = []
    for path in source_files(root, excludes):
        with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
            text = f.read()
        files.append((text.count("\n") + (0 if text.endswith("\n") or not text else 1), path))
        code = strip_code(text)
        if code.count("{") != code.count("}"):
            raise ValueError(f"{path}: braces do not balance once comments, literals and "
                             "preprocessor lines are removed, so it cannot be measured")
        for name, start, end in find_functions(code):
            first_line = code.count("\n", 0, start) + 1
            last_line = code.count("\n", 0, end - 1) + 1
            functions.append((last_line - first_line + 1, path, first_line, name))
    functions.sort(key=lambda f: (-f[0], f[1], f[2]))
    files.sort(key=lambda f: (-f[0], f[1]))
    return functions, files


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(
        __file__))), help="repository root (default: the one holding this script)")
    parser.add_argument("--top", type=int, default=10, help="how many of each to list")
    parser.add_argument("--max-function", type=int, help="longest function allowed, in lines")
    parser.add_argument("--max-file", type=int, help="longest source file allowed, in lines")
    parser.add_argument("--exclude", action="append", default=[],
                        help="a file or folder relative to the root to leave out (repeatable)")
    args = parser.parse_args()
    if not os.path.isdir(os.path.join(args.root, "host")):
        print(f"code_size.py: {args.root} has no host/ folder", file=sys.stderr)
        return 2

    try:
        functions, files = measure(args.root, args.exclude)
    except ValueError as error:
        print(f"code_size.py: {error}", file=sys.stderr)
        return 2
    print(f"Longest functions ({len(functions)} measured):")
    for lines, path, line, name in functions[:args.top]:
        print(f"  {lines:5d}  {path}:{line}  {name}")
    print(f"Longest files ({len(files)} measured):")
    for lines, path in files[:args.top]:
        print(f"  {lines:5d}  {path}")

    violations = []
    if args.max_function is not None:
        violations += [f"{path}:{line}: function {name} has {lines} lines (max {args.max_function})"
                       for lines, path, line, name in functions if lines > args.max_function]
    if args.max_file is not None:
        violations += [f"{path}: file has {lines} lines (max {args.max_file})"
                       for lines, path in files if lines > args.max_file]
    if violations:
        print(f"{len(violations)} violation(s):")
        for violation in violations:
            print(f"  {violation}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
