"""Logging for pipeline scripts: one log file per job, plus warnings captured; an :class:`OSError` that ends
the job is one line on stderr."""

from __future__ import annotations

import errno
import logging
import sys
from pathlib import Path


def to_file(path: str | Path | None) -> logging.Logger:
    """Send ``geardyn`` log records (and Python warnings) to ``path``; return the logger.  From here on an
    :class:`OSError` that ends the process (a full disk, a read-only folder, a quota) is one line on stderr,
    ``geardyn: No space left on device (ENOSPC): <path>``, its traceback in the log where the disk takes it."""
    sys.excepthook = _excepthook
    logging.raiseExceptions = False  # a log on a full disk: no traceback for each record it cannot write
    logger = logging.getLogger("geardyn")
    logger.setLevel(logging.INFO)
    if path is not None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        handler = logging.FileHandler(path, mode="w", encoding="utf-8")
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        logger.addHandler(handler)
        logging.getLogger("py.warnings").addHandler(handler)
    logging.captureWarnings(True)
    return logger


def _excepthook(kind: type[BaseException], err: BaseException, tb: object) -> None:
    if not isinstance(err, OSError):
        return sys.__excepthook__(kind, err, tb)  # type: ignore[arg-type]
    where = " -> ".join(str(f) for f in (err.filename, err.filename2) if f is not None)
    line = f"geardyn: {err.strerror or err} ({errno.errorcode.get(err.errno or 0, err.errno)}): {where or '?'}"
    if logging.getLogger("geardyn").handlers:  # without one, logging would print the traceback on stderr
        logging.getLogger("geardyn").error(line, exc_info=(kind, err, tb))  # type: ignore[arg-type]
    print(line, file=sys.stderr)
