import numpy as np
import pytest


@pytest.fixture
def rng():
    """A seeded random generator, so every run draws the same numbers."""
    return np.random.default_rng(20261121)


@pytest.fixture(scope="session")
def demo(tmp_path_factory):
    """``drumstroke demo OUT`` run once (it builds, renders and composes everything): the folder and the result.

    Its tests only read what it wrote.
    """
    from _cli import run

    out = tmp_path_factory.mktemp("demo") / "out"
    return out, run("demo", out)
