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


# ---- the kernels compiled once for both test processes (tests/kernel_warmup.py) ----------------------------------
WARMUP_ENV = "RISKRF_TEST_KERNEL_WARMUP"
_warmup = []


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    """In the pytest-xdist controller, before it starts the test processes: two children compile the two halves of
    the kernels into numba's cache (each specialisation once, not once per test process); the folder where they
    mark themselves done is passed to the test processes in the environment."""
    import subprocess
    import sys
    import tempfile
    config = session.config
    if (hasattr(config, "workerinput") or not getattr(config.option, "numprocesses", None)
            or getattr(config.option, "dist", "no") == "no"
            or os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0") or WARMUP_ENV in os.environ):
        return
    done = Path(tempfile.mkdtemp(prefix="riskrf-kernel-warmup-"))
    os.environ[WARMUP_ENV] = str(done)
    for half in (0, 1):
        try:
            _warmup.append(subprocess.Popen([sys.executable, "-m", "tests.kernel_warmup", str(half),
                                             str(done / f"half{half}.done")], cwd=ROOT,
                                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                            stderr=subprocess.DEVNULL))
            (done / f"half{half}.pid").write_text(str(_warmup[-1].pid))
        except OSError:
            (done / f"half{half}.done").touch()      # no child: the kernels compile on first use


def _warmup_finished(folder: Path, half: int) -> bool:
    """True when the child compiling ``half`` marked itself done or is no longer running (killed before it could)."""
    if (folder / f"half{half}.done").exists():
        return True
    try:
        pid = int((folder / f"half{half}.pid").read_text())
        os.kill(pid, 0)
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        return state in ("Z", "X")                   # ended, not yet reaped by the controller
    except ProcessLookupError:
        return True
    except (OSError, ValueError, IndexError):
        return False                                 # pid file not written yet, or no /proc: the time limit holds


def pytest_collection_finish(session):
    """In a test process, after collecting (which overlaps the compilation): wait until both halves are compiled
    (at most 10 minutes; a child that failed has marked itself done too, and one killed counts as finished)."""
    import time
    folder = os.environ.get(WARMUP_ENV)
    if not folder or not hasattr(session.config, "workerinput"):
        return
    deadline = time.monotonic() + 600.0
    while time.monotonic() < deadline and not all(_warmup_finished(Path(folder), h) for h in (0, 1)):
        time.sleep(0.1)


def pytest_unconfigure(config):
    import shutil
    for child in _warmup:
        if child.poll() is None:
            child.kill()
        child.wait()
    if _warmup and os.environ.get(WARMUP_ENV):
        shutil.rmtree(os.environ.pop(WARMUP_ENV), ignore_errors=True)
    _warmup.clear()


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
