import numpy as np
import pytest


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
