"""Start-up of the command and the packages: public names exported lazily, the simulator's compilation started
before the heavy imports (README "Speed of the demo")."""
import os
import subprocess
import time
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


def test_public_name_kept_when_its_module_is_imported():
    """``riskrf.rate_model`` is the function, as with an eager ``__init__``, even after something imports the
    submodule of the same name (a plain lazy package would then hold the module)."""
    code = ("import riskrf.risk.closure, riskrf.frequency.rates as m; from riskrf import rate_model; import riskrf; "
            "print(callable(rate_model), riskrf.rate_model is rate_model, 'lazy_exports' in dir(riskrf))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["True", "True", "False"]


def test_submodules_as_attributes():
    assert riskrf.risk.mitigation.MitigationStudy.__name__ == "MitigationStudy"
    assert simulation.kernel.simulate is not None
    from riskrf import fit_gutenberg_richter
    from riskrf.frequency.power_law import fit_gutenberg_richter as same
    assert fit_gutenberg_richter is same


class _FakePrecompile:
    made = []

    def __init__(self, *, check_cache=True):
        self.check_cache = check_cache
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
    assert early.check_cache is False
    monkeypatch.setattr(pc, "_cache_exists", lambda: False)
    assert pc.precompile() is early
    later = pc.precompile()                                      # taken over once; then a new one
    assert later is not early and len(fake_precompile) == 2


def test_no_early_child_without_jit(fake_precompile, monkeypatch):
    monkeypatch.setenv("NUMBA_DISABLE_JIT", "1")
    pc.start_early()
    assert fake_precompile == []


@pytest.mark.parametrize("argv, started", [
    (["demo"], True), (["--debug", "assess", "sim.toml"], True), (["assess", "--out", "x", "sim.toml"], True),
    (["assess", "velocities.toml"], False), (["assess", "missing.toml"], False), (["assess"], False),
    (["demo", "--help"], False), (["demo", "--he"], False), (["assess", "sim.toml", "-h"], False),
    (["fit", "x.csv"], False), ([], False), (["simulate", "s.toml"], False)])
def test_command_starts_compiling_only_for_assessments_that_simulate(argv, started, monkeypatch, tmp_path):
    (tmp_path / "sim.toml").write_text('[hazard]\nscenario = "s.toml"\n')
    (tmp_path / "velocities.toml").write_text('[hazard]\nvelocities = "v.csv"\n')
    monkeypatch.chdir(tmp_path)
    calls = []
    monkeypatch.setattr(pc, "start_early", lambda: calls.append(1))
    cli._compile_early(argv)
    assert bool(calls) is started


def test_early_child_stopped_when_not_taken_over(monkeypatch):
    """A child no run took over (the command failed early, the site has no scenario) is stopped."""
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    early = pc.Precompile.__new__(pc.Precompile)
    early._proc = child
    monkeypatch.setattr(pc, "_early", early)
    pc.discard_early()
    assert child.poll() is not None and pc._early is None


def test_warm_cache_needs_no_child(fake_precompile, monkeypatch):
    """With the kernel's cache there (numba's own lookup), an early child is stopped and nothing is started."""
    stopped = []
    monkeypatch.setattr(pc, "_cache_exists", lambda: True)
    monkeypatch.setattr(pc, "discard_early", lambda: stopped.append(1))
    made = pc.precompile()
    assert stopped == [1] and made.check_cache is True      # Precompile(check_cache=True) finds the cache


def test_compile_call_has_the_runs_argument_types(monkeypatch):
    """The compiling child calls the kernel on no blocks (``compile_kernel``, without pandas or scipy.stats); its
    arguments must have exactly the numba types of a real run's, or the run would compile a second version."""
    import inspect

    import numba

    import simulation.kernel as kernel
    signature = inspect.signature(getattr(kernel.simulate, "py_func", kernel.simulate))
    empty = pc.empty_kernel_arguments()
    calls = []
    monkeypatch.setattr(kernel, "simulate", lambda *a, **kw: calls.append(signature.bind(*a, **kw).arguments))
    scenario = simulation.load_scenario(pc.Path(simulation.__file__).parent / "scenarios" / "road_cut_barrier.toml")
    try:
        simulation.run(scenario, n=3, seed=0, record_paths=3)
    except Exception:          # the stand-in kernel did nothing, so no result can be built: the calls are what counts
        pass
    assert calls and list(empty) == list(signature.parameters)
    for real in calls:
        assert list(real) == list(empty)
        for name in real:
            assert numba.typeof(real[name]) == numba.typeof(empty[name]), name


def test_compile_kernel_runs_on_no_blocks():
    """``compile_kernel`` in a fresh interpreter: loads (here, from the suite's warm cache) or compiles the kernel
    and simulates nothing, without importing pandas or scipy.stats."""
    code = ("import sys, simulation.precompile as p; p.compile_kernel(); "
            "print(sorted({'pandas', 'scipy.stats'} & set(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=300)
    assert out.stdout.strip() == "[]"


def test_the_flat_module_paths_of_before_the_stage_layout_are_gone():
    """No alias layer: ``riskrf.assess`` (now ``riskrf.app.assess``) does not import, and the public function
    ``riskrf.rate_model`` is the function, not a module."""
    code = ("import riskrf\n"
            "try:\n    import riskrf.assess\nexcept ModuleNotFoundError as e:\n    print(e.name)\n"
            "print(callable(riskrf.rate_model), riskrf.rate_model.__module__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["riskrf.assess", "True", "riskrf.frequency.rates.fit"]


def test_every_input_error_is_a_riskrf_error():
    """One base for riskrf's input errors; each keeps the built-in base it had (ValueError)."""
    from riskrf.app.corridor import CorridorError
    from riskrf.app.site import SiteError
    from riskrf.hazard.mass_coupling import NoArrivalsError
    from riskrf.risk.decision_tree import TreeError
    from riskrf.risk.measures import MeasureError
    from riskrf.risk.mitigation_inputs import MitigationError
    from riskrf.risk.rhrs import RHRSError
    assert "RiskrfError" in riskrf.__all__
    for cls in (CorridorError, SiteError, NoArrivalsError, TreeError, MeasureError, MitigationError, RHRSError):
        assert issubclass(cls, riskrf.RiskrfError) and issubclass(cls, ValueError), cls
    with pytest.raises(riskrf.RiskrfError, match="node type 'nonsense'"):
        riskrf.DecisionTree.from_dict({"name": "tree", "type": "nonsense"})



def test_no_precompile_switch_starts_no_child(fake_precompile, monkeypatch):
    """``RISKRF_NO_PRECOMPILE=1``: no early child (tests/benchmarks/bench_startup.py measures with it)."""
    monkeypatch.delenv("NUMBA_DISABLE_JIT", raising=False)
    monkeypatch.setenv("RISKRF_NO_PRECOMPILE", "1")
    pc.start_early()
    assert fake_precompile == [] and pc.disabled()


def test_no_precompile_switch_keeps_the_compilation_in_the_run(monkeypatch):
    """``RISKRF_NO_PRECOMPILE=1``: the real :class:`Precompile` starts no child even when asked to."""
    monkeypatch.setenv("RISKRF_NO_PRECOMPILE", "1")
    monkeypatch.setattr(pc, "_cache_exists", lambda: False)
    assert pc.Precompile(check_cache=False)._proc is None


def test_no_fork_switch_keeps_the_work_in_this_process(monkeypatch):
    """``RISKRF_NO_FORK=1``: :class:`~riskrf.cli.runner.InBackground` runs its work here, same value."""
    from riskrf.cli.runner import InBackground
    monkeypatch.setenv("RISKRF_NO_FORK", "1")
    work = InBackground(lambda: 6 * 7)
    assert work.proc is None and work.result() == 42


class _Compiling:
    """A compilation that runs until waited for."""

    def __init__(self, order):
        self.running, self.order = True, order

    def wait(self):
        self.order.append("compiled")
        self.running = False


def test_two_cores_does_this_cores_work_while_the_simulator_compiles(monkeypatch):
    """:class:`~riskrf.cli.runner.TwoCores` (``riskrf assess``): while the simulator compiles on the other core
    nothing is forked and the work handed to it is done here before the wait; after it, work is forked again."""
    from riskrf.cli.runner import TwoCores
    order, lines, timings = [], [], {}
    monkeypatch.setattr(pc, "precompile", lambda: _Compiling(order))
    runner = TwoCores()
    runner.start(True, lines.append)
    assert not runner.fork and "compiled once on the other core" in lines[0]
    part = runner.beside(lambda: order.append("fits' figures") or 1)
    assert part.proc is None and order == []
    runner.before_simulation(timings)
    assert order == ["fits' figures", "compiled"] and "compilation" in timings and part.result() == 1
    assert runner.fork


def test_two_cores_starts_nothing_for_a_run_without_simulation(monkeypatch):
    """No scenario (velocities read from a file): no compilation, nothing waited for, no timing added."""
    from riskrf.cli.runner import TwoCores
    monkeypatch.setattr(pc, "precompile", lambda: pytest.fail("compiled without a scenario"))
    runner, timings = TwoCores(), {}
    runner.start(False, lambda line: pytest.fail(line))
    runner.before_simulation(timings)
    assert runner.fork and timings == {}


def test_in_line_runner_defers_the_work_and_drops_its_warnings():
    """The app's default runner (:class:`~riskrf.app.scheduling.InLine`) forks nothing: the work runs once, here,
    at its result, its warnings dropped as a forked child's would be."""
    import warnings

    from riskrf.app.scheduling import InLine
    calls = []

    def work():
        calls.append(1)
        warnings.warn("not passed on")
        return 7
    part = InLine().beside(work)
    assert calls == []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert part.result() == 7 and part.result() == 7
    assert calls == [1]


def test_gate_holds_forked_work_until_this_process_opens_it(tmp_path, monkeypatch):
    """:class:`~riskrf.cli.runner.Gate`: work forked beside this process that calls ``wait()`` goes on only after
    ``open()`` (here: it reads a file written just before); in this process ``wait()`` never blocks."""
    from riskrf.cli.runner import Gate, InBackground
    monkeypatch.delenv("RISKRF_NO_FORK", raising=False)
    gate, ready = Gate(), tmp_path / "ready.txt"

    def work():
        gate.wait()
        return ready.read_text()
    part = InBackground(work)
    if part.proc is None:
        pytest.skip("no fork here")
    ready.write_text("written before the gate opened")
    gate.open()
    assert part.result() == "written before the gate opened"
    assert gate.wait() and gate.wait(tmp_path / "absent")      # here: returns at once, the gate open
    gate.close()


def test_gate_wait_for_a_file_returns_when_it_appears(tmp_path, monkeypatch):
    """``wait(path)`` in forked work returns False once the file exists although the gate is still shut, and
    True once the gate opens; a later ``wait`` returns True at once."""
    from riskrf.cli.runner import Gate, InBackground
    monkeypatch.delenv("RISKRF_NO_FORK", raising=False)
    gate, figure, second = Gate(), tmp_path / "figure.png", tmp_path / "second.png"

    def work():
        appeared = gate.wait(figure)
        (tmp_path / "seen.txt").write_text("seen")
        return appeared, gate.wait(second), gate.wait(second), second.exists()
    part = InBackground(work)
    if part.proc is None:
        pytest.skip("no fork here")
    figure.write_bytes(b"png")
    for _ in range(3000):                          # the child saw the file while the gate was still shut
        if (tmp_path / "seen.txt").exists():
            break
        time.sleep(0.01)
    gate.open()
    assert part.result() == (False, True, True, False)
    gate.close()


_ORPHANED_GATE = """
import os, select, sys
from riskrf.cli.runner import Gate
r, w = os.pipe()
if os.fork() == 0:                      # the parent of the gate, which ends without opening it
    os.close(r)
    gate = Gate()
    if os.fork() == 0:                  # its child, waiting on the gate
        gate.wait()
        os.write(w, b"1")
        os._exit(0)
    os._exit(0)
os.close(w)
ready, _, _ = select.select([r], [], [], 30.0)
print(os.read(r, 1).decode() if ready else "still waiting")
"""


def test_gate_of_a_child_ends_with_its_parent():
    """A child waiting on a gate its parent never opens is not left waiting for ever: the read returns when the
    parent ends (the child's own copy of the write end was closed by ``wait()``)."""
    done = subprocess.run([sys.executable, "-c", _ORPHANED_GATE], capture_output=True, text=True, timeout=60)
    assert done.stdout.strip() == "1", done.stderr


def test_in_line_gate_never_waits():
    """The default runner's gate (:class:`~riskrf.app.scheduling.OpenGate`) neither waits nor signals."""
    from riskrf.app.scheduling import InLine
    gate = InLine().gate()
    gate.wait()
    gate.open()
    gate.wait()


def test_every_kernel_module_imports_with_the_jit_disabled():
    """Coverage runs the kernels as plain Python; a module that needs a compiled object at import fails there."""
    code = "import simulation.kernel, simulation.kernel3d, simulation.engine, simulation.engine3d"
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
