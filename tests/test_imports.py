"""Jobs that only read results start without the solver: their modules do not import numba, the compiled
loops or scipy's heavier packages (each workflow job is a new process, so its imports are its start-up)."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from geardyn.khv import design

HEAVY = (
    "numba",
    "scipy.optimize",
    "scipy.signal",
    "scipy.integrate",
    "scipy.interpolate",
    "geardyn.solve.run",
    "matplotlib.pyplot",
)

#: Modules of the jobs that merge chunks, draw figures and write tables, and what the DAG reads.
READERS = (
    "geardyn.runs.cube",
    "geardyn.runs.bands",
    "geardyn.plots.captions",
    "geardyn.plots.dynamics",
    "geardyn.plots.orbits",
    "geardyn.plots.stiffness",
    "geardyn.label.verdict",
    "geardyn.label.policy",
    "geardyn.solve.base",
)


@pytest.mark.parametrize("module", READERS)
def test_a_reader_module_does_not_import_the_solver(module: str) -> None:
    code = f"import sys, {module}; print(' '.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == []


def test_the_dag_reads_run_specs_without_the_solver() -> None:
    code = (
        "import sys; from geardyn.runs.sweep import SweepSpec; from geardyn.runs.maps import MapSpec; "
        f"print(' '.join(m for m in {HEAVY!r} if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == []


def test_a_labelling_job_loads_the_reference_solver_only_for_dop853() -> None:
    """The map and sweep chunks label with the RK4 loops: scipy.integrate (0.5 s) is not imported until a
    run asks for the DOP853 reference."""
    drive = Path(__file__).parents[1] / "config" / "designs" / "li2013.yaml"
    code = (
        "import sys; from geardyn.runs import maps, sweep; import geardyn.label; from geardyn.solve import simulate, "
        "warm_up, SimulationSettings; from geardyn.khv import design, point; print('scipy.integrate' in sys.modules); "
        f"c = point.point_coefficients(design.load({str(drive)!r})); "
        "r = simulate(c, SimulationSettings(integrator='dop853', transient_periods=0, recorded_periods=1)); "
        "print('scipy.integrate' in sys.modules, r.poincare.shape)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "True", "(1,", "6)"]


def test_lazy_names_resolve_to_what_they_name() -> None:
    # the package's names are loaded from their modules on first use and are those modules' objects
    code = """
import geardyn.label, geardyn.solve
from geardyn.label.lines import label_lines
from geardyn.solve import simulate, simulate_batch
from geardyn.solve.run import warm_up
import sys
mod = sys.modules["geardyn.solve.run"]
assert simulate is mod.simulate and simulate_batch is mod.simulate_batch and callable(simulate)
assert geardyn.solve.warm_up is warm_up and geardyn.label.label_lines is label_lines
try:
    geardyn.solve.no_such_name
except AttributeError:
    print("ok")
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "ok"


def test_a_design_header_is_what_the_full_design_says() -> None:
    # the jobs that only read results take the header (no geometry, no scipy.optimize): the same name, title,
    # paper, model variant and provenance record as the full design, for every KHV design shipped
    files = sorted((Path(__file__).parents[1] / "config" / "designs").glob("li2013*.yaml"))
    assert len(files) >= 4
    for path in files:
        full, head = design.load(path), design.header(path)
        assert (head.name, head.title, head.paper, head.stiffness, head.raw) == (
            full.name,
            full.title,
            full.paper,
            full.stiffness,
            full.raw,
        )
    code = (
        "import sys; from geardyn.khv import design; "
        f"design.header({str(files[0])!r}); print('scipy.optimize' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


#: The workflow's adapters that draw, merge or write tables: nothing in them integrates, so their imports (their
#: job's start-up) load neither numba nor the kernel cache, nor scipy's linear algebra.
DRAWING_ADAPTERS = (
    "closed_graph",
    "curves_figure",
    "fig03_closed_graph",
    "map_figure",
    "map_merge",
    "orbits_figure",
    "plus_claims",
    "plus_modal_figures",
    "plus_te_figures",
    "point_figure",
    "probabilities_claims",
    "probabilities_merge",
    "stiffness_figures",
    "stiffness_table",
    "sweep_merge",
)
SCRIPTS = Path(__file__).parents[1] / "workflow" / "scripts"


@pytest.mark.parametrize("adapter", DRAWING_ADAPTERS)
def test_a_drawing_or_merging_adapter_does_not_import_the_solver(adapter: str) -> None:
    # the adapter's own import statements, run as its job runs them (a new interpreter)
    tree = ast.parse((SCRIPTS / f"{adapter}.py").read_text())
    imports = [ast.unparse(n) for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)]
    assert imports, adapter
    heavy = (*HEAVY, "scipy.linalg", "geardyn.solve._cache", "geardyn.solve._batch")
    code = "\n".join(imports) + f"\nimport sys; print(' '.join(m for m in {heavy!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == []
