"""How many examples the property tests draw: ``max_examples * EXAMPLE_SCALE``; the scale is 10 under
the ``explore`` Hypothesis profile (see ``conftest.py``) and 1 otherwise."""

import os

EXAMPLE_SCALE = 10 if os.environ.get("HYPOTHESIS_PROFILE") == "explore" else 1
