import numpy as np
import pytest

#: the independent references are programs and modules the tests import, not tests: their doctests are not collected
#: (some of them compute their tables when run as scripts)
collect_ignore_glob = ["reference/*.py"]


@pytest.fixture
def rng():
    """A fixed random generator: every test run sees the same numbers."""
    return np.random.default_rng(20261126)
