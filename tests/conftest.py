import numpy as np
import pytest


@pytest.fixture
def rng():
    """A fixed random generator: every test run sees the same numbers."""
    return np.random.default_rng(20261126)
