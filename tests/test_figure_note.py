"""A note stamped at the foot of the figures written inside riskrf.report.files.figure_note (an uncalibrated
trajectory model says so on every figure drawn from its trajectories), and none on the frequency fits."""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

import riskrf  # noqa: E402
from riskrf.report import files  # noqa: E402

NOTE = "UNCALIBRATED trajectory model"


@pytest.fixture
def saved(monkeypatch):
    """The figure-level texts of every figure saved, in order."""
    seen = []
    real = files.save_figure

    def spy(fig, path, **kw):
        out = real(fig, path, **kw)
        seen.append([t.get_text() for t in fig.texts])
        return out
    monkeypatch.setattr(files, "save_figure", spy)
    return seen


def test_a_figure_saved_inside_the_note_carries_it_and_outside_does_not(tmp_path, saved):
    def draw(name):
        fig, ax = plt.subplots()
        ax.plot([0, 1], [0, 1])
        files.save_figure(fig, tmp_path / name)
    with files.figure_note(NOTE):
        draw("a.png")
        with files.figure_note(None):
            draw("b.png")
    draw("c.png")
    assert saved == [[NOTE], [], []]
    assert all((tmp_path / n).stat().st_size > 0 for n in ("a.png", "b.png", "c.png"))


def test_the_frequency_figures_carry_no_trajectory_note(tmp_path, saved):
    inv = riskrf.read_inventory(Path(riskrf.__file__).parent / "data" / "lauterbrunnen_tls_2018.csv")
    fits = riskrf.analyse_inventory(inv, n_bootstrap=0)
    with files.figure_note(NOTE):
        files.write_frequency_figures(fits, tmp_path)
    assert saved and all(NOTE not in t for t in saved)


def test_riskrf_simulate_says_when_its_trajectory_model_is_uncalibrated(tmp_path, capsys):
    from riskrf.cli import main

    from .conftest import ROOT
    assert main(["simulate", str(ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml"), "-n", "20",
                 "--out", str(tmp_path / "c.csv")]) == 0
    assert "UNCALIBRATED trajectory model" in capsys.readouterr().out
