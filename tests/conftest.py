import os

# One BLAS thread per test process, set before numpy is first imported: the suite runs on two processes
# (pytest-xdist), and OpenBLAS's own threads on a 2-core machine then compete with the other process (the
# Gaussian-process tests took 57 s with them and 31 s without on a loaded machine).  Timing is not asserted.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import hashlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"
INVENTORIES = ROOT / "inventories"
DEMO = ROOT / "riskrf" / "data"
SCENARIO = ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml"
LAUTER = DEMO / "lauterbrunnen_tls_2018.csv"


def digest(directory: Path) -> dict:
    """Content digest of every file under ``directory`` (inputs must be byte-identical after any command)."""
    return {p.relative_to(directory): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(directory.rglob("*")) if p.is_file()}


def pytest_configure(config):
    config.addinivalue_line("filterwarnings", "ignore::riskrf.core.validation.RiskrfWarning")


@pytest.fixture
def data_dir():
    return DATA


@pytest.fixture
def no_work(monkeypatch):
    """Every expensive stage fails loudly: a refusal must come before any of them runs (the bad-input tests)."""
    import riskrf.app.assess.decision
    import riskrf.app.assess.hazard
    import riskrf.app.assess.run
    import riskrf.frequency.study
    import simulation

    def boom(*a, **k):
        raise AssertionError("work started before the input was refused")
    monkeypatch.setattr(riskrf.frequency.study, "analyse_inventory", boom)
    monkeypatch.setattr(riskrf.app.assess.hazard, "energy_hazard_from_inputs", boom)
    monkeypatch.setattr(riskrf.app.assess.decision, "energy_hazard_from_inputs", boom)
    monkeypatch.setattr(riskrf.app.assess.run, "run_assessment", boom)
    monkeypatch.setattr(simulation, "run", boom)
    monkeypatch.setattr(simulation, "calibrate", boom)

from hypothesis import settings  # noqa: E402

# Property tests draw new examples on every run (a failure prints the seed and the example
# to reproduce it: ``pytest --hypothesis-seed=N``); no deadline, since the first call of a
# compiled kernel includes its compilation.
settings.register_profile("riskrf", deadline=None, print_blob=True)
settings.load_profile("riskrf")
