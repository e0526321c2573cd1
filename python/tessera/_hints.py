"""The host's hints name CLI commands ("run `tessera extract` first"); a call from Python
reads them as the Python call that does the same ("call tessera.extract() first")."""

import re
import shlex

_COMMAND = re.compile(r"(?:\b(run|rerun) )?`tessera ([a-z_]+)((?: [^`]*)?)`")


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
        name = word[2:].replace("-", "_")
        if index + 1 < len(words) and not words[index + 1].startswith("--"):
            value = words[index + 1]
            keywords.append(f"{name}={value}" if value.isdigit() else f"{name}={value!r}")
            index += 2
        else:
            keywords.append(f"{name}=True")
            index += 1
    return ", ".join(keywords)


def for_python(text: str) -> str:
    """`text` with each `tessera VERB ...` command as the call tessera.VERB(...)."""

    def replace(match: "re.Match[str]") -> str:
        verb = "run" if match.group(2) == "run" else match.group(2)
        call = f"tessera.{verb}({_keywords(match.group(3))})"
        return f"call {call}" if match.group(1) else call

    # The warnings are logging records, shown only where the program shows them.
    text = text.replace("(see the warnings above)",
                        "(see the warnings logged on 'tessera.map' and 'tessera.match')")
    return _COMMAND.sub(replace, text)
