"""Hypothesis profiles. The default ``ci`` profile is derandomised: every run draws the same examples,
so a result of ``.ci/run`` does not depend on luck. ``HYPOTHESIS_PROFILE=explore`` draws fresh
random examples, ten times as many, to hunt for new failures; add what it finds as ``@example``.

pytest restarts itself once (before any test or worker starts) when it runs the C library's math
functions built with fused multiply-adds: the tests then compute the bits that the pipeline's jobs
compute on every x86-64 CPU (``geardyn.libm``).

``pytest -n 2`` hands the tests to its two workers in units (pytest-xdist's ``--dist loadscope``, set in
pyproject.toml, with the scopes of :func:`unit`): the tests that read one of the session's workflow builds
(``_workflow.shared``) form one unit, so that no worker waits for a build the other is making; these units go out
first, the longest build first, so that the two workers share them and the short tests fill in after; every other
test module is one unit, so that its module-scoped fixtures are set up once.

geardyn is imported before anything else, so that its OpenBLAS setting (``geardyn.BLAS_CORETYPE``) holds
in the test process as in the pipeline's jobs."""

import os

import pytest
from hypothesis import settings

import geardyn  # first: pins OpenBLAS's kernels before any test module loads numpy

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", derandomize=False, deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def pytest_configure(config):
    """The restart (:func:`geardyn.libm.restart_canonical`) with pytest's own output capture stopped, so
    that the new process writes to the terminal."""
    if geardyn.libm.needs_restart() and not os.environ.get("PYTEST_XDIST_WORKER"):
        capman = config.pluginmanager.getplugin("capturemanager")
        if capman is not None:
            capman.stop_global_capturing()
        geardyn.libm.restart_canonical()


#: The test modules that read one of the session's workflow builds, and the unit of work of that build's readers.
BUILDS = {
    "tests/test_own_design.py": "own_designs",
    "tests/test_faults.py": "faults",
    "tests/test_pipeline_outputs.py": "pipeline",
    "tests/test_quickstart.py": "results_build",
    "tests/test_results_tree.py": "results_build",  # and one test of the pipeline's build, made by then
    "tests/test_curves_workflow.py": "curves_workflow",
}
#: The units of the builds in the order the workers take them: the longest first (seconds of setup, idle).
FIRST = ("own_designs", "faults", "pipeline", "results_build", "curves_workflow")


def unit(nodeid: str) -> str:
    """The unit of work of a test: its build's (:data:`BUILDS`), else its module."""
    module = nodeid.split("::")[0]
    return BUILDS.get(module, module)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadscope`` with :func:`unit` as the scope (pytest-xdist asks this hook for its scheduler)."""
    if config.getoption("dist") != "loadscope":
        return None
    from xdist.scheduler import LoadScopeScheduling  # noqa: PLC0415 - only where pytest-xdist runs the tests

    class Units(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return unit(nodeid)

    return Units(config, log)


def pytest_collection_modifyitems(config, items):
    """In a pytest-xdist worker: the tests of the units of :data:`FIRST` first, in that order (every worker
    collects the same order; the scheduler hands the units out in it, ``--no-loadscope-reorder``)."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return
    rank = {name: i for i, name in enumerate(FIRST)}
    items.sort(key=lambda item: rank.get(unit(item.nodeid), len(FIRST)))
