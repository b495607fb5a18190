"""Command line: ``geardyn check-design``, ``check-config``, ``new-design``, ``verify-archive`` and ``show`` (each
subcommand's help says what it does; exit codes: 0 good, 1 not feasible / archive damaged, 2 invalid input;
README, A design of your own)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from geardyn import __version__, libm
from geardyn.config import ConfigError, load_design_dict
from geardyn.jsontypes import Json

#: The pair's values that ``check-design`` prints (lengths in mm).
PAIR_KEYS = ("z1", "z2", "module", "x1", "x2", "pressure_angle_deg", "addendum", "clearance", "facewidth")


def _khv_summary(raw: dict[str, Json], path: str) -> dict[str, Json]:
    from geardyn.gears import constraints  # noqa: PLC0415 - --help loads no numba or scipy
    from geardyn.khv import design  # noqa: PLC0415 - --help loads no numba or scipy

    spec = design.from_dict(raw, path, check=False)
    pair = spec.base
    derived = constraints.describe(pair, cutter=spec.cutter)
    values = constraints.constraints(pair, min_tip_thickness=spec.min_tip_thickness, cutter=spec.cutter)
    failed = design.violated_constraints(pair, spec.min_tip_thickness, spec.enforce_cutter_constraints, spec.cutter)
    problem = design.meshing_problem(pair)
    try:
        mesh = None if problem else design.mesh_properties(spec, pair.x1)
    except ConfigError as err:
        problem = str(err).split(": ", 1)[-1]
        mesh = None
    segment: dict[str, dict[str, float | str]] = {}
    for label, x1 in (("M", spec.x1_min), ("N", spec.x1_max)):
        try:
            segment[label] = {"x1": x1, "x2": design.x2_for(spec, x1)}
        except ValueError as err:
            segment[label] = {"x1": x1, "error": str(err)}
    return {
        "design": spec.name,
        "kind": "khv",
        "pair": {f"{k}_mm" if k in ("module", "facewidth") else k: getattr(pair, k) for k in PAIR_KEYS},
        "x2_source": "line 4 (G_s = 0)" if spec.x2_on_line4 else "fixed in design",
        "geometry": {k: v for k, v in derived.items() if not k.startswith("margin_")},
        "constraints (>= 0 is satisfied)": values,
        "stiffness": (
            {"options": spec.stiffness.label, "q_mm_um_per_N": mesh.q}
            | {f"{k}_N_per_um": getattr(mesh, k.lower()) / 1e6 for k in ("k_C", "k_prime", "k_mean", "k_min")}
            | {"contact_ratio": mesh.contact_ratio}
            if mesh is not None
            else {"not computed": problem}
        ),
        "admissible_segment": segment,
        "violated": failed,
    }


def _defined(data: Json) -> Json:
    """The summary with every NaN replaced by 'undefined' (a quantity the pair does not have)."""
    if isinstance(data, dict):
        return {k: _defined(v) for k, v in data.items()}
    if isinstance(data, float) and math.isnan(data):
        return "undefined"
    return data


def _print_tree(data: dict[str, Json], indent: int = 0) -> None:
    pad = "  " * indent
    for key, value in data.items():
        if isinstance(value, dict):
            print(f"{pad}{key}:")
            _print_tree(value, indent + 1)
        elif isinstance(value, float):
            print(f"{pad}{key}: {value:.6g}" if math.isfinite(value) else f"{pad}{key}: {value}")
        else:
            print(f"{pad}{key}: {value}")


def _plus_summary(raw: dict[str, Json], path: str) -> dict[str, Json]:
    from geardyn.plus import design, modal  # noqa: PLC0415 - --help loads no numba or scipy

    plus = design.design_from_dict(raw, path)
    modes = {cond: modal.modes(plus, cond) for cond in ("I", "II", "III")}
    freqs = {c: ", ".join(f"{v:.1f}" for v in md.freq_hz[md.n_rigid :][:6]) for c, md in modes.items()}
    return {
        "design": plus.name,
        "kind": "plus_planetary",
        "paper": plus.paper or "none",
        "teeth (sun, inner planet, outer planet, ring)": f"{plus.sun.teeth}, {plus.planet_p.teeth}, "
        f"{plus.planet_d.teeth}, {plus.ring.teeth}",
        "planets": plus.n_planets,
        "module_mm": plus.module * 1e3,
        "first natural frequencies (Hz)": freqs,
    }


def check_design(path: str, as_json: bool) -> int:
    """Print what can be computed of the design, then run the pipeline's own checks of it
    (:func:`geardyn.config.validate.check_design`): exit 0 when it builds, 1 when not (with the reason)."""
    from geardyn.config.validate import check_design as pipeline_check  # noqa: PLC0415 - --help loads no numba or scipy

    raw = load_design_dict(path)
    summary = _defined(_khv_summary(raw, path) if raw["kind"] == "khv" else _plus_summary(raw, path))
    try:
        pipeline_check(raw, path)
        verdict = None
    except ConfigError as err:
        verdict = str(err).removeprefix(f"{path}: ")
    summary["feasible"] = verdict is None
    summary["why not"] = verdict or ""
    summary["skipped by"] = "; ".join(_skipped_by(raw)) or "none"
    if as_json:
        print(json.dumps(summary, indent=2, default=float))
    else:
        _print_tree(summary)
        if verdict:
            print(f"NOT FEASIBLE: {verdict}")
    return 0 if verdict is None else 1


def _skipped_by(raw: dict[str, Json]) -> list[str]:
    """The studies of ``config/config.yaml`` (from the working directory, where there is one) that would skip
    the design for a block it lacks."""
    from geardyn.config.run_checks import skipped_studies  # noqa: PLC0415 - --help loads no numba or scipy
    from geardyn.config.validate import read_config_file  # noqa: PLC0415 - --help loads no numba or scipy

    config = Path("config/config.yaml")
    return skipped_studies(raw, read_config_file(config)) if raw["kind"] == "khv" and config.exists() else []


def check_config(path: str) -> int:
    from geardyn.config.validate import read_config_file, validate_workflow  # noqa: PLC0415 - --help loads no numba or scipy

    cfg = read_config_file(path)
    root = Path(path).resolve().parent.parent
    _, designs = validate_workflow(cfg, root)
    print(f"{path}: valid; designs: {', '.join(designs)}")
    return 0


def new_design(kind: str, name: str, out: str | None, force: bool, z1: int, z2: int, module: float) -> int:
    """Write a new design file and print the next two commands."""
    from geardyn.config import scaffold  # noqa: PLC0415 - --help loads no numba or scipy

    path = Path(out or f"config/designs/{name}.yaml")
    if path.exists() and not force:
        raise ConfigError(f"{path}: exists already; choose another name or pass --force")
    raw = scaffold.khv_design(name, z1, z2, module) if kind == "khv" else scaffold.plus_design(name)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(scaffold.render(raw, kind), encoding="utf-8")
    print(f"wrote {path}")
    print("next:")
    print(f"  geardyn check-design {path}")
    print(f"  add '{name}: {path}' under designs: in config/config.yaml, then: snakemake --cores 2")
    return 0


def verify_archive(path: str) -> int:
    from geardyn.io.archive import ArchiveError, verify  # noqa: PLC0415 - --help loads no numba or scipy

    try:
        print(verify(path).text())
    except ArchiveError as err:
        print(f"error: {err}", file=sys.stderr)
        return 1
    return 0


def show(path: str) -> int:
    """Print what an output file is, its axes, its label shares or headline numbers and its provenance (under 20
    lines, :meth:`geardyn.accessor.GeardynAccessor.describe`): exit 0; a file that is not a geardyn output or
    cannot be read: one line, exit 1."""
    import xarray as xr  # noqa: PLC0415 - --help loads no numba or scipy

    try:
        with xr.open_dataset(path, engine="netcdf4") as ds:
            if "geardyn_version" not in ds.attrs:
                print(f"{path}: not a geardyn output (no geardyn_version attribute)", file=sys.stderr)
                return 1
            first, *rest = ds.geardyn.describe()
            print("\n".join([f"{path}: {first}", *rest]))
    except (OSError, ValueError, KeyError, RuntimeError) as err:
        print(f"{path}: cannot be read: {' '.join(str(err).split())}", file=sys.stderr)
        return 1
    return 0


def main(argv: list[str] | None = None) -> int:
    if argv is None:  # the command itself (not a call from Python): the C library's plain math, as in the jobs
        libm.restart_canonical()
    parser = argparse.ArgumentParser(prog="geardyn", description="geardyn gear-dynamics tools")
    parser.add_argument("--version", action="version", version=f"geardyn {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("check-design", help="validate a design file and print its derived geometry")
    p.add_argument("path")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p = sub.add_parser("check-config", help="validate the workflow config and every design it lists")
    p.add_argument("path", nargs="?", default="config/config.yaml")
    p = sub.add_parser("new-design", help="write a clean, commented design file of your own")
    p.add_argument("--kind", choices=("khv", "plus"), required=True)
    p.add_argument("name", help="design name (letters, digits, _), used in results/<name>/")
    p.add_argument("--out", help="file to write (default config/designs/<name>.yaml)")
    p.add_argument("--force", action="store_true", help="overwrite an existing file")
    p.add_argument("--z1", type=int, default=40, help="KHV: planet teeth (default 40)")
    p.add_argument("--z2", type=int, default=43, help="KHV: annulus teeth (default 43)")
    p.add_argument("--module", type=float, default=2.0, help="KHV: module in mm (default 2)")
    p = sub.add_parser("verify-archive", help="check a results archive: sha256 sums and that every cube opens")
    p.add_argument("path")
    p = sub.add_parser("show", help="what an output file is: axes, label shares or headline numbers, provenance")
    p.add_argument("path")
    args = parser.parse_args(argv)
    if args.command == "verify-archive":
        return verify_archive(args.path)
    if args.command == "show":
        return show(args.path)
    try:
        if args.command == "check-design":
            return check_design(args.path, args.json)
        if args.command == "new-design":
            return new_design(args.kind, args.name, args.out, args.force, args.z1, args.z2, args.module)
        return check_config(args.path)
    except ConfigError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
