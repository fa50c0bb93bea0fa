"""Shared, module-cached experiment runs (each is deterministic: every signal and noise is seeded)."""

import pytest

from trms.experiments import identification_ch3 as c3
from trms.experiments.plants import make_plant


@pytest.fixture(scope="session")
def ch3_results():
    r1 = {w: c3.identify_1dof(make_plant(w, "1dof"), make_plant(w, "1dof", 0.1)) for w in ("linear", "twin")}
    r2 = {w: c3.identify_2dof(make_plant(w, "2dof")) for w in ("linear", "twin")}
    return r1, r2
