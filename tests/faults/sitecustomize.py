"""The fault point of the kill tests, loaded at interpreter start (Python's ``sitecustomize``) by every process
whose PYTHONPATH holds this folder: a workflow job interrupts itself where ``GEARDYN_FAULT`` says.

``<rule>:<n>:<SIGNAL>``: when the n-th job of ``rule`` starts (its script, which Snakemake runs as a file named
``*.<rule>.py``; counted in the file named by ``GEARDYN_FAULT_COUNTER``), SIGNAL goes to the whole process group
(Snakemake and its jobs). The kill-and-resume tests start Snakemake in its own process group with
``GEARDYN_FAULT=sweep_chunk:3:SIGINT`` (Ctrl-C) or ``...:SIGKILL`` (a power cut) and ``--cores 1``: exactly two
chunks are finished when the third starts and the run dies, whatever the machine's speed. Nothing of this is in
the package: production code imports nothing made for tests.
"""

import os
import signal
import sys


def _fault_point() -> None:
    spec = os.environ.get("GEARDYN_FAULT", "")
    if not spec:
        return
    rule, nth, name = spec.split(":")
    if not (sys.argv and sys.argv[0].endswith(f".{rule}.py")):
        return
    with open(os.environ["GEARDYN_FAULT_COUNTER"], "a+", encoding="utf-8") as fh:
        fh.write("x")
        fh.seek(0)
        count = len(fh.read())
    if count == int(nth):
        os.killpg(os.getpgrp(), getattr(signal, name))


_fault_point()
