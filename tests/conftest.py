"""Hypothesis profiles. The default ``ci`` profile is derandomised: every run draws the same examples,
so a result of ``.ci/run`` does not depend on luck. ``HYPOTHESIS_PROFILE=explore`` draws fresh
random examples, ten times as many, to hunt for new failures; add what it finds as ``@example``."""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", derandomize=False, deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
