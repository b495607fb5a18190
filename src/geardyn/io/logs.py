"""Logging for pipeline scripts: one log file per job, plus warnings captured."""

from __future__ import annotations

import logging
from pathlib import Path


def to_file(path: str | Path | None, name: str = "geardyn") -> logging.Logger:
    """Send ``geardyn`` log records (and Python warnings) to ``path``; return the logger."""
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
