"""docs/quickstart.ipynb runs top to bottom (nbclient, a kernel of this venv) on the small build of
tests/_results_build.py, and is committed without outputs."""

import os

import nbformat
import pytest
from nbclient import NotebookClient

import _results_build
import _workflow as wf

NOTEBOOK = wf.ROOT / "docs" / "quickstart.ipynb"


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    return wf.shared(tmp_path_factory, "results_build", _results_build.build) / "results"


def test_the_notebook_is_committed_without_outputs():
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbformat.validate(nb)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code and all(not c.outputs and c.execution_count is None for c in code)


def test_the_notebook_runs_top_to_bottom(results, monkeypatch):
    nb = nbformat.read(NOTEBOOK, as_version=4)
    monkeypatch.setenv("GEARDYN_RESULTS", str(results))  # the kernel inherits the environment
    NotebookClient(
        nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}
    ).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) == 6  # the bifurcation diagram, map, curves, probabilities, two designs, the orbit
    text = "".join(o.get("text", "") + o.get("data", {}).get("text/plain", "") for o in outputs)
    assert "li2013_calibrated" in text and "labelled" in text
    assert os.environ.get("GEARDYN_RESULTS") == str(results)
