from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"
INVENTORIES = ROOT / "inventories"


@pytest.fixture
def data_dir():
    return DATA

from hypothesis import settings  # noqa: E402

# Property tests draw new examples on every run (a failure prints the seed and the example
# to reproduce it: ``pytest --hypothesis-seed=N``); no deadline, since the first call of a
# compiled kernel includes its compilation.
settings.register_profile("riskrf", deadline=None, print_blob=True)
settings.load_profile("riskrf")
