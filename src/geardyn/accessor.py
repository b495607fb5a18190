"""``ds.geardyn``: an output of the pipeline read by name and drawn as the workflow draws it (registered when
:mod:`geardyn` is imported; ``docs/notebook.md`` has the table of what it offers).

The names are the flags' (``flag_values``/``flag_meanings``, read with cf_xarray's flag support, which also gives
``ds.cf``): a motion label by its short name (``P1``, ``QP``, ``chaos``: :func:`geardyn.label.vocabulary.short_name`)
or its flag meaning (``quasi_periodic``), an impact class or a bifurcation kind by its flag meaning (the one
vocabulary of :mod:`geardyn.solve.bifurcations` and :data:`geardyn.solve.response.IMPACT_CLASSES`).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import cf_xarray  # noqa: F401  (registers ds.cf, whose flag support reads the codes by name)
import numpy as np
import pandas as pd
import xarray as xr

from geardyn.io.provenance import runtime_of
from geardyn.io.tree import SOURCE
from geardyn.label.vocabulary import short_name

#: The kind of an output from its folder below ``results/<design>/`` and the end of its name (first match).
KINDS: tuple[tuple[str, str, str], ...] = (
    ("sweeps", "", "sweep"),
    ("points", "", "points"),
    ("maps", "_curves", "curves"),
    ("maps", "", "map"),
    ("curves", "", "curves"),
    ("probabilities", "", "probabilities"),
    ("response", "", "response"),
    ("orbits", "_branches", "branches"),
    ("orbits", "_attractors", "attractors"),
    ("calibration", "_sensitivity", "sensitivity"),
    ("calibration", "_map", "score_map"),
    ("calibration", "", "calibration"),
)


def kind_of(path: str | Path) -> str:
    """The kind of the output at ``path`` (``results/<design>/<folder>/<name>.nc``): a study's (:data:`KINDS`), or
    for ``data/`` and ``benchmarks/`` the file's name (``closed_graph``, ``te``, ``work_precision`` ...)."""
    path = Path(path)
    folder, stem = path.parent.name, path.stem
    found = next((kind for f, end, kind in KINDS if f == folder and stem.endswith(end)), None)
    return found or stem


def _labels_of(da: xr.DataArray) -> bool:
    """Whether ``da`` holds motion labels (its flags name the periods)."""
    return "period_1" in str(da.attrs.get("flag_meanings", "")).split()


def _display(da: xr.DataArray) -> dict[str, str]:
    """flag meaning -> the name a user reads: a motion label's short name, else the meaning itself."""
    meanings = str(da.attrs["flag_meanings"]).split()
    if not _labels_of(da):
        return {m: m for m in meanings}
    codes = np.atleast_1d(da.attrs["flag_values"]).tolist()
    return {m: short_name(int(c)) for m, c in zip(meanings, codes, strict=True)}


#: The numbers ``describe`` shows first: the response measures and exponents a user reads a study for.
HEADLINES = ("dynamic_factor", "dte_rms", "lyapunov", "dynamic_factor_quantile", "family_probability", "contact_ratio")


@xr.register_dataset_accessor("geardyn")
class GeardynAccessor:
    """The ``ds.geardyn`` accessor (module docstring)."""

    def __init__(self, ds: xr.Dataset) -> None:
        self._ds = ds

    # --- what the file is ---

    @property
    def path(self) -> Path | None:
        """The file the dataset was read from (a node of :func:`geardyn.open_results`, or ``xr.open_dataset``)."""
        where = self._ds.attrs.get(SOURCE) or self._ds.encoding.get("source")
        return Path(where) if where else None

    @property
    def kind(self) -> str:
        """The output's kind (:func:`kind_of`); for a dataset not read from a build's folders, from its attributes."""
        if self.path is not None and self.path.parent.name in {f for f, _, _ in KINDS} | {"data", "benchmarks"}:
            return kind_of(self.path)
        attrs, dims = self._ds.attrs, set(self._ds.dims)
        guesses = (
            ("curve_parameters" in attrs, "curves"),
            ("axis_parameter" in attrs and "sample" in dims, "probabilities"),
            ("control_parameter" in attrs, "sweep"),
            ({"x", "y"} <= dims and "label" in self._ds, "map"),
        )
        return next((kind for hit, kind in guesses if hit), "unknown")

    @property
    def provenance(self) -> dict[str, Any]:
        """The design, the config, the versions and the commit that made the file (its global attributes)."""
        attrs = self._ds.attrs
        config = json.loads(attrs["config_json"]) if "config_json" in attrs else {}
        design = config.get("design", {})
        return {
            "design": design.get("name") if isinstance(design, Mapping) else design,
            "paper": attrs.get("paper"),
            "title": attrs.get("title"),
            "config": config,
            "config_hash": attrs.get("config_hash"),
            "geardyn_version": attrs.get("geardyn_version"),
            "git_commit": attrs.get("git_commit"),
            "created": attrs.get("history"),
            "versions": runtime_of(attrs),
        }

    # --- flags by name ---

    @property
    def flag_variables(self) -> list[str]:
        """The variables that hold codes with names (cf_xarray's flag variables)."""
        return [str(n) for n, v in self._ds.variables.items() if xr.DataArray(v).cf.is_flag_variable]

    def names(self, var: str = "label") -> xr.DataArray:
        """The codes of flag variable ``var`` as names (motion labels by short name, others by flag meaning; ""
        where a code has none), from cf_xarray's flag masks."""
        da = self._ds[var]
        if not da.cf.is_flag_variable:
            raise KeyError(f"{var}: not a flag variable (flag variables: {', '.join(self.flag_variables) or 'none'})")
        display, masks = _display(da), da.cf.flags
        out = np.select([masks[m].values for m in display], list(display.values()), default="").astype(object)
        return da.copy(data=out).assign_attrs({"long_name": da.attrs.get("long_name", var) + " (by name)"})

    @property
    def labels(self) -> xr.DataArray:
        """The motion labels by name (``P1``, ``P2``, ``QP``, ``chaos`` ...)."""
        return self.names("label")

    @property
    def impact_classes(self) -> xr.DataArray:
        """The impact classes by name (``no_impact``, ``single_sided``, ``double_sided`` ...)."""
        return self.names("impact_class")

    @property
    def bifurcations(self) -> xr.DataArray:
        """The bifurcation kinds by name (``period_doubling``, ``neimark_sacker`` ...): a point's, or a curve's."""
        return self.names("bifurcation" if "bifurcation" in self._ds else "curve_kind")

    def where(self, name: str, var: str | None = None) -> xr.DataArray:
        """True where flag variable ``var`` (None: the first that knows ``name``, the motion label first) holds
        ``name`` (a short name such as ``QP`` or a flag meaning such as ``double_sided``)."""
        order = ["label", *(v for v in self.flag_variables if v != "label")] if var is None else [var]
        for v in (v for v in order if v in self._ds.variables):
            meaning = {**{d: m for m, d in _display(self._ds[v]).items()}, **{m: m for m in _display(self._ds[v])}}
            if name in meaning:
                return (self._ds[v].cf == meaning[name]).rename(name)
        known = sorted({d for v in order if v in self._ds.variables for d in _display(self._ds[v]).values()})
        raise KeyError(f"name {name!r}: not a flag of {', '.join(order)} (allowed: {', '.join(known) or 'none'})")

    def shares(self, var: str = "label", by: Sequence[str] | None = None) -> pd.DataFrame:
        """The share of each name of ``var`` (a row per line or map, columns the names present, each row summing
        to 1); ``by``: the dimensions that make a row (default: every dimension but the study's axes)."""
        names = self.names(var)
        axes = set(self._axes()) | {"sample"}
        by = [str(d) for d in names.dims if d not in axes] if by is None else list(by)
        table = names.to_dataframe(name=var).reset_index()
        index = [table[d] for d in by] if by else pd.Series("all", index=table.index, name="of")
        return pd.crosstab(index, table[var], normalize="index").rename_axis(columns=var)

    def _axes(self) -> list[str]:
        """The dimensions of the study's axes (a sweep's parameter, a map's x and y, the probabilities' axis ...)."""
        attrs = self._ds.attrs
        named = [attrs.get("control_parameter"), attrs.get("axis_parameter"), "x", "y", "w"]
        return [str(d) for d in named if d in self._ds.dims]

    def describe(self, max_lines: int = 19) -> list[str]:
        """What the file is, its axes, its label shares (or its headline numbers) and its provenance, in at most
        ``max_lines`` lines (``geardyn show``)."""
        ds, prov = self._ds, self.provenance
        versions = prov["versions"]
        tail = [
            f"made by geardyn {prov['geardyn_version']}, commit {prov['git_commit']}; {prov['created']}",
            "with "
            + ", ".join(f"{k.removesuffix('_version')} {v}" for k, v in versions.items() if k.endswith("_version")),
        ]
        lines = [
            f"{self.kind} of design {prov['design'] or 'unknown'}: {_title(ds) or 'untitled'}",
            "axes: " + (", ".join(f"{d} ({n}: {_extent(ds, d)})" for d, n in ds.sizes.items()) or "none"),
        ]
        flags = set(self.flag_variables)
        for var in (v for v in ("label", "impact_class") if v in flags):
            shares = self.shares(var, by=[]).iloc[0].sort_values(ascending=False)
            lines.append(f"{var} shares: " + ", ".join(f"{k} {v:.3f}" for k, v in shares.items()))
        numbers = [v for v in ds.data_vars if v not in flags and ds[v].dtype.kind in "fiu" and ds[v].size]
        numbers.sort(key=lambda v: v not in HEADLINES)
        room = max_lines - len(lines) - len(tail) - 1
        for v in numbers[:room]:
            values = np.asarray(ds[v].values, float)
            finite = values[np.isfinite(values)]
            span = f"{finite.min():.4g} .. {finite.max():.4g}" if finite.size else "no finite value"
            lines.append(f"{v}: {span} {ds[v].attrs.get('units', '')}".rstrip())
        if len(numbers) > room:
            lines.append(f"... and {len(numbers) - room} more numeric variables ({len(ds.data_vars)} variables in all)")
        return lines + tail

    # --- figures ---

    def plot(
        self,
        *,
        range: tuple[float, float] | Mapping[str, tuple[float, float]] | None = None,
        line: Any = None,
        panel: int | None = None,
        title: str | None = None,
    ) -> Any:
        """The figure the workflow draws for this kind of file (the same function of :mod:`geardyn.plots`), as a
        :class:`matplotlib.figure.Figure`.  ``range``: a sub-range (lo, hi) of the study's first axis, or
        {dimension: (lo, hi)}; ``line``: one line (a case of a sweep or of points); ``panel``: only the figure's
        panel of that index (0: the first; colour bars follow their panel)."""
        ds = self._ds
        if range is not None:
            if not isinstance(range, Mapping) and not self._axes():
                raise ValueError(f"range={range!r}: a {self.kind} file has no axis (give {{dimension: (lo, hi)}})")
            box = range if isinstance(range, Mapping) else {self._axes()[0]: range}
            ds = ds.sel({d: slice(*sorted(lim)) for d, lim in box.items()})
        if line is not None:
            if "case" not in ds.dims:
                raise ValueError(f"line={line!r}: a {self.kind} file has no lines (allowed: sweeps and points)")
            ds = ds.sel(case=[line])
        draw = FIGURES.get(self.kind)
        if draw is None:
            raise ValueError(f"kind {self.kind!r}: no figure of its own (allowed: {', '.join(sorted(FIGURES))})")
        fig = draw(ds, title or _title(ds), self.path)
        return fig if panel is None else _only_panel(fig, panel)


def _extent(ds: xr.Dataset, dim: Any) -> str:
    """The first and last value of dimension ``dim`` (its index when it has no coordinate)."""
    if dim not in ds.coords:
        return "no coordinate"
    values = ds[dim].values
    if values.dtype.kind in "fiu":
        return f"{values[0]:.4g} .. {values[-1]:.4g}"
    return ", ".join(map(str, values[:3])) + (" ..." if values.size > 3 else "")


def _title(ds: xr.Dataset) -> str:
    """The study's title as the workflow's figure gives it: the config entry's, else the file's."""
    config = json.loads(ds.attrs.get("config_json", "{}"))
    spec = next((v for k, v in config.items() if k != "design" and isinstance(v, Mapping) and "title" in v), {})
    return str(spec.get("title") or ds.attrs.get("title", ""))


def _spec(ds: xr.Dataset) -> dict[str, Any]:
    """The study's config entry (the file's ``config_json`` without the design)."""
    config = json.loads(ds.attrs.get("config_json", "{}"))
    return dict(next((v for k, v in config.items() if k != "design" and isinstance(v, Mapping)), {}))


def _beside(path: Path | None, name: str) -> xr.Dataset | None:
    """The output ``name`` in the folder of ``path`` (a map's curves, a curves file's map), read, or None."""
    from geardyn.io import read_dataset  # noqa: PLC0415 - geardyn.io imports this module's package first

    other = None if path is None else path.with_name(name)
    return read_dataset(other) if other is not None and other.exists() else None


def _only_panel(fig: Any, panel: int) -> Any:
    """``fig`` with only its panel ``panel`` (and that panel's colour bar), enlarged to the figure."""
    bars = {id(ax) for ax in fig.axes if hasattr(ax, "_colorbar")}
    panels = [ax for ax in fig.axes if id(ax) not in bars]
    if not 0 <= panel < len(panels):
        raise ValueError(f"panel = {panel}: out of range (allowed: 0 to {len(panels) - 1})")
    keep = panels[panel]
    for ax in fig.axes:
        mine = id(ax) in bars and getattr(ax._colorbar.mappable, "axes", None) is keep
        if ax is not keep and not mine:
            fig.delaxes(ax)
    if keep.get_subplotspec() is not None:
        keep.set_subplotspec(fig.add_gridspec(1, 1)[0])
    return fig


def _map(ds: xr.Dataset, title: str, path: Path | None) -> Any:
    from geardyn.plots.dynamics import plot_map  # noqa: PLC0415 - matplotlib only when a figure is drawn

    spec = _spec(ds)
    curves = _beside(path, f"{path.stem}_curves.nc") if path is not None else None
    return plot_map(ds, title, spec.get("cuts_x", []), spec.get("cuts_y", []), curves)


def _curves(ds: xr.Dataset, title: str, path: Path | None) -> Any:
    from geardyn.plots.curves import plot_curves  # noqa: PLC0415 - matplotlib only when a figure is drawn
    from geardyn.plots.dynamics import label_image  # noqa: PLC0415 - matplotlib only when a figure is drawn

    cube = _beside(path, path.name.removesuffix("_curves.nc") + ".nc") if path and path.parent.name == "maps" else None
    title += "" if "boundar" in title.lower() else ": regime boundaries"
    return plot_curves(ds, title, label_image(cube) if cube is not None else None)


def _simple(module: str, function: str, titled: bool = True) -> Callable[[xr.Dataset, str, Path | None], Any]:
    """A figure of ``module.function`` that takes the dataset (and the title when ``titled``)."""

    def draw(ds: xr.Dataset, title: str, path: Path | None) -> Any:
        import importlib  # noqa: PLC0415 - matplotlib only when a figure is drawn

        fn = getattr(importlib.import_module(f"geardyn.plots.{module}"), function)
        return fn(ds, title) if titled else fn(ds)

    return draw


def _branches(ds: xr.Dataset, title: str, path: Path | None) -> Any:
    from geardyn.plots.orbits import plot_branches  # noqa: PLC0415 - matplotlib only when a figure is drawn

    return plot_branches(None, ds, title)


#: kind -> the workflow's figure of it (dataset, title, path) -> Figure.
FIGURES: dict[str, Callable[[xr.Dataset, str, Path | None], Any]] = {
    "sweep": _simple("dynamics", "plot_bifurcation"),
    "points": _simple("dynamics", "plot_points"),
    "map": _map,
    "curves": _curves,
    "probabilities": _simple("probabilities", "probabilities_figure"),
    "response": _simple("response", "frequency_response_figure"),
    "branches": _branches,
    "score_map": _simple("calibration", "plot_score_map", titled=False),
    "closed_graph": _simple("closed_graph", "plot_closed_graph", titled=False),
    "stiffness_table": _simple("stiffness", "plot_mesh_stiffness", titled=False),
    "te": _simple("plus", "te_unmodified_figure", titled=False),
    "forced_response": _simple("plus", "forced_response_figure", titled=False),
    "modal": _simple("plus", "mode_shape_figure", titled=False),
}
