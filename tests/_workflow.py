"""Helpers for tests that run the Snakemake workflow on a copy in a temporary directory.

The copy holds workflow/ (its Snakefile too), config/ and benchmarks/ (the work-precision target's code, beside the
package); the library comes from this checkout's src/ via PYTHONPATH. Nothing is ever written into the
repository's own results/.
"""

from __future__ import annotations

import copy
import fcntl
import os
import runpy
import shutil
import subprocess
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parents[1]

#: Integrator settings that make a sweep point take a few milliseconds.
FAST = {"steps_per_period": 64, "transient_periods": 40, "recorded_periods": 8}


def shipped(rel: str) -> dict[str, Any]:
    return yaml.safe_load((ROOT / rel).read_text(encoding="utf-8"))


def workflow_copy(
    dest: Path, config: dict[str, Any] | None = None, designs: dict[str, dict[str, Any]] | None = None
) -> Path:
    """Copy the workflow to ``dest``; replace config.yaml and design files by the given mappings."""
    dest.mkdir(parents=True, exist_ok=True)
    for item in ("workflow", "config", "benchmarks"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, dest / item)
    if config is not None:
        (dest / "config" / "config.yaml").write_text(yaml.safe_dump(config, sort_keys=False), encoding="utf-8")
    for name, raw in (designs or {}).items():
        (dest / "config" / "designs" / f"{name}.yaml").write_text(
            yaml.safe_dump(raw, sort_keys=False), encoding="utf-8"
        )
    return dest


def env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(ROOT / "src")}


def snakemake_cmd(*args: str) -> list[str]:
    return [sys.executable, "-m", "snakemake", *args]


def snakemake(work: Path, *args: str, timeout: float = 600, check: bool = True) -> subprocess.CompletedProcess:
    """Run Snakemake in ``work``; with ``check`` a failure shows its stderr."""
    run = subprocess.run(snakemake_cmd(*args), cwd=work, env=env(), capture_output=True, text=True, timeout=timeout)
    if check and run.returncode != 0:
        raise AssertionError(f"snakemake {' '.join(args)} failed ({run.returncode}):\n{run.stderr[-4000:]}")
    return run


def sweep_config(chunks: int = 4, num: int = 12, integration: dict[str, Any] | None = None) -> dict[str, Any]:
    """A config with design li2013 and one x1 sweep, nothing else."""
    return {
        "designs": {"li2013": "config/designs/li2013.yaml"},
        "sweeps": {
            "fig07_small": {
                "designs": ["li2013"],
                "title": "small x1 sweep",
                "parameter": "x1",
                "start": 0.45,
                "stop": 0.80,
                "num": num,
                "fixed": {"b": 2.0, "e": 5.0},
                "chunks": chunks,
                "integration": dict(FAST if integration is None else integration),
            }
        },
        "points": {},
        "calibration": {},
        "benchmarks": {"work_precision": False},
    }


def small_config() -> dict[str, Any]:
    """Every kind of job of the pipeline on small grids (seconds each)."""
    cfg = sweep_config(chunks=2, num=6)
    cfg["sweeps"]["fig07_small"]["cases"] = [{"e": 5.0}, {"e": 4.5}]  # two lines: two chunks
    cfg["designs"]["yue2014"] = "config/designs/yue2014.yaml"
    cfg["closed_graph"] = {"x1": {"start": 0.2, "stop": 1.1, "num": 19}, "x2": {"start": 0.3, "stop": 1.4, "num": 23}}
    cfg["stiffness_table"] = {"points": 11, "phase_points": 32, "fig05_x1": [0.416, 0.626, 0.835]}
    cfg["points"] = {
        "fig08_small": {
            "designs": ["li2013"],
            "title": "small points",
            "fixed": {"b": 2.0, "e": 5.0},
            "cases": [{"x1": 0.5}, {"x1": 0.761}],
            "samples_per_period": 16,
        }
    }
    cfg["benchmarks"] = {"work_precision": True, "quick": True}
    cfg["probabilities"] = {
        "small_prob": {
            "designs": ["li2013"],
            "title": "small probabilities",
            "axis": {"parameter": "x1", "start": 0.45, "stop": 0.8, "num": 5},
            "fixed": {"b": 2.0, "e": 5.0},
            "inputs": {"zeta": {"low": 0.08, "high": 0.12}},
            "samples": 8,
            "sensitivity": {"samples": 8},  # the indices' Latin hypercube: 8 lines, not the default 128
            "chunks": 1,
            "claims": "fig07",
            "integration": dict(FAST),
        }
    }
    cfg["calibration"] = {
        "small_search": {
            "design": "li2013",
            "x1": {"start": 0.416, "stop": 0.835, "num": 5},
            "b": {"start": 0.0, "stop": 2.25, "num": 2},
            "e": {"start": 4.0, "stop": 5.0, "num": 2},
            "search": {
                "bounds": {"w": {"low": 0.85, "high": 0.95}, "zeta": {"low": 0.08, "high": 0.12}},
                "budget": {"popsize": 1, "maxiter": 1},
                "workers": 1,
                "verify_top": 1,
                "refine": {"steps": [0.1], "rounds": 0},
            },
            "sensitivity": {"steps": [0.1], "map_points": 2},
            "integration": dict(FAST),
        }
    }
    return cfg


def small_designs() -> dict[str, dict[str, Any]]:
    """li2013 with short point runs, yue2014 with a small relief search (as in test_plus_workflow)."""
    li = shipped("config/designs/li2013.yaml")
    li["dynamics"]["integration"].update(FAST)
    yue = shipped("config/designs/yue2014.yaml")
    yue["relief"].update(landscape_points=5, maxiter=10, popsize=6)
    yue["transmission_error"]["points_per_period"] = 60
    return {"li2013": li, "yue2014": yue}


def shared(tmp_path_factory, name: str, build) -> Path:
    """A directory ``build(path)`` fills once per test session, whichever pytest-xdist worker asks first;
    the others wait for it (a file lock) and then read the same directory."""
    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    work = root / name
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (root / f"{name}.done").exists():
            shutil.rmtree(work, ignore_errors=True)
            build(work)
            (root / f"{name}.done").touch()
    return work


def deep(data: dict[str, Any]) -> dict[str, Any]:
    return copy.deepcopy(data)


# --- run a workflow script without Snakemake (a Job in place of the ``snakemake`` object it reads) ---


class Files(list):
    """Named and positional access, like Snakemake's ``input``/``output`` (``f.name`` and ``f[0]``)."""

    def __init__(self, items: Mapping[str, Any] | Sequence[Any] | None = None) -> None:
        items = items or {}
        if isinstance(items, Mapping):
            super().__init__(items.values())
            self._names = dict(items)
        else:
            super().__init__(items)
            self._names = {}

    def __getattr__(self, name: str) -> Any:
        try:
            return self._names[name]
        except KeyError:
            raise AttributeError(name) from None

    def __getitem__(self, key: Any) -> Any:  # type: ignore[override]
        if isinstance(key, str):
            return self._names[key]
        return super().__getitem__(key)


class Job:
    """What a script reads from ``snakemake``: input, output, params, wildcards and log."""

    def __init__(
        self,
        input: Mapping[str, Any] | Sequence[Any] | None = None,
        output: Mapping[str, Any] | Sequence[Any] | None = None,
        params: Mapping[str, Any] | None = None,
        wildcards: Mapping[str, Any] | None = None,
        log: Sequence[Any] | None = None,
    ) -> None:
        self.input = Files(_strings(input))
        self.output = Files(_strings(output))
        self.params = Files(params or {})
        self.wildcards = Files({k: str(v) for k, v in (wildcards or {}).items()})
        self.log = Files([str(p) for p in (log or [])])


def _strings(items: Mapping[str, Any] | Sequence[Any] | None) -> Mapping[str, Any] | Sequence[Any] | None:
    if isinstance(items, Mapping):
        return {k: [str(x) for x in v] if isinstance(v, list | tuple) else str(v) for k, v in items.items()}
    return [str(x) for x in items] if items is not None else None


def run_script(path: str | Path, job: Job) -> dict[str, Any]:
    """Run the workflow script at ``path`` with ``job`` as its ``snakemake`` object; returns its globals."""
    return runpy.run_path(str(path), init_globals={"snakemake": job})
