"""Logging for pipeline scripts: one log file per job, plus warnings captured; an :class:`OSError` that ends
the job is one line on stderr."""

from __future__ import annotations

import errno
import logging
import sys
from pathlib import Path


def to_file(path: str | Path | None, name: str = "geardyn") -> logging.Logger:
    """Send ``geardyn`` log records (and Python warnings) to ``path``; return the logger.  From here on an
    :class:`OSError` that ends the process (a full disk, a read-only folder, a quota) prints one line on stderr,
    :func:`oserror_line`, and its traceback goes to the log where the disk takes it."""
    sys.excepthook = _excepthook
    logging.raiseExceptions = False  # a log on a full disk: no traceback for every record it cannot write
    logger = logging.getLogger(name)
    logger.setLevel(logging.INFO)
    if path is not None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        handler = logging.FileHandler(path, mode="w", encoding="utf-8")
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        logger.addHandler(handler)
        logging.getLogger("py.warnings").addHandler(handler)
    logging.captureWarnings(True)
    return logger


def oserror_line(err: OSError) -> str:
    """What failed and where: ``geardyn: No space left on device (ENOSPC): results/.../chunk_0.nc``."""
    code = errno.errorcode.get(err.errno or 0, f"errno {err.errno}")
    where = " -> ".join(str(f) for f in (err.filename, err.filename2) if f is not None) or "(no path)"
    return f"geardyn: {err.strerror or err} ({code}): {where}"


def _excepthook(kind: type[BaseException], err: BaseException, tb: object) -> None:
    if not isinstance(err, OSError):
        sys.__excepthook__(kind, err, tb)  # type: ignore[arg-type]
        return
    log = logging.getLogger("geardyn")
    if log.handlers:  # without one, logging would print the traceback on stderr
        log.error("%s", oserror_line(err), exc_info=(kind, err, tb))  # type: ignore[arg-type]
    print(oserror_line(err), file=sys.stderr)
