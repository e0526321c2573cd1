"""The host's log lines as records of Python's `logging`: logger "tessera", one child per
stage ("tessera.extract", "tessera.match", "tessera.map", "tessera.export", ...). The
library adds only a NullHandler, so nothing is printed unless the program configures
logging (logging.basicConfig(level=logging.INFO) shows what `tessera run` prints)."""

import logging
import re

from . import _hints

logger = logging.getLogger("tessera")
logger.addHandler(logging.NullHandler())

# The stages whose lines start "stage: ..."; other lines belong to the stage last named.
STAGES = ("extract", "match", "map", "export", "partition", "merge", "georeference", "plugins",
          "run", "bench", "triangulate", "register", "adjust", "align", "import")
_PREFIX = re.compile(r"^([a-z_]+):")
# spdlog's levels (trace, debug, info, warn, err, critical) as logging's.
_LEVELS = (logging.DEBUG, logging.DEBUG, logging.INFO, logging.WARNING, logging.ERROR,
           logging.CRITICAL)


def child_threshold(verb: str) -> int:
    """The lowest spdlog level any stage logger of `verb` would emit (2: info), so that the
    child formats and sends no line that every logger would drop; 6: none."""
    loggers = [logger] + [logger.getChild(stage) for stage in STAGES]
    for spdlog_level, level in enumerate(_LEVELS):
        if any(each.isEnabledFor(level) for each in loggers):
            return spdlog_level
    return 6


class StageLog:
    """The log of one call (`verb`): each line to the logger of the stage it names."""

    def __init__(self, verb: str) -> None:
        self.stage = verb

    def emit(self, spdlog_level: int, text: str) -> None:
        prefix = _PREFIX.match(text)
        if prefix and prefix.group(1) in STAGES:
            self.stage = prefix.group(1)
        level = _LEVELS[min(max(spdlog_level, 0), len(_LEVELS) - 1)]
        target = logger.getChild(self.stage)
        if target.isEnabledFor(level):
            target.log(level, "%s", _hints.for_python(text))
