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


def pytest_configure(config):
    """numba's disk cache of the main job's and the onset detector's kernels written once, before any test (before the
    workers start: an xdist worker has ``workerinput``). A test's console-script subprocess then loads them instead of
    compiling them (a cold ``drumstroke compare`` spends 36 s of CPU compiling, a warm one 1.2 s; the hostile corpus
    allows 10 s), and the two workers never compile the same kernels at once. In one process (``-n 0``) it is the
    compilation the first tests would do anyway."""
    if hasattr(config, "workerinput") or config.option.collectonly:
        return
    import tempfile

    import _recorded_drums
    from drumstroke.analysis import find_onsets
    from drumstroke.demo import run_demo

    with tempfile.TemporaryDirectory() as folder:
        run_demo(os.path.join(folder, "out"))
    for recording in _recorded_drums.recordings(fonts=("FluidR3",), keys=(38,), sets=("roll", "drop"),
                                                conditions=("reverb", "noise60")):
        find_onsets(recording.signal, _recorded_drums.RATE)


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
