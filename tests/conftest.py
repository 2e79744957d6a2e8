import numpy as np
import pytest


@pytest.fixture
def rng():
    """A seeded random generator, so every run draws the same numbers."""
    return np.random.default_rng(20261121)
