"""Start-up of the command and the packages: public names exported lazily, the simulator's compilation started
before the heavy imports (README "Speed of the demo")."""
import subprocess
import sys

import pytest

import riskrf
import simulation
import simulation.precompile as pc
from riskrf import cli


def test_light_imports_load_no_numerics():
    """``riskrf``, ``riskrf.cli`` and ``simulation.precompile`` import neither numpy, pandas, scipy nor numba:
    the command can start the compiling child before those imports (about 2 s)."""
    code = ("import sys, riskrf, riskrf.cli, simulation, simulation.precompile, simulation.units; "
            "print(sorted({'numpy', 'pandas', 'scipy', 'numba', 'matplotlib'} & set(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("package", [riskrf, simulation])
def test_every_public_name_resolves(package):
    for name in package.__all__:
        value = getattr(package, name)
        assert value is not None
        assert name in dir(package)
    with pytest.raises(AttributeError, match="no attribute 'not_a_name'"):
        package.not_a_name


def test_submodules_as_attributes():
    assert riskrf.mitigation.MitigationStudy.__name__ == "MitigationStudy"
    assert simulation.kernel.simulate is not None
    from riskrf import fit_gutenberg_richter
    from riskrf.power_law import fit_gutenberg_richter as same
    assert fit_gutenberg_richter is same


class _FakePrecompile:
    made = []

    def __init__(self, scenario_path, *, check_cache=True):
        self.scenario_path, self.check_cache = scenario_path, check_cache
        _FakePrecompile.made.append(self)


@pytest.fixture
def fake_precompile(monkeypatch):
    _FakePrecompile.made = []
    monkeypatch.setattr(pc, "Precompile", _FakePrecompile)
    monkeypatch.setattr(pc, "_early", None)
    return _FakePrecompile.made


def test_early_child_is_taken_over_once(fake_precompile, monkeypatch, tmp_path):
    monkeypatch.delenv("NUMBA_DISABLE_JIT", raising=False)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))       # cache not visible by file name: start
    pc.start_early()
    pc.start_early()                                             # a second call starts nothing more
    assert len(fake_precompile) == 1
    early = fake_precompile[0]
    assert early.scenario_path == pc.BUNDLED_SCENARIO and pc.BUNDLED_SCENARIO.exists()
    assert early.check_cache is False
    assert pc.precompile("site_scenario.toml") is early
    later = pc.precompile("site_scenario.toml")                  # taken over once; then a new one
    assert later is not early and later.scenario_path == "site_scenario.toml" and later.check_cache


def test_no_early_child_without_jit(fake_precompile, monkeypatch):
    monkeypatch.setenv("NUMBA_DISABLE_JIT", "1")
    pc.start_early()
    assert fake_precompile == []


@pytest.mark.parametrize("argv, started", [
    (["demo"], True), (["--debug", "assess", "site.toml"], True), (["demo", "--help"], False),
    (["fit", "x.csv"], False), ([], False), (["simulate", "s.toml"], False)])
def test_command_starts_compiling_only_for_assessments(argv, started, monkeypatch):
    calls = []
    monkeypatch.setattr(pc, "start_early", lambda: calls.append(1))
    cli._compile_early(argv)
    assert bool(calls) is started
