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


#: Handed out first: the longest file late in the alphabet (27 s of Gaussian-process fits, no compiled kernel).  In
#: alphabetical order the two processes of ``--dist loadfile`` end about 20 s apart, one running it while the other
#: has nothing left; first, it runs while the other process compiles the simulator.  (All the longest files first
#: was slower on a cold numba cache: both processes then compiled the same kernels at once.)
FIRST = ("test_surrogate.py",)


def pytest_collection_modifyitems(config, items):
    """:data:`FIRST` first, then every other file in its order; each file's tests in their own order."""
    items.sort(key=lambda item: item.path.name not in FIRST)


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
