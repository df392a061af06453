"""Shared test set-up: no test may change mpmath's global working precision."""

import mpmath
import pytest


@pytest.fixture(autouse=True)
def _mpmath_precision_unchanged():
    """Tests use ``mpmath.workdps`` (a context manager or decorator); a test
    that sets ``mpmath.mp.dps`` and leaves it changed fails here."""
    dps = mpmath.mp.dps
    yield
    assert mpmath.mp.dps == dps, f"the test left mpmath.mp.dps = {mpmath.mp.dps} (was {dps}): use mpmath.workdps"
