"""File helpers of the paper-2 adapters (to be replaced by ``geardyn.io`` once it is on main).

This is the only module of :mod:`geardyn.plus` that touches files; the numerical modules stay pure.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import hashlib
import json
import logging
from pathlib import Path
from typing import Any, Iterator, Mapping

import pandas as pd
import xarray as xr
import yaml

from .design import PlusDesign, design_from_dict


def read_design(path: str | Path) -> PlusDesign:
    """Parse the YAML design file and build the validated :class:`PlusDesign`."""
    return design_from_dict(yaml.safe_load(Path(path).read_text()))


def config_hash(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16]


def provenance(design_path: str | Path, title: str, variant: str, extra: Mapping[str, Any] | None = None) -> dict[str, str]:
    """Global attributes: source, history, config hash, model variant."""
    now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    attrs = {
        "title": title,
        "source": "geardyn.plus (Yue et al. 2014, J. Vibroengineering, plus planetary gear set)",
        "history": f"{now} created by geardyn.plus from {Path(design_path).name}",
        "config_hash": config_hash(design_path),
        "model_variant": variant,
        "Conventions": "CF-1.10",
    }
    if extra:
        attrs["config"] = json.dumps(extra, default=str, sort_keys=True)
    return attrs


def write_netcdf(ds: xr.Dataset, path: str | Path, attrs: Mapping[str, str]) -> None:
    """Write ``ds`` with provenance attributes (object/str variables stored as strings)."""
    ds = ds.copy()
    ds.attrs.update(attrs)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(path)


def write_table(df: pd.DataFrame, csv: str | Path, md: str | Path | None = None, header: str = "", floatfmt: str = ".4g") -> None:
    from .tables import to_markdown

    Path(csv).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(csv, index=False, float_format="%.6g")
    if md is not None:
        Path(md).write_text((header + "\n\n" if header else "") + to_markdown(df, floatfmt))


def write_figure(fig, path: str | Path, caption: str) -> None:
    """Save a Figure (PNG, 150 dpi) and its caption file ``<path>.txt``."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    Path(str(path) + ".txt").write_text(caption.strip() + "\n")


@contextlib.contextmanager
def logger(path: str | Path | None, name: str) -> Iterator[logging.Logger]:
    """A logger writing to ``path`` (if given) for the duration of the block; handlers closed after."""
    log = logging.getLogger(name)
    log.setLevel(logging.INFO)
    log.propagate = False
    handlers: list[logging.Handler] = []
    if path:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        h = logging.FileHandler(path, mode="w")
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
