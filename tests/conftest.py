"""Suite-wide fixtures.

Libraries the project builds on (pomdp-py's POUCT, parts of pgmpy and numpy's legacy API) draw from
the process-wide `random` and `numpy.random` generators. Seeding both before every test makes each
test's outcome independent of which tests ran before it in the same process.
"""

import random

import numpy as np
import pytest


@pytest.fixture(autouse=True)
def _seeded_global_generators():
    state, np_state = random.getstate(), np.random.get_state()
    random.seed(0)
    np.random.seed(0)
    yield
    random.setstate(state)
    np.random.set_state(np_state)
