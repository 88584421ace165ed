"""Every ```python block of README.md and docs/**/*.md runs as written.

Each block is a complete program: it is run alone, in a fresh interpreter namespace, in a temporary
working directory that holds links to the repository's data folders (``inventories``, ``simulation``,
``tests``, ``corridors``, ``riskrf``), so that the paths the documentation uses (``inventories/...``)
resolve and whatever a block writes lands in the temporary directory, never in the repository.  Blocks
that are not meant to run are fenced as something else (```text for output, ```toml, ```bash, ```json).
A block that imports a module path that no longer exists (``riskrf.inventory`` for ``riskrf.frequency.inventory``) fails.
A block made only of ``--8<--`` includes shows an example script, which ``tests/test_examples.py`` runs.
"""
from __future__ import annotations

import re
import warnings
from pathlib import Path

import matplotlib
import pytest

from .conftest import ROOT

matplotlib.use("Agg")

DATA_DIRS = ("inventories", "simulation", "tests", "corridors", "riskrf")
FENCE = re.compile(r"^(?P<indent>[ \t]*)```python[^\n]*\n(?P<body>.*?)^(?P=indent)```[ \t]*$", re.M | re.S)


def doc_files() -> list[Path]:
    return [ROOT / "README.md"] + sorted((ROOT / "docs").rglob("*.md"))


def python_blocks(path: Path) -> list[tuple[int, str]]:
    """(line number, source) of every ```python block of a markdown file, indentation removed."""
    text = path.read_text(encoding="utf-8")
    blocks = []
    for m in FENCE.finditer(text):
        indent = len(m.group("indent"))
        body = "".join(line[indent:] for line in m.group("body").splitlines(keepends=True))
        if all(not line.strip() or line.strip().startswith("--8<--") for line in body.splitlines()):
            continue
        blocks.append((text.count("\n", 0, m.start()) + 1, body))
    return blocks


BLOCKS = [pytest.param(path, line, body, id=f"{path.relative_to(ROOT).as_posix()}:{line}")
          for path in doc_files() for line, body in python_blocks(path)]


def test_the_documentation_has_python_blocks():
    assert len(BLOCKS) >= 10, [b.id for b in BLOCKS]


def test_the_block_finder_sees_indented_blocks_and_skips_other_languages(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("```python\nx = 1\n```\n\n```text\ny\n```\n\n!!! note\n\n    ```python\n    z = 2\n    ```\n"
                    "\n```python\n--8<-- \"docs/examples/corridor.py\"\n```\n")
    assert [body for _, body in python_blocks(page)] == ["x = 1\n", "z = 2\n"]


@pytest.mark.parametrize("path,line,body", BLOCKS)
def test_block_runs(path, line, body, tmp_path, monkeypatch):
    # blocks run from a folder like the repository's root: its data folders, and the read-only ../shared
    shared = ROOT.parent / "shared"
    if "../shared/" in body:
        if not shared.is_dir():
            pytest.skip(f"{shared} (the project's shared data) is absent")
        (tmp_path / "shared").symlink_to(shared, target_is_directory=True)
    work = tmp_path / "repo"
    work.mkdir()
    for name in DATA_DIRS:
        (work / name).symlink_to(ROOT / name, target_is_directory=True)
    monkeypatch.chdir(work)
    code = compile(body, f"{path.relative_to(ROOT).as_posix()}:{line}", "exec")
    namespace = {"__name__": "__doc_block__"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")            # a block shows what a user sees; warnings are not failures,
        warnings.filterwarnings("error", message="old module path")   # but the documentation uses current paths
        exec(code, namespace)
    import matplotlib.pyplot as plt
    plt.close("all")


def test_readme_is_a_front_door():
    """README.md stays short (the reference lives in docs/) and carries no dated measurement."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert 100 <= len(text.splitlines()) <= 200 and len(text) < 30_000
    assert re.search(r"\b20\d\d-\d\d-\d\d\b", text) is None, "dated figures go to CHANGELOG.md"
    for command in ('python3 -m venv .venv && . .venv/bin/activate && pip install . && riskrf demo',
                    'python3 -m venv .venv && . .venv/bin/activate && pip install ".[test]" && python -m pytest'):
        assert f"```bash\n{command}\n```" in text
