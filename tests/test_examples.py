"""The example scripts of the documentation (docs/examples/*.py) run as a user runs them.

Each is run in a child process from the repository root, ``python docs/examples/NAME.py OUT_DIR``, as the
documentation build does; it must exit 0, print its results and write at least one figure, only into OUT_DIR.
"""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from .conftest import ROOT

EXAMPLES = sorted((ROOT / "docs" / "examples").glob("*.py"))


def test_there_are_six_examples():
    assert {p.stem for p in EXAMPLES} >= {"fit_inventory", "energy_at_fence", "calibrate_authume",
                                          "mitigation_ranking", "corridor", "calibrate_then_assess"}


@pytest.mark.slow
@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_and_writes_its_figures(script, tmp_path):
    out = tmp_path / "out"
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    proc = subprocess.run([sys.executable, str(script), str(out)], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, f"{script.name} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    assert proc.stdout.strip(), f"{script.name} printed nothing"
    figures = sorted(p.name for p in out.glob("*.png"))
    assert figures, f"{script.name} wrote no figure into {out}"
    for line in proc.stdout.splitlines():
        if line.startswith("wrote "):
            assert line.split("wrote ", 1)[1].startswith(str(out)), line
