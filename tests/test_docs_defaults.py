"""docs/defaults.md is what docs/defaults.py writes from the settings dataclasses: a default changed in the code and
not on the page fails here (regenerate: ``python docs/defaults.py > docs/defaults.md``)."""

import dataclasses
import importlib.util
from pathlib import Path

from geardyn.runs.continuation import corrector

ROOT = Path(__file__).resolve().parents[1]


def _script():
    spec = importlib.util.spec_from_file_location("docs_defaults", ROOT / "docs" / "defaults.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_defaults_page_is_current():
    assert (ROOT / "docs" / "defaults.md").read_text() == _script().render()


def test_the_page_would_show_a_changed_default():
    """The page is made from the values, not retyped: a default changed in the code changes the page."""
    script = _script()
    before = script.render()
    changed = dataclasses.replace(corrector.CURVES, max_points=401)
    script.SECTIONS = tuple(
        (t, [(c, changed if o is corrector.CURVES else o) for c, o in cols]) for t, cols in script.SECTIONS
    )
    after = script.render()
    assert before != after and "| `max_points` | 5000 | 401 |" in after and "| `max_points` | 5000 | 400 |" in before
