"""File helpers of the paper-2 adapters: thin wrappers over :mod:`geardyn.io` and :mod:`geardyn.config`.

This is the only module of :mod:`geardyn.plus` that touches files; the numerical modules stay pure.
"""

from __future__ import annotations

import contextlib
import logging
from pathlib import Path
from typing import Any, Iterator, Mapping

import pandas as pd
import xarray as xr

from geardyn import io
from geardyn.config import load_design_dict

from .design import PlusDesign, design_from_dict

PAPER = "yue2014"


def read_design(path: str | Path) -> PlusDesign:
    """Read and schema-validate the YAML design (``geardyn.config``), then build the :class:`PlusDesign`."""
    return design_from_dict(load_design_dict(path))


def provenance(design: PlusDesign, title: str, variant: str, extra: Mapping[str, Any] | None = None) -> dict[str, str]:
    """Global attributes (source, history, git commit, config hash of the validated design, variant)."""
    return io.provenance(title=title, paper=PAPER, config=dict(design.raw), model_variant=variant, extra=extra)


def write_netcdf(ds: xr.Dataset, path: str | Path, attrs: Mapping[str, str]) -> Path:
    """Atomic, CF-checked netCDF write (``geardyn.io.write_netcdf``)."""
    return io.write_netcdf(ds, path, attrs)


def write_table(df: pd.DataFrame, csv: str | Path, md: str | Path | None = None, header: str = "", floatfmt: str = ".4g") -> None:
    """CSV (full precision) and, if asked, a Markdown version with a header paragraph."""
    from .tables import to_markdown

    Path(csv).parent.mkdir(parents=True, exist_ok=True)
    io.write_text(df.to_csv(index=False, float_format="%.6g"), csv)
    if md is not None:
        io.write_text((header + "\n\n" if header else "") + to_markdown(df, floatfmt), md)


def write_text(text: str, path: str | Path) -> Path:
    return io.write_text(text, path)


def write_figure(fig, path: str | Path, caption: str) -> Path:
    """Save a Figure (PNG, 150 dpi) and its caption file ``<path>.txt`` (``geardyn.io.save_figure``)."""
    return io.save_figure(fig, path, caption)


@contextlib.contextmanager
def logger(path: str | Path | None, name: str) -> Iterator[logging.Logger]:
    """A logger writing to ``path`` (if given) for the duration of the block; handlers closed after."""
    log = logging.getLogger(name)
    log.setLevel(logging.INFO)
    log.propagate = False
    handlers: list[logging.Handler] = []
    if path:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        h = logging.FileHandler(path, mode="w", encoding="utf-8")
        h.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        log.addHandler(h)
        handlers.append(h)
    try:
        yield log
    except Exception:
        log.exception("failed")
        raise
    finally:
        for h in handlers:
            log.removeHandler(h)
            h.close()
