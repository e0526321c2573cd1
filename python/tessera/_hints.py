"""The host's hints name CLI commands ("run `tessera extract` first") and options
("pass --force-map"); a call from Python reads them as the Python call that does the same
("call tessera.extract() first", "pass force_map=True")."""

import re
import shlex

# Only the verbs the module has; another (`tessera merge`) stays a command for the shell.
_COMMAND = re.compile(
    r"(?:\b(run|rerun) )?`tessera (run|extract|match|map|export|plugins|bench)((?: [^`]*)?)`")
# "map --cluster 3", "map --hierarchical": a verb with one option, outside backticks.
_VERB_OPTION = re.compile(r"\b(run|extract|match|map) --([a-z][a-zA-Z-]*)((?: [0-9]+)?)\b")
# The stages' flags (True when given) and options, as their Python keywords.
_FLAGS = {"force-map": "force_map", "hierarchical": "hierarchical",
          "camera-per-folder": "camera_per_folder"}
_OPTIONS = {"camera-K": "camera_K", "cluster": "cluster", "cluster-shard": "cluster_shard",
            "images": "images", "jobs": "jobs", "manifest": "manifest", "masks": "masks",
            "output": "output", "rig": "rig", "shard": "shard", "threads": "threads",
            "video": "videos", "model-index": "model_index", "options": "options"}
_OPTION = re.compile(r"(pass |with )?--([a-z][a-zA-Z-]*)( [A-Z]+\b)?")
# Stages named as CLI steps.
_PHRASES = (
    ("run extract and match first", "call tessera.extract(...) and tessera.match(...) first"),
    ("run extract, match and partition first",
     "call tessera.extract(...), tessera.match(...) and the CLI's `tessera partition` first"),
    ("extract again with", "call tessera.extract(...) again with"),
    ("run extract first", "call tessera.extract(...) first"),
    ("run match first", "call tessera.match(...) first"),
)


def _keywords(arguments: str) -> str:
    """`--images DIR --threads 2 --json` as `images='DIR', threads=2, json=True`."""
    try:
        words = shlex.split(arguments)
    except ValueError:
        return arguments.strip()
    keywords = []
    index = 0
    while index < len(words):
        word = words[index]
        if not word.startswith("--"):
            keywords.append(repr(word))
            index += 1
            continue
        name = _OPTIONS.get(word[2:], word[2:].replace("-", "_"))
        if index + 1 < len(words) and not words[index + 1].startswith("--"):
            value = words[index + 1]
            keywords.append(f"{name}={value}" if value.isdigit() else f"{name}={value!r}")
            index += 2
        else:
            keywords.append(f"{name}=True")
            index += 1
    return ", ".join(keywords)


def _option(match: "re.Match[str]") -> str:
    """An option outside a command: "pass --force-map" as "pass force_map=True", "with
    --camera-K FILE" as "with camera_K=FILE", "pass --images" as "pass images=...", a
    named one ("--jobs: ...") as its keyword; an option that is not a stage's stays."""
    verb, name, value = match.group(1) or "", match.group(2), (match.group(3) or "").strip()
    keyword = _FLAGS.get(name, _OPTIONS.get(name))
    if keyword is None:
        return match.group(0)
    if not verb:
        return keyword + (" " + value if value else "")
    if name in _FLAGS:
        return f"{verb}{keyword}=True" + (" " + value if value else "")
    return f"{verb}{keyword}={value or '...'}"


def for_python(text: str) -> str:
    """`text` with each `tessera VERB ...` command as the call tessera.VERB(...), and the
    stages' CLI options as their keywords."""

    def command(match: "re.Match[str]") -> str:
        call = f"tessera.{match.group(2)}({_keywords(match.group(3))})"
        return f"call {call}" if match.group(1) else call

    def verb_option(match: "re.Match[str]") -> str:
        name, value = match.group(2), match.group(3)
        if not value and name not in _FLAGS:
            return f"tessera.{match.group(1)}({_OPTIONS.get(name, name)}=...)"
        return f"tessera.{match.group(1)}({_keywords('--' + name + value)})"

    # The warnings are logging records, shown only where the program shows them.
    text = text.replace("(see the warnings above)",
                        "(see the warnings logged on 'tessera.map' and 'tessera.match')")
    for cli, python in _PHRASES:
        text = text.replace(cli, python)
    # Backticked commands first; the options left are outside any command.
    parts = re.split(r"(`[^`]*`)", _COMMAND.sub(command, text))
    for index in range(0, len(parts), 2):
        parts[index] = _OPTION.sub(_option, _VERB_OPTION.sub(verb_option, parts[index]))
    return "".join(parts)
