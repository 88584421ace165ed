"""MkDocs hooks of the riskrf documentation (named in ``mkdocs.yml``; not part of the site).

At build time they

- run every example script ``docs/examples/NAME.py`` once (``python NAME.py OUT_DIR`` from the
  repository root, as ``tests/test_examples.py`` does) and put the figures it writes into the site
  as ``examples/out/NAME/FIGURE.png``; the marker ``<!-- example-output NAME -->`` in a page is
  replaced by the script's printed output and its figures.  A failing example fails the build.
- replace ``<!-- riskrf-help -->`` by the ``--help`` text of the ``riskrf`` command and of every
  sub-command, taken from the command's own argument parser, so the reference cannot drift;
- complete the API reference: ``<!-- api-other PACKAGE -->`` becomes an entry for every name of
  ``PACKAGE.__all__`` the page does not document yet, so a newly exported name is never missing;
- add the figures the repository already holds (``inventories/*/figures``, the scenario and
  corridor figures) to the site as ``repo/PATH``, so pages show them without copies.

Examples run once per process: ``mkdocs serve`` re-uses their output on later rebuilds.
"""
from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "docs" / "examples"
#: Figures of the repository shown in the pages, as glob patterns relative to the repository root.
REPO_FIGURES = ("inventories/*/figures/*.png", "simulation/scenarios/figures/*.png",
                "simulation/scenarios/*/figures/*.png", "corridors/*/*.png")
#: Seconds an example may take at build time before the build fails (they take about 10 s each).
EXAMPLE_TIMEOUT_S = 600

#: ``RISKRF_DOCS_SKIP_EXAMPLES=1 mkdocs serve`` previews the pages without running the examples (their pages
#: then say so); a strict build runs them.
SKIP_EXAMPLES = os.environ.get("RISKRF_DOCS_SKIP_EXAMPLES", "") not in ("", "0")

_examples: dict[str, tuple[str, list[Path]]] = {}
_help: list[str] = []
_out = Path(tempfile.mkdtemp(prefix="riskrf-docs-examples-"))

_HELP_SCRIPT = """
import argparse
from riskrf.cli import build_parser
parser = build_parser()
print(parser.format_help())
sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
for name, p in sub.choices.items():
    print("\\x00" + name)
    print(p.format_help())
"""


def _env() -> dict:
    env = dict(os.environ, COLUMNS="100", MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


def run_example(name: str) -> tuple[str, list[Path]]:
    """Run ``docs/examples/NAME.py`` into its own output folder; its printed output and figures."""
    if SKIP_EXAMPLES:
        return "(not run: RISKRF_DOCS_SKIP_EXAMPLES is set)", []
    if name not in _examples:
        out = _out / name
        proc = subprocess.run([sys.executable, str(EXAMPLES / f"{name}.py"), str(out)], cwd=ROOT, env=_env(),
                              capture_output=True, text=True, timeout=EXAMPLE_TIMEOUT_S)
        if proc.returncode != 0:
            raise RuntimeError(f"docs/examples/{name}.py failed (exit {proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
        _examples[name] = (proc.stdout, sorted(out.glob("*.png")))
    return _examples[name]


def command_help() -> list[tuple[str, str]]:
    """``riskrf --help`` and ``riskrf COMMAND --help`` for every sub-command, in the parser's order."""
    if not _help:
        proc = subprocess.run([sys.executable, "-c", _HELP_SCRIPT], cwd=ROOT, env=_env(), capture_output=True,
                              text=True, timeout=120, check=True)
        _help.extend(proc.stdout.split("\x00"))
    first, *rest = _help
    return [("riskrf", first)] + [(part.split("\n", 1)[0], part.split("\n", 1)[1]) for part in rest]


def on_config(config):
    if str(ROOT) not in sys.path:           # the pages document this checkout's riskrf and simulation
        sys.path.insert(0, str(ROOT))
    return config


def on_files(files, config):
    for pattern in REPO_FIGURES:
        for path in sorted(ROOT.glob(pattern)):
            files.append(File.generated(config, f"repo/{path.relative_to(ROOT).as_posix()}", abs_src_path=str(path)))
    for script in sorted(EXAMPLES.glob("*.py")):
        _, figures = run_example(script.stem)
        for fig in figures:
            files.append(File.generated(config, f"examples/out/{script.stem}/{fig.name}", abs_src_path=str(fig)))
    return files


def _fence(text: str, indent: str = "") -> str:
    lines = [line.rsplit("\r", 1)[-1] for line in text.rstrip().split("\n")]   # a progress bar's last state
    body = "\n".join(indent + line if line else line for line in lines)
    return f"{indent}```text\n{body}\n{indent}```\n"


def _example_output(match: re.Match) -> str:
    name = match.group(1)
    stdout, figures = run_example(name)
    parts = ['??? example "What it prints"\n\n' + _fence(stdout, "    ")]
    parts += [f"![{fig.stem.replace('_', ' ')}, written by {name}.py](out/{name}/{fig.name})\n" for fig in figures]
    return "\n".join(parts)


def _help_text(match: re.Match) -> str:
    sections = []
    for name, text in command_help():
        title = "riskrf" if name == "riskrf" else f"riskrf {name}"
        sections.append(f"### `{title}`\n\n{_fence(text)}")
    return "\n".join(sections)


def _api_other(match: re.Match, markdown: str) -> str:
    """Entries for the public names of a package that the page does not document yet (names added since)."""
    package = match.group(1)
    names = importlib.import_module(package).__all__
    missing = [n for n in names if not re.search(rf"^::: {package}\.{n}$", markdown, re.M)]
    if not missing:
        return ""
    entries = "".join(f"::: {package}.{n}\n    options:\n      heading_level: 4\n\n" for n in missing)
    return f"### Other public names\n\n{entries}"


def _module_path(match: re.Match) -> str:
    """``::: riskrf.NAME`` -> ``::: MODULE.NAME``, the module that holds the public name today.

    The pages name public objects by their stable public name; the modules behind them may move.  The package's
    export table (``_EXPORTS``, the same one its lazy ``__getattr__`` uses) says where each name lives.
    """
    package, name = match.group(1), match.group(2)
    module = importlib.import_module(package)
    where = getattr(module, "_EXPORTS", {}).get(name)
    if where is None:
        where = getattr(getattr(module, name), "__module__", package).removeprefix(f"{package}.")
    return f"::: {package}.{where}.{name}" if where != package else match.group(0)


def on_page_markdown(markdown, page, config, files):
    markdown = re.sub(r"<!-- api-other (\w+) -->", lambda m: _api_other(m, markdown), markdown)
    markdown = re.sub(r"^::: (riskrf|simulation)\.(\w+)$", _module_path, markdown, flags=re.M)
    markdown = re.sub(r"<!-- example-output (\w+) -->", _example_output, markdown)
    return re.sub(r"<!-- riskrf-help -->", _help_text, markdown)
