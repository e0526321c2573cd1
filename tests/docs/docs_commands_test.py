#!/usr/bin/env python3
"""Every `tessera` command in README.md and docs/*.md is checked against the built binary,
so that none drifts from the code.

- Each command in a fenced shell block (```sh, ```bash, ```console or unlabelled) and
  each inline code span that starts with `tessera`: the verb exists, every option before
  the verb is one `tessera --help` lists and every option after it one that
  `tessera VERB --help` lists, and each file of the repository it names is there.
- The usage block (```text, lines starting with `tessera VERB`): the same, and each verb
  and each option that the binary accepts is in it.
- Every relative link and image points to an existing file (and heading).
- A design note (a line `Status: design only`) describes commands to come: only its links
  are checked.
- The README's tables: one row per recipe in manifests/, one per bundled plugin that
  `tessera plugins` finds.
- The commands of a fenced block that name PHOTOS or OUT are run, in the order of the
  documents, with PHOTOS a 512 px copy of examples/fountain-P11-small and OUT a temporary
  workspace; what they promise is checked (models of all 11 images, a transforms.json that
  `tessera eval` scores as the model itself, a 3DGS scene, a GUI screenshot under a
  private Xvfb when there is one). `tessera plugins` is run too.

A failure names the document and the line of the command: README.md:76: ...
usage: docs_commands_test.py --source DIR --tessera EXE --downscale EXE [--static-only]
                             [--skip-gui]
"""
import argparse
import glob
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

SHELL_BLOCKS = {"", "sh", "bash", "shell", "console"}
# First folders of paths that are part of the repository; anything else (build/, OUT,
# ../shared, /tmp) is made by a build or a run, or lies outside it.
REPOSITORY_FOLDERS = {".ci", "benchmarks", "cmake", "docs", "examples", "host", "manifests",
                      "plugins", "scripts", "tests"}
# Options whose value is a file the command writes, so need not exist beforehand.
OUTPUT_OPTIONS = {"--output", "--json", "--csv", "--chart", "--screenshot", "--workspace"}
# Commands that run another command (`nice -n 19 tessera ...`).
WRAPPERS = {"nice", "env", "time", "/usr/bin/time", "exec", "timeout"}
CONTROL_OPERATORS = {"|", "||", "&&", ";", "&"}
PLACEHOLDERS = ("PHOTOS", "OUT")
SAMPLE_IMAGES = 11


class Command:
    """One `tessera ...` command as a document writes it."""

    def __init__(self, doc, line, text, tokens, runnable):
        self.doc = doc            # path relative to the source folder
        self.line = line          # 1-based line of the command's first line
        self.text = text          # as written, for messages
        self.tokens = tokens      # tokens from the executable on
        self.runnable = runnable  # from a fenced block and names PHOTOS or OUT

    def where(self):
        return f"{self.doc}:{self.line}: `{self.text}`"


class Failures:
    def __init__(self):
        self.messages = []

    def add(self, message):
        self.messages.append(message)
        print(f"FAIL {message}", flush=True)


# ---------------------------------------------------------------------------------------
# What the binary accepts.


class Cli:
    """The verbs and options of the built `tessera`, read from its --help."""

    def __init__(self, executable):
        self.executable = executable
        top = self._help([])
        self.global_options = self._options(top)
        self.verbs = {}
        in_subcommands = False
        for line in top.splitlines():
            if line.startswith("Subcommands:"):
                in_subcommands = True
            elif in_subcommands and re.match(r"^  \w", line):
                verb = line.split()[0]
                self.verbs[verb] = self._options(self._help([verb]))

    def _help(self, verb):
        result = subprocess.run([self.executable] + verb + ["--help"], capture_output=True,
                                text=True, timeout=60)
        if result.returncode != 0:
            sys.exit(f"FAIL {self.executable} {' '.join(verb)} --help: exit {result.returncode}")
        return result.stdout

    @staticmethod
    def _options(help_text):
        """{'--images': True (takes a value), '--dry-run': False, '-q': False, ...}"""
        options = {}
        # CLI11 puts each option at column 2: `  -q,--quiet  text` or `  --images TEXT ...`.
        for match in re.finditer(r"^  (?:(-\w),)?(--[\w-]+)( [A-Z][A-Z:_]*)?", help_text,
                                 re.MULTILINE):
            takes_value = match.group(3) is not None
            options[match.group(2)] = takes_value
            if match.group(1):
                options[match.group(1)] = takes_value
        return options


# ---------------------------------------------------------------------------------------
# Reading the documents.


def is_executable(token):
    return token == "tessera" or token.endswith("/tessera")


def shell_words(text):
    """Shell tokens of one logical line, comments dropped; None if it does not parse."""
    lexer = shlex.shlex(text, posix=True, punctuation_chars=";&|")
    lexer.whitespace_split = True
    lexer.commenters = "#"
    try:
        return list(lexer)
    except ValueError:
        return None


def simple_commands(tokens):
    """Splits at control operators; drops redirections and leading VAR=value and wrappers."""
    commands, current = [], []
    for token in tokens + [";"]:
        if token in CONTROL_OPERATORS:
            if current:
                commands.append(current)
            current = []
        else:
            current.append(token)
    result = []
    for command in commands:
        words = []
        skip_next = False
        for token in command:
            if skip_next:
                skip_next = False
            elif re.match(r"^\d*>>?$|^<$", token):
                skip_next = True
            elif not re.match(r"^\d*[<>]", token):
                words.append(token)
        while words and re.match(r"^[A-Za-z_]\w*=", words[0]):
            words.pop(0)
        while words and words[0] in WRAPPERS:
            words.pop(0)
            while words and (words[0].startswith("-") or words[0].isdigit()):
                words.pop(0)
        if words:
            result.append(words)
    return result


def names_placeholder(token):
    value = token.split("=", 1)[1] if token.startswith("--") and "=" in token else token
    return any(value == name or value.startswith(name + "/") for name in PLACEHOLDERS)


class Document:
    def __init__(self, source, relative):
        self.source = source
        self.relative = relative
        self.text = open(os.path.join(source, relative), encoding="utf-8").read()
        self.lines = self.text.split("\n")
        self.blocks = []  # (language, first line number of the contents, [lines])
        self.prose = []   # the lines outside fenced blocks ("" inside them)
        language, start, contents = None, 0, []
        for number, line in enumerate(self.lines, 1):
            fence = re.match(r"^\s*(```|~~~)\s*([\w+-]*)", line)
            if language is None:
                if fence:
                    language, start, contents = fence.group(2).lower(), number + 1, []
                    self.prose.append("")
                else:
                    self.prose.append(line)
            else:
                self.prose.append("")
                if fence and not fence.group(2):
                    self.blocks.append((language, start, contents))
                    language = None
                else:
                    contents.append(line)

    def shell_commands(self):
        """(line, text, tokens) of each simple command in the fenced shell blocks."""
        for language, start, contents in self.blocks:
            if language not in SHELL_BLOCKS:
                continue
            logical, first = "", None
            for offset, line in enumerate(contents):
                if first is None:
                    first = start + offset
                stripped = re.sub(r"^\s*\$ ", "", line) if not logical else line
                if stripped.endswith("\\"):
                    logical += stripped[:-1] + " "
                    continue
                logical += stripped
                if logical.strip():
                    yield first, logical.strip(), shell_words(logical)
                logical, first = "", None

    def usage_lines(self):
        """(block start, [(line, text)]) of each ```text block whose lines start `tessera `."""
        for language, start, contents in self.blocks:
            if language == "text" and contents and contents[0].startswith("tessera "):
                yield start, [(start + i, line) for i, line in enumerate(contents)]

    def inline_spans(self):
        """(line, text) of each inline code span, whitespace folded."""
        prose = "\n".join(self.prose)
        for match in re.finditer(r"`([^`]+)`", prose):
            if "\n\n" in match.group(1):
                continue
            line = prose.count("\n", 0, match.start()) + 1
            yield line, " ".join(match.group(1).split())

    def links(self):
        prose = "\n".join(self.prose)
        for match in re.finditer(r"!?\[[^\]]*\]\(([^)\s]+)\)", prose):
            yield prose.count("\n", 0, match.start()) + 1, match.group(1)

    def anchors(self):
        """GitHub's anchors of the headings."""
        result = set()
        for line in self.prose:
            heading = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
            if heading:
                slug = re.sub(r"[^\w\- ]", "", heading.group(1).lower()).replace(" ", "-")
                result.add(slug)
        return result


def commands_of(document, others):
    """Every `tessera` command of a document: from shell blocks and inline spans. The other
    commands of its shell blocks (scripts, cmake) go to `others`."""
    commands = []
    for line, text, tokens in document.shell_commands():
        if tokens is None:
            if "tessera" in text:
                commands.append(Command(document.relative, line, text, None, False))
            continue
        for words in simple_commands(tokens):
            if is_executable(words[0]):
                runnable = any(names_placeholder(word) for word in words)
                commands.append(Command(document.relative, line, text, words, runnable))
            else:
                others.append(Command(document.relative, line, text, words, False))
    for line, text in document.inline_spans():
        words = text.split()
        if words and is_executable(words[0]) and len(words) > 1:
            commands.append(Command(document.relative, line, text, words, False))
            continue
        # A script of the repository named inline (`bash benchmarks/slurm_shards.sh ...`).
        for words in simple_commands(shell_words(text) or []):
            if words[0] in ("bash", "sh", "python3", "python"):
                words = words[1:]
            if words and re.search(r"\.(sh|py)$", words[0]):
                others.append(Command(document.relative, line, text, words[:1], False))
    return commands


# ---------------------------------------------------------------------------------------
# Static checks.


def option_name(token):
    """'--sbatch-arg=--x' -> '--sbatch-arg'; '[--camera-K' -> '--camera-K'; else None."""
    token = token.lstrip("[(")
    if not re.match(r"^--?[A-Za-z]", token):
        return None
    return re.match(r"^(--?[\w-]+)", token.split("=", 1)[0]).group(1).rstrip("-")


def repository_path(source, token):
    """The repository file a token names, or None when it names none."""
    path = token[2:] if token.startswith("./") else token
    first = path.split("/", 1)[0]
    if "/" not in path or first not in REPOSITORY_FOLDERS:
        return None
    return os.path.join(source, path)


def check_command(cli, source, command, failures):
    """The verb, the options and the repository files of one command."""
    if command.tokens is None:
        failures.add(f"{command.where()}: not a shell command that parses")
        return None
    words = command.tokens[1:]
    position = 0
    while position < len(words) and words[position].startswith("-"):
        name = option_name(words[position])
        if name not in cli.global_options:
            failures.add(f"{command.where()}: `tessera` has no option {words[position]} "
                         f"before the verb (tessera --help)")
        position += 1
    if position == len(words):
        return None  # `tessera --version`
    verb = words[position]
    if re.match(r"^[A-Z]+$", verb) or verb == "...":
        return None  # `tessera VERB --help`: a placeholder for any verb
    if verb not in cli.verbs:
        failures.add(f"{command.where()}: `tessera` has no verb '{verb}' "
                     f"(verbs: {', '.join(sorted(cli.verbs))})")
        return None
    accepted = cli.verbs[verb]
    used = set()
    value_of = None  # the option whose value the next token is
    for token in words[position + 1:]:
        if value_of is not None:
            if value_of not in OUTPUT_OPTIONS:
                check_path(source, command, token, failures)
            value_of = None
            continue
        name = option_name(token)
        if name is None:
            check_path(source, command, token.strip("[]()|"), failures)
            continue
        used.add(name)
        if name not in accepted:
            failures.add(f"{command.where()}: `tessera {verb}` has no option {name} "
                         f"(tessera {verb} --help)")
        elif "=" in token:
            if name not in OUTPUT_OPTIONS:
                check_path(source, command, token.split("=", 1)[1], failures)
        elif accepted[name]:
            value_of = name
    return verb, used


def check_path(source, command, token, failures):
    path = repository_path(source, token)
    if path is not None and not os.path.exists(path):
        failures.add(f"{command.where()}: names {token}, which is not in the repository")


def check_usage_block(cli, source, document, start, lines, failures):
    """The usage block: each line as a command, and nothing the binary accepts left out."""
    listed = {}
    verb = None
    for line, text in lines:
        words = text.split()
        if not words:
            continue
        if words[0] != "tessera":  # a continuation of the verb above
            if verb is None:
                failures.add(f"{document.relative}:{line}: `{text}`: no verb above it")
                continue
            words = ["tessera", verb] + words
        # A line may hold several commands (`tessera extract ... --shard K/N  tessera match ...`).
        starts = [i for i, word in enumerate(words) if word == "tessera"]
        for begin, end in zip(starts, starts[1:] + [len(words)]):
            command = Command(document.relative, line, text, words[begin:end], False)
            result = check_command(cli, source, command, failures)
            if result:
                verb, used = result
                listed.setdefault(verb, set()).update(used)
    for verb, accepted in sorted(cli.verbs.items()):
        if verb not in listed:
            failures.add(f"{document.relative}:{start}: the usage block lacks `tessera {verb}`")
            continue
        for name in sorted(accepted):
            if name.startswith("--") and name != "--help" and name not in listed[verb]:
                failures.add(f"{document.relative}:{start}: the usage block lacks "
                             f"{name} of `tessera {verb}` (tessera {verb} --help)")


def check_links(source, documents, failures):
    by_path = {os.path.normpath(os.path.join(source, d.relative)): d for d in documents}
    for document in documents:
        folder = os.path.dirname(os.path.join(source, document.relative))
        for line, target in document.links():
            if re.match(r"^[a-z]+:", target):
                continue  # http:, https:, mailto:
            path, _, anchor = target.partition("#")
            resolved = os.path.normpath(os.path.join(folder, path)) if path else \
                os.path.normpath(os.path.join(source, document.relative))
            if not os.path.exists(resolved):
                failures.add(f"{document.relative}:{line}: link to {target}: "
                             f"{os.path.relpath(resolved, source)} does not exist")
            elif anchor and resolved in by_path and anchor not in by_path[resolved].anchors():
                failures.add(f"{document.relative}:{line}: link to {target}: "
                             f"no heading '#{anchor}' in {os.path.relpath(resolved, source)}")


def table_rows(document, heading):
    """(line, first cell, second cell) of the rows of the first table below a heading."""
    rows, inside = [], False
    for number, line in enumerate(document.prose, 1):
        if line.startswith("#"):
            inside = line.lstrip("#").strip() == heading
        elif inside and line.startswith("|") and not line.startswith("| ---"):
            cells = [cell.strip() for cell in line.strip("|").split("|")]
            rows.append((number, cells[0], cells[1] if len(cells) > 1 else ""))
    return rows[1:]  # the header row


def check_recipes_table(source, readme, failures):
    rows = table_rows(readme, "Recipes")
    names = {cell.strip("`"): line for line, cell, _ in rows}
    shipped = {os.path.basename(p) for p in glob.glob(os.path.join(source, "manifests", "*.json"))}
    for name, line in names.items():
        if name not in shipped:
            failures.add(f"README.md:{line}: recipe {name} is not in manifests/")
    for name in sorted(shipped - set(names)):
        failures.add(f"README.md: the Recipes table has no row for manifests/{name}")


def check_ci_runs_readme_test_command(source, readme, failures):
    """README: `CI (.ci/run) runs exactly this command`, the test command."""
    commands = [text for _, text, _ in readme.shell_commands()]
    if "./scripts/test.sh" not in commands:
        failures.add("README.md: no shell block holds the test command ./scripts/test.sh")
    ci = open(os.path.join(source, ".ci", "run"), encoding="utf-8").read().splitlines()
    if "./scripts/test.sh" not in [line.strip() for line in ci]:
        failures.add(".ci/run does not run the README's test command ./scripts/test.sh")


# ---------------------------------------------------------------------------------------
# Running the commands on the sample.


def run(arguments, failures, what, timeout=300, env=None, cwd=None):
    """Runs a command; None, and a failure named `what`, unless it exits 0."""
    print("$ " + " ".join(shlex.quote(a) for a in arguments), flush=True)
    try:
        result = subprocess.run(arguments, capture_output=True, text=True, timeout=timeout,
                                env=env, cwd=cwd)
    except subprocess.TimeoutExpired:
        failures.add(f"{what}: did not end within {timeout} s")
        return None
    if result.returncode != 0:
        tail = "\n".join((result.stdout + result.stderr).strip().splitlines()[-5:])
        failures.add(f"{what}: exit {result.returncode}\n{tail}")
        return None
    return result


def check_plugins(cli, readme, failures):
    result = run([cli.executable, "plugins"], failures, "tessera plugins", timeout=120)
    listing = run([cli.executable, "plugins", "--json"], failures, "tessera plugins --json",
                  timeout=120)
    if result is None or listing is None:
        return
    found = {(p["kind"], p["name"]) for p in json.loads(listing.stdout)["plugins"] if p["usable"]}
    table = {(kind, name.strip("`")): line for line, kind, name in
             table_rows(readme, "Bundled plugins")}
    for (kind, name), line in table.items():
        if (kind, name) not in found:
            failures.add(f"README.md:{line}: bundled plugin {kind} '{name}' is not found by "
                         f"`tessera plugins`")
    for kind, name in sorted(found - set(table)):
        failures.add(f"README.md: the Bundled plugins table has no row for {kind} '{name}'")


class Xvfb:
    """A private X server for the GUI's screenshot mode, stopped by its process id."""

    def __init__(self):
        self.process = None
        self.display = None
        if shutil.which("Xvfb") is None:
            return
        read_end, write_end = os.pipe()
        self.process = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write_end), "-screen", "0", "1600x1000x24", "-nolisten",
             "tcp"], pass_fds=(write_end,), stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        os.close(write_end)
        with os.fdopen(read_end) as pipe:
            line = pipe.readline().strip()
        self.display = f":{line}" if line else None

    def stop(self):
        if self.process is not None:
            self.process.kill()
            self.process.wait()


def manifest_exporters(source, tokens):
    for i, token in enumerate(tokens):
        if token == "--manifest" and i + 1 < len(tokens):
            path = tokens[i + 1]
            path = path if os.path.isabs(path) else os.path.join(source, path)
            with open(path, encoding="utf-8") as file:
                pipeline = json.load(file).get("pipeline", {})
            return {slot["plugin"] for slot in pipeline.get("exporters", [])}
    return set()


def run_documented(cli, source, command, work, xvfb, failures):
    """Runs a command on PHOTOS and OUT, then checks what the documents say it makes."""
    def substitute(token):
        for name in PLACEHOLDERS:
            folder = os.path.join(work, name)
            if token == name or token.startswith(name + "/"):
                return folder + token[len(name):]
            if token.startswith("--") and "=" + name in token:
                return token.replace("=" + name, "=" + folder, 1)
        return token

    tokens = [substitute(token) for token in command.tokens[1:]]
    arguments = [cli.executable] + tokens
    verb = next(t for t in tokens if not t.startswith("-"))
    value = lambda option: tokens[tokens.index(option) + 1] if option in tokens else None
    env = None
    if verb == "gui":
        if "built without the GUI" in (subprocess.run(
                [cli.executable, "gui"], capture_output=True, text=True,
                env={k: v for k, v in os.environ.items() if k != "DISPLAY"}).stderr):
            print(f"note: {command.where()} not run: this tessera has no GUI", flush=True)
            return
        if xvfb is None or xvfb.display is None:
            print(f"note: {command.where()} not run: no Xvfb, or --skip-gui", flush=True)
            return
        # The window cannot be looked at in a test: its screenshot mode draws it and exits.
        shot = os.path.join(work, "gui.png")
        arguments += ["--screenshot", shot, "--width", "640", "--height", "400"]
        env = dict(os.environ, DISPLAY=xvfb.display, LIBGL_ALWAYS_SOFTWARE="1")
    # The documents' paths (manifests/...) are relative to the repository.
    if run(arguments, failures, command.where(), env=env, cwd=source) is None:
        return
    if verb == "run":
        output = value("--output")
        with open(os.path.join(output, "run_summary.json"), encoding="utf-8") as file:
            per_model = json.load(file).get("map", {}).get("images_per_model", [])
        if not per_model or per_model[0] != SAMPLE_IMAGES:
            failures.add(f"{command.where()}: model 0 holds {per_model[:1]} images of the "
                         f"sample, expected {SAMPLE_IMAGES}")
        for name in ("cameras.bin", "images.bin", "points3D.bin", "points3D.ply"):
            if not os.path.isfile(os.path.join(output, "sparse", "0", name)):
                failures.add(f"{command.where()}: no sparse/0/{name}")
        if "gaussian_splatting" in manifest_exporters(source, tokens):
            checker = os.path.join(source, "tests", "tools", "check_3dgs_scene.py")
            run([sys.executable, checker, os.path.join(output, "gaussian_splatting"),
                 str(SAMPLE_IMAGES)], failures, f"{command.where()}: the 3DGS scene")
    elif verb == "export" and value("--format") == "transforms_json":
        # The exported cameras, read back as ground truth, are the model's own poses.
        model, transforms = value("--model"), os.path.join(value("--output"), "transforms.json")
        result = run([cli.executable, "eval", model, transforms, "--json"], failures,
                     f"{command.where()}: tessera eval of its transforms.json")
        if result is not None:
            scores = json.loads(result.stdout)
            if (scores["registered"] != SAMPLE_IMAGES or scores["pos_mean_rel"] > 1e-9 or
                    scores["rot_max_deg"] > 1e-3):
                failures.add(f"{command.where()}: tessera eval against its transforms.json: "
                             f"{scores['registered']} registered, position error "
                             f"{scores['pos_mean_rel']} of the extent, rotation error up to "
                             f"{scores['rot_max_deg']} deg")
        # Each file_path, resolved as nerfstudio resolves it, names an image that is there.
        with open(transforms, encoding="utf-8") as file:
            for frame in json.load(file)["frames"]:
                path = os.path.join(os.path.dirname(transforms), frame["file_path"])
                if not os.path.isfile(path):
                    failures.add(f"{command.where()}: file_path {frame['file_path']} of "
                                 f"{transforms} resolves to {path}, which does not exist")
                    break
    elif verb == "gui":
        with open(shot, "rb") as file:
            header = file.read(24)
        if header[:8] != b"\x89PNG\r\n\x1a\n" or header[16:24] != (640).to_bytes(4, "big") + \
                (400).to_bytes(4, "big"):
            failures.add(f"{command.where()}: the screenshot is not a 640x400 PNG")


def check_placeholder_paths(work, documents, failures):
    """Paths under OUT that other commands (a trainer) are told to read exist after the runs."""
    for document in documents:
        for line, text, tokens in document.shell_commands():
            for words in simple_commands(tokens or []):
                if is_executable(words[0]):
                    continue
                for word in words:
                    if word.startswith("OUT/") and \
                            not os.path.exists(os.path.join(work, word)):
                        failures.add(f"{document.relative}:{line}: `{text}`: {word} was not "
                                     f"made by the commands before it")


# ---------------------------------------------------------------------------------------


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--source", required=True, help="the repository")
    parser.add_argument("--tessera", required=True, help="the built tessera executable")
    parser.add_argument("--downscale", help="the built tessera_test_downscale executable")
    parser.add_argument("--static-only", action="store_true",
                        help="check the commands, run none of them")
    parser.add_argument("--skip-gui", action="store_true",
                        help="do not run `tessera gui` (the sanitizer build: its GUI tests are "
                        "labelled slow, and do not run there either)")
    args = parser.parse_args()
    source = os.path.abspath(args.source)

    names = ["README.md"] + sorted(os.path.relpath(p, source) for p in
                                   glob.glob(os.path.join(source, "docs", "*.md")))
    documents = [Document(source, name) for name in names]
    readme = documents[0]
    cli = Cli(os.path.abspath(args.tessera))
    failures = Failures()

    commands, others = [], []
    for document in documents:
        if re.search(r"^Status: design only", document.text, re.MULTILINE):
            # A design note describes verbs that do not exist yet; its links still count.
            print(f"note: {document.relative} is a design note: its commands are not checked")
            continue
        commands += commands_of(document, others)
        for start, lines in document.usage_lines():
            check_usage_block(cli, source, document, start, lines, failures)
    for command in commands:
        check_command(cli, source, command, failures)
    for command in others:
        for token in command.tokens:
            check_path(source, command, token.split("=", 1)[-1], failures)
    check_links(source, documents, failures)
    check_recipes_table(source, readme, failures)
    check_ci_runs_readme_test_command(source, readme, failures)
    print(f"{len(commands)} commands in {len(documents)} documents checked against "
          f"{args.tessera}", flush=True)

    if not args.static_only:
        if not args.downscale:
            parser.error("--downscale is needed to run the commands")
        check_plugins(cli, readme, failures)
        work = tempfile.mkdtemp(prefix="docs_commands_")
        xvfb = None
        try:
            sample = os.path.join(source, "examples", "fountain-P11-small", "images")
            run([os.path.abspath(args.downscale), sample, os.path.join(work, "PHOTOS"), "512",
                 "90"], failures, "downscaling the sample")
            xvfb = None if args.skip_gui else Xvfb()
            runnable = [c for c in commands if c.runnable]
            if not runnable:
                failures.add("no command in a fenced block names PHOTOS or OUT: nothing was run")
            for command in runnable:
                run_documented(cli, source, command, work, xvfb, failures)
            check_placeholder_paths(work, documents, failures)
        finally:
            if xvfb is not None:
                xvfb.stop()
            shutil.rmtree(work, ignore_errors=True)

    if failures.messages:
        print(f"{len(failures.messages)} failure(s)")
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
