"""The units in which ``pytest -n 2`` hands out the tests (tests/conftest.py): every module that reads one of the
session's workflow builds has the unit of that build, so that the build's readers run on one worker, and those
units go out first."""

import re

import _workflow as wf
import conftest

TESTS = wf.ROOT / "tests"


def _readers() -> dict[str, set[str]]:
    """Test module -> the builds it reads (the names it passes to ``wf.shared``), found in the source."""
    out: dict[str, set[str]] = {}
    for path in sorted(TESTS.glob("test_*.py")):
        names = set(re.findall(r"wf\.shared\(tmp_path_factory, \"(\w+)\"", path.read_text(encoding="utf-8")))
        if names:
            out[f"tests/{path.name}"] = names
    return out


def test_every_reader_of_a_build_is_in_a_unit_of_its_own_that_goes_first():
    readers = _readers()
    assert {"tests/test_own_design.py", "tests/test_faults.py", "tests/test_quickstart.py"} <= set(readers)
    assert set(readers) == set(conftest.BUILDS)
    assert set(conftest.BUILDS.values()) == set(conftest.FIRST)
    # the readers of one build share one unit (test_results_tree also reads the pipeline's, made first)
    by_build: dict[str, set[str]] = {}
    for module, names in readers.items():
        for name in names:
            by_build.setdefault(name, set()).add(conftest.unit(f"{module}::test_x"))
    assert by_build["results_build"] == {"results_build"} and by_build["own_designs"] == {"own_designs"}
    assert by_build["reference"] == by_build["premerge"] == {"faults"}
    assert conftest.FIRST.index("pipeline") < conftest.FIRST.index("results_build")


def test_a_module_that_reads_no_build_is_a_unit_of_its_own():
    assert conftest.unit("tests/test_model.py::test_x[1]") == "tests/test_model.py"
    assert conftest.unit("tests/test_own_design.py::test_x") == "own_designs"
