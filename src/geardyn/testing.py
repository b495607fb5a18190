"""Run a workflow script without Snakemake (:func:`run_script` with a :class:`Job` in place of the
``snakemake`` object it reads, e.g. from a test or a notebook), and the fault points of the kill tests.
"""

from __future__ import annotations

import os
import runpy
import signal
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any


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


#: ``<rule>:<n>:<SIGNAL>``: when the n-th job of ``rule`` starts (counted in the file named by
#: ``GEARDYN_FAULT_COUNTER``), send SIGNAL to the whole process group (Snakemake and its jobs).
FAULT_ENV = "GEARDYN_FAULT"


def fault_point(rule: str) -> None:
    """A deterministic interruption for fault tests: does nothing unless ``GEARDYN_FAULT`` names ``rule``.

    The kill-and-resume tests start Snakemake in its own process group with ``GEARDYN_FAULT=
    sweep_chunk:3:SIGINT`` (Ctrl-C) or ``...:SIGKILL`` (a power cut) and ``--cores 1``: exactly two
    chunks are finished when the third starts and the run dies, whatever the machine's speed.
    """
    spec = os.environ.get(FAULT_ENV, "")
    if not spec.startswith(f"{rule}:"):
        return
    _, nth, name = spec.split(":")
    counter = os.environ["GEARDYN_FAULT_COUNTER"]
    with open(counter, "a+", encoding="utf-8") as fh:
        fh.write("x")
        fh.seek(0)
        count = len(fh.read())
    if count == int(nth):
        os.killpg(os.getpgrp(), getattr(signal, name))
