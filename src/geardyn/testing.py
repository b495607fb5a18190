"""The fault points of the kill tests: a workflow job interrupts itself where ``GEARDYN_FAULT`` says."""

from __future__ import annotations

import os
import signal

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
