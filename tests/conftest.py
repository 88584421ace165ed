from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"
INVENTORIES = ROOT / "inventories"


@pytest.fixture
def data_dir():
    return DATA

from hypothesis import settings  # noqa: E402

# Property tests draw the same examples on every run: CI results do not depend on chance.
settings.register_profile("riskrf", derandomize=True, deadline=None)
settings.load_profile("riskrf")
