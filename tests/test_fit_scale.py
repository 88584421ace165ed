"""Scale of the power-law fits: parallel, seeded, gridded and interruptible bootstrap."""
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import riskrf
from riskrf.frequency.power_law import GRID_CANDIDATES, LARGE_SAMPLE
from riskrf.frequency.power_law.threshold import _candidates


def _sample(n, seed=3, b=0.8):
    rng = np.random.default_rng(seed)
    pareto = (1 - rng.random(n)) ** (-1 / b)
    return np.concatenate([pareto * 5, rng.uniform(0.1, 5, n // 3)])     # a power-law tail over a flat body


def test_bootstrap_identical_for_any_number_of_workers():
    fit = riskrf.fit_gutenberg_richter(_sample(600), 10.0)
    one = fit.bootstrap_test(24, seed=7, workers=1)
    two = fit.bootstrap_test(24, seed=7, workers=2)
    three = fit.bootstrap_test(24, seed=7, workers=3)
    assert one == two == three
    assert one.grid is None and one.ks_distance == fit.ks_distance      # small samples: the exact scan
    assert one != fit.bootstrap_test(24, seed=8, workers=2)


def test_progress_is_reported_from_zero_to_total():
    fit = riskrf.fit_gutenberg_richter(_sample(300), 10.0)
    seen = []
    fit.bootstrap_test(12, seed=1, workers=2, progress=lambda done, total: seen.append((done, total)))
    assert seen[0] == (0, 12) and seen[-1] == (12, 12)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen) and {t for _, t in seen} == {12}


def test_grid_scan_is_exact_when_it_covers_every_value_and_never_below_the_full_minimum():
    x = np.sort(_sample(3000))
    full = riskrf.find_m_min(x)
    assert riskrf.find_m_min(x, grid=10 * x.size) == full          # grid larger than the sample: every value
    coarse = riskrf.find_m_min(x, grid=60)
    assert coarse[1] >= full[1]                                      # a minimum over fewer candidates
    cand = _candidates(x, 10, 60)
    assert cand.size <= 60 and np.all(x.size - cand >= 10)
    # tail sizes are log-spaced: the smallest candidate tails are dense, the largest sparse
    tails = np.sort(x.size - cand)
    assert tails[0] <= 11 and tails[-1] > x.size * 0.9


def test_forced_grid_measures_data_and_replicates_alike():
    fit = riskrf.fit_gutenberg_richter(_sample(2000), 10.0)
    res = fit.bootstrap_test(10, seed=2, grid=40)
    assert res.grid == 40
    assert res.ks_distance == riskrf.find_m_min(fit.data, grid=40)[1] >= fit.ks_distance
    assert "40 candidates" in res.summary().loc["grid", "note"]
    # the default switches to the grid only above LARGE_SAMPLE values
    assert fit.bootstrap_test(3, seed=2).grid is None and LARGE_SAMPLE == 100_000 and GRID_CANDIDATES == 2000
    with pytest.raises(ValueError, match="grid = 1"):
        fit.bootstrap_test(3, grid=1)
    with pytest.raises(ValueError, match="workers must be"):
        fit.bootstrap_test(3, workers=0)


def test_cli_fit_reports_grid_and_rejects_bad_workers(tmp_path, capsys):
    from riskrf.cli import main
    f = tmp_path / "inv.csv"
    f.write_text("volume_m3\n" + "\n".join(f"{v:.6g}" for v in _sample(400) / 100) + "\n")
    rc = main(["fit", str(f), "--duration-years", "10", "--bootstrap", "5", "--bootstrap-grid", "30",
               "--workers", "2", "--no-progress", "--out", str(tmp_path / "o")])
    assert rc == 0
    text = capsys.readouterr().out
    assert "each replicate scan 30 log-spaced thresholds" in text
    rc = main(["fit", str(f), "--duration-years", "10", "--workers", "0", "--out", str(tmp_path / "p")])
    assert rc == 2 and "--workers = 0" in capsys.readouterr().err and not (tmp_path / "p").exists()


def test_ctrl_c_during_a_long_bootstrap_ends_with_one_line_and_writes_nothing(tmp_path):
    f = tmp_path / "inv.csv"
    f.write_text("volume_m3\n" + "\n".join(f"{v:.6g}" for v in _sample(2_000) / 100) + "\n")
    out = tmp_path / "fit-out"
    code = textwrap.dedent(f"""
        import sys
        from riskrf.cli import main
        sys.exit(main(["fit", {str(f)!r}, "--duration-years", "10", "--bootstrap", "1000000", "--workers", "2",
                       "--progress", "--out", {str(out)!r}]))
    """)
    # the child gets the default SIGINT action even when pytest runs with SIGINT ignored (nohup, background
    # jobs): Python only turns SIGINT into KeyboardInterrupt when it starts with the default action
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            cwd=tmp_path, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    seen = b""
    deadline = time.monotonic() + 120
    while b"replicates" not in seen and time.monotonic() < deadline:      # the bar: the bootstrap is running
        chunk = proc.stderr.read1(4096)
        if not chunk:
            break
        seen += chunk
    assert b"replicates" in seen, seen.decode(errors="replace")
    proc.send_signal(signal.SIGINT)
    _, rest = proc.communicate(timeout=60)
    err = (seen + rest).decode()
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    # the bar redraws itself after "\r" on one line (split on "\n" only: splitlines() would split at each "\r",
    # and the number of redraws before the signal is a matter of timing)
    lines = err.strip().split("\n")
    assert lines[-1] == "riskrf fit: interrupted; nothing was written (outputs appear only when complete)"
    assert len(lines) == 2 and lines[0].lstrip("\r").startswith("bootstrap [")       # the bar, then one line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["inv.csv"]
