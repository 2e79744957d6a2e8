import os

import numpy as np
import pytest
from hypothesis import settings

# Property tests draw the same examples on every run (derandomised, no example database), so the suite never
# fails on an example a run happened to try; ``HYPOTHESIS_PROFILE=explore`` draws new ones, to look for bugs.
# No deadline on an example: how long one takes depends on the machine's load (the suite's workers share its
# cores), and a test that checks time says so itself.
settings.register_profile("repeatable", derandomize=True, database=None, deadline=None)
settings.register_profile("explore", derandomize=False, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


@pytest.fixture
def rng():
    """A seeded random generator, so every run draws the same numbers."""
    return np.random.default_rng(20261121)


@pytest.fixture(scope="session")
def demo(tmp_path_factory):
    """``drumstroke demo OUT`` run once for the tests that read what it wrote: (the finished run, OUT)."""
    from _cli import run

    out = tmp_path_factory.mktemp("demo") / "out"
    return run("demo", out), out
