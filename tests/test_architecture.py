"""The layout of :mod:`riskrf` by stage, checked from the source: imports go one way only, modules stay small.

Every ``import`` and ``from ... import`` of every module under ``riskrf/`` is read with :mod:`ast` (imports made
inside functions included), resolved to the riskrf module it names, and checked against the stage order
``core < io < frequency < hazard < risk < report < app < cli``: a module imports only its own stage and the
stages before it, the science (core .. risk) never imports ``riskrf.report`` or ``riskrf.app``, and the
module graph has no cycle.  No module of ``riskrf/`` or ``simulation/`` is longer than :data:`MAX_MODULE_LINES`
but those listed in :data:`STILL_TO_SPLIT` (none now).
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "riskrf"
STAGES = ("core", "io", "frequency", "hazard", "risk", "report", "app", "cli")
SCIENCE = ("core", "io", "frequency", "hazard", "risk")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules(root: Path = ROOT) -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(root.rglob("*.py"))}


def _imports(name: str, path: Path, known: set[str], top: str = "riskrf") -> set[str]:
    """The modules of package ``top`` (other than the top package) that the module ``name`` imports anywhere."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            # ``from riskrf.risk import rhrs`` names the module riskrf.risk.rhrs
            targets = [source] + [f"{source}.{alias.name}" for alias in node.names]
        else:
            continue
        for target in targets:
            while target and target not in known:       # ``import a.b.c`` of a name inside a module
                target = target.rpartition(".")[0]
            if target.startswith(top + ".") and target != name:
                found.add(target)
    return found


def _stage(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in STAGES else None


@pytest.fixture(scope="module")
def graph():
    modules = _modules()
    return {name: _imports(name, path, set(modules)) for name, path in modules.items()}


def test_every_module_sits_in_a_stage(graph):
    loose = sorted(m for m in graph if m != "riskrf" and _stage(m) is None)
    assert loose == [], f"modules outside the stage packages: {loose}"


def test_science_never_imports_report_or_app(graph):
    bad = sorted((m, t) for m, targets in graph.items() if _stage(m) in SCIENCE
                 for t in targets if _stage(t) in ("report", "app", "cli"))
    assert bad == [], "science modules importing report/app/cli:\n" + "\n".join(f"{m} -> {t}" for m, t in bad)


def test_stages_import_only_earlier_stages(graph):
    bad = sorted((m, t) for m, targets in graph.items() for t in targets
                 if _stage(m) and _stage(t) and STAGES.index(_stage(t)) > STAGES.index(_stage(m)))
    assert bad == [], "imports against the stage order:\n" + "\n".join(f"{m} -> {t}" for m, t in bad)


@pytest.fixture(scope="module")
def simulation_graph():
    modules = _modules(ROOT.parent / "simulation")
    return {name: _imports(name, path, set(modules), "simulation") for name, path in modules.items()}


@pytest.mark.parametrize("which", ["riskrf", "simulation"])
def test_no_import_cycle(which, graph, simulation_graph):
    """No circle of imports, counting the imports inside functions too (simulation/ once had an 8-module
    circle through calibration, pooled, materials and material_uncertainty)."""
    graph = graph if which == "riskrf" else simulation_graph
    order, state = [], {}

    def visit(node, path):
        state[node] = "open"
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                cycle = path[path.index(nxt):] + [nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = "done"
        order.append(node)

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    assert len(order) == len(graph)


def test_the_checker_sees_imports():
    """The parser finds relative, absolute and function-level imports (so the tests above can fail)."""
    modules = _modules()
    known = set(modules)
    cli = _imports("riskrf.cli.decisions", modules["riskrf.cli.decisions"], known)
    assert {"riskrf.app.assess.run", "riskrf.io.outputs", "riskrf.cli.steps"} <= cli   # ``from ..app.assess.run import``
    parser = _imports("riskrf.cli.parser", modules["riskrf.cli.parser"], known)
    assert "riskrf.core.units" in parser
    model = _imports("riskrf.app.corridor.model", modules["riskrf.app.corridor.model"], known)
    assert "riskrf.risk.rhrs" in model                          # ``from ...risk import rhrs``
    result = _imports("riskrf.app.corridor.result", modules["riskrf.app.corridor.result"], known)
    assert "riskrf.report.corridor_report" in result            # imported inside a function
    package = _imports("riskrf.app.corridor", modules["riskrf.app.corridor"], known)
    assert {"riskrf.app.corridor.run", "riskrf.app.cluster"} <= package     # a package's ``from .run import``


def _installed_modules():
    """Every module of both packages (scripts live in ``validation/``, which is not installed)."""
    for package in ("riskrf", "simulation"):
        root = ROOT.parent / package
        for path in sorted(root.rglob("*.py")):
            parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            yield ".".join(parts), path


def test_no_script_ships_in_the_packages():
    """The validation studies and derivation scripts live in ``validation/``, outside the installed packages:
    every ``.py`` file under ``riskrf/`` and ``simulation/`` is a module of a package (each directory down to it
    has an ``__init__.py``), and the package data in ``pyproject.toml`` names no ``.py`` file."""
    import tomllib
    loose = []
    for package in ("riskrf", "simulation"):
        for path in sorted((ROOT.parent / package).rglob("*.py")):
            folder = path.parent
            while folder != ROOT.parent:
                if not (folder / "__init__.py").exists():
                    loose.append(str(path.relative_to(ROOT.parent)))
                    break
                folder = folder.parent
    assert loose == [], f"scripts inside the installed packages (move them to validation/): {loose}"
    with open(ROOT.parent / "pyproject.toml", "rb") as f:
        setuptools = tomllib.load(f)["tool"]["setuptools"]
    data = [g for globs in setuptools.get("package-data", {}).values() for g in globs if g.endswith(".py")]
    assert data == [], f"package data that installs scripts: {data}"
    assert not any(p.startswith("validation") for p in setuptools["packages"]["find"]["include"])


def test_every_error_of_both_packages_is_a_riskrf_error():
    import importlib
    import inspect
    from riskrf import RiskrfError
    bad = []
    for name, _ in _installed_modules():
        module = importlib.import_module(name)
        for cls_name, cls in inspect.getmembers(module, inspect.isclass):
            if (cls.__module__ == name and issubclass(cls, Exception) and not issubclass(cls, Warning)
                    and not issubclass(cls, RiskrfError)):
                bad.append(f"{name}.{cls_name}")
    assert bad == [], f"errors that ``except riskrf.RiskrfError`` would miss: {bad}"
    import simulation
    assert issubclass(simulation.ScenarioError, RiskrfError) and issubclass(simulation.ScenarioError, ValueError)


def test_no_backend_choice_outside_the_command_line():
    """Only the command line chooses matplotlib's backend (MPLBACKEND); a library call never does, so a notebook's
    inline figures keep working after it."""
    bad = []
    for name, path in _installed_modules():
        if name == "riskrf.cli" or name.startswith("riskrf.cli."):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr in ("use", "switch_backend")
                    and isinstance(node.func.value, ast.Name) and node.func.value.id in ("matplotlib", "plt")):
                bad.append(f"{name}:{node.lineno}")
    assert bad == [], f"backend chosen outside riskrf.cli: {bad}"


#: Longest a module of ``riskrf/`` or ``simulation/`` may be [lines]: a newcomer reads one in a sitting.
MAX_MODULE_LINES = 900
#: Modules still longer than that, each to be split where its code has seams; the list only shrinks (a module
#: that is split or falls below the limit must leave it).
STILL_TO_SPLIT: set[str] = set()


def _module_lengths() -> dict[str, int]:
    return {str(p.relative_to(ROOT.parent)): len(p.read_text(encoding="utf-8").splitlines())
            for package in ("riskrf", "simulation") for p in sorted((ROOT.parent / package).rglob("*.py"))}


def test_no_module_is_a_big_room():
    lengths = _module_lengths()
    big = sorted(f"{m}: {n} lines" for m, n in lengths.items() if n > MAX_MODULE_LINES and m not in STILL_TO_SPLIT)
    assert big == [], (f"modules over {MAX_MODULE_LINES} lines (split them where the code has seams, e.g. "
                       "riskrf/app/corridor/ and riskrf/frequency/power_law/):\n" + "\n".join(big))
    done = sorted(m for m in STILL_TO_SPLIT if lengths.get(m, 0) <= MAX_MODULE_LINES)
    assert done == [], f"split or below {MAX_MODULE_LINES} lines now: remove from STILL_TO_SPLIT: {done}"


def test_every_plot_method_draws_with_its_own_stage_figures():
    """A science result's ``plot()`` calls a drawing function of its own stage's ``figures`` module (imported inside
    the method, so the stage loads without matplotlib) or another result's ``plot()``; never a string registry,
    riskrf.report or matplotlib itself."""
    found = 0
    for name, path in _modules().items():
        stage = _stage(name)
        if stage not in SCIENCE or name.endswith(".figures"):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if not (isinstance(node, ast.FunctionDef) and node.name == "plot"):
                continue
            found += 1
            package = name.rpartition(".")[0]
            sources = []
            for sub in ast.walk(node):
                if isinstance(sub, ast.ImportFrom):
                    base = package.split(".")[: len(package.split(".")) - (sub.level - 1)] if sub.level else []
                    sources.append(".".join(base + [sub.module or ""]) if sub.level else sub.module)
            delegates = not sources and not any(isinstance(sub, ast.Import) for sub in ast.walk(node))
            assert f"riskrf.{stage}.figures" in sources or delegates, f"{name}.plot imports from {sources}"
    assert found >= 10
    import riskrf.core.figures as core_figures
    assert not hasattr(core_figures, "FIGURES") and not hasattr(core_figures, "draw")
