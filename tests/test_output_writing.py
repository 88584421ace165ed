"""Output tables: the vectorised CSV writer gives the previous writer's bytes, Parquet round-trips, a missing
pyarrow is named with its install command, and CSV cells stay safe in spreadsheets."""
import csv
import sys

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings, strategies as st

from riskrf.cli import main
from riskrf.io import outputs
from riskrf.io.outputs import (MissingDependencyError, atomic_output_dir, neutralise_csv, require_pyarrow,
                               write_csv, write_table)

from .test_simulation_run import BARRIER


def previous_writer(df, path, index=False):
    """The previous writer: pandas' to_csv, then every cell read back and checked one by one."""
    df.to_csv(path, index=index)
    with open(path, newline="", encoding="utf-8", errors="surrogateescape") as fh:
        rows = list(csv.reader(fh))
    changed = False
    for row in rows:
        for j, cell in enumerate(row):
            new = outputs._neutralise_cell(cell)
            if new is not cell:
                row[j] = new
                changed = True
    if changed:
        with open(path, "w", newline="", encoding="utf-8", errors="surrogateescape") as fh:
            csv.writer(fh, lineterminator="\n").writerows(rows)


def _table():
    rng = np.random.default_rng(3)
    n = 257
    x = rng.normal(size=n) * 10.0 ** rng.integers(-8, 20, size=n)
    x[[0, 5, 9]] = [np.nan, np.inf, -0.0]
    text = pd.Series(rng.choice(["stopped", "left profile", "=1+2", "-inf", "-2.5", "+x", "@SUM(A1)", "a,b",
                                 'say "hi"', "two\nlines", "\tTab", "", "-", "crossed"], size=n))
    text[[3, 4]] = None
    return pd.DataFrame({"x_stop_m": x, "impacts": rng.integers(-5, 40, size=n), "held": rng.random(n) < 0.5,
                         "reason": text, "mass_kg": np.abs(x).astype(np.float32),
                         "=label": rng.integers(0, 3, size=n).astype(np.uint8),
                         "collector": pd.Series(rng.choice(["barrier", "road"], size=n), dtype=object),
                         "outcome": pd.Categorical(rng.choice(["held", "=over", None, "a,b"], size=n))})


@pytest.mark.parametrize("arrow", [True, False], ids=["arrow", "no-pyarrow"])
def test_csv_is_byte_for_byte_the_previous_writers(tmp_path, monkeypatch, arrow):
    df = _table()
    previous_writer(df, tmp_path / "old.csv")
    if not arrow:
        monkeypatch.setitem(sys.modules, "pyarrow", None)        # the pure-Python formatting
    write_csv(df, tmp_path / "new.csv")
    assert (tmp_path / "new.csv").read_bytes() == (tmp_path / "old.csv").read_bytes()
    back = pd.read_csv(tmp_path / "new.csv", keep_default_na=False, dtype=str)
    assert "'=1+2" in set(back["reason"]) and "'@SUM(A1)" in set(back["reason"]) and "'+x" in set(back["reason"])
    assert "-2.5" in set(back["reason"]) and "-inf" in set(back["reason"])        # numbers are not prefixed
    assert "'=label" in back.columns                                                # nor is a header spared
    assert not back["x_stop_m"].str.startswith("'").any()


def test_small_simulation_tables_are_the_previous_writers(tmp_path):
    import simulation
    sc = simulation.load_scenario(BARRIER)
    res = simulation.run(sc, n=400, seed=2)
    crossings = pd.concat([res.collector(c.name).assign(collector=c.name) for c in sc.collectors],
                          ignore_index=True)
    crossings["outcome"] = crossings["outcome"].astype(str)
    for name, table in (("crossings", crossings), ("runout", res.runout), ("envelopes", res.envelopes)):
        previous_writer(table, tmp_path / f"{name}-old.csv")
        write_csv(table, tmp_path / f"{name}-new.csv")
        assert (tmp_path / f"{name}-new.csv").read_bytes() == (tmp_path / f"{name}-old.csv").read_bytes(), name


def test_chunks_and_fallback_give_the_same_bytes(tmp_path, monkeypatch):
    df = _table()
    previous_writer(df, tmp_path / "old.csv")
    monkeypatch.setattr(outputs, "CSV_CHUNK_ROWS", 10)
    write_csv(df, tmp_path / "chunked.csv")
    assert (tmp_path / "chunked.csv").read_bytes() == (tmp_path / "old.csv").read_bytes()
    odd = df.assign(when=pd.Timestamp("2024-01-01"), kind=pd.Categorical(["=x"] * len(df)),
                    mixed=pd.Series(["=y", 1.5] * (len(df) // 2) + ["z"], dtype=object))
    for index in (False, True):
        previous_writer(odd, tmp_path / "odd-old.csv", index=index)
        write_csv(odd, tmp_path / "odd-new.csv", index=index)
        assert (tmp_path / "odd-new.csv").read_bytes() == (tmp_path / "odd-old.csv").read_bytes()


_cells = st.one_of(st.none(), st.text(alphabet=st.sampled_from(list("=+-@\t\r\n\",.'e1 x")), max_size=6),
                   st.floats(allow_nan=True).map(str))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(_cells, st.floats(allow_nan=True, allow_infinity=True), _cells), min_size=1,
                max_size=12))
def test_any_text_gives_the_previous_writers_bytes(tmp_path_factory, rows):
    folder = tmp_path_factory.mktemp("csv")
    df = pd.DataFrame(rows, columns=["a", "b", "c"])
    df["d"] = np.arange(len(df)) * -7
    df["e"] = df["b"].isna()
    df["f"] = np.trunc(df["b"].to_numpy())                      # whole numbers of every size
    for col in ("a", "c"):
        df[col] = df[col].astype(object)
    previous_writer(df, folder / "old.csv")
    write_csv(df, folder / "new.csv")
    assert (folder / "new.csv").read_bytes() == (folder / "old.csv").read_bytes()
    df.to_csv(folder / "net.csv", index=False)          # the safety net for files other writers leave
    neutralise_csv(folder / "net.csv")
    assert (folder / "net.csv").read_bytes() == (folder / "old.csv").read_bytes()


def test_safety_net_still_neutralises_plain_to_csv(tmp_path):
    with atomic_output_dir(tmp_path / "out") as tmp:
        pd.DataFrame({"a": ["=HYPERLINK(1)", "-3"], "b": [-1.0, 2.0]}).to_csv(tmp / "t.csv", index=False)
        write_csv(pd.DataFrame({"a": ["=x", "y"], "b": [1, 2]}), tmp / "w.csv")
        with open(tmp / "w.csv", "a", encoding="utf-8") as fh:        # changed after writing: checked again
            fh.write("=z,3\n")
    assert (tmp_path / "out" / "t.csv").read_text() == "a,b\n'=HYPERLINK(1),-1.0\n-3,2.0\n"
    assert (tmp_path / "out" / "w.csv").read_text() == "a,b\n'=x,1\ny,2\n'=z,3\n"


def test_simulate_reads_no_table_back(tmp_path, monkeypatch):
    checked = []
    monkeypatch.setattr(outputs, "neutralise_csv", lambda path: checked.append(path))
    assert main(["simulate", str(BARRIER), "-n", "200", "--out", str(tmp_path / "run.csv"), "--no-progress"]) == 0
    assert checked == []                # write_csv checked the cells in memory; atomic_outputs trusts it
    assert (tmp_path / "run-figures" / "runout.csv").is_file()


def test_parquet_round_trips_the_table(tmp_path):
    pytest.importorskip("pyarrow", reason="Parquet output needs pyarrow (pip install 'riskrf[parquet]')")
    df = _table()
    write_table(df, tmp_path / "t.parquet")
    back = pd.read_parquet(tmp_path / "t.parquet")
    pd.testing.assert_frame_equal(back, df, check_dtype=False)
    assert back["reason"].tolist()[:10] == df["reason"].tolist()[:10]        # values as they are, not prefixed


def test_missing_pyarrow_names_the_option_and_the_install(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "pyarrow", None)                    # import pyarrow -> ImportError
    with pytest.raises(MissingDependencyError, match=r"--format parquet: .*pip install 'riskrf\[parquet\]'"):
        require_pyarrow("--format parquet")
    with pytest.raises(ImportError):
        write_table(pd.DataFrame({"a": [1]}), tmp_path / "t.parquet")
    out = tmp_path / "run.parquet"
    assert main(["simulate", str(BARRIER), "-n", "50", "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and "pip install 'riskrf[parquet]'" in err and "name a .csv file" in err
    assert not out.exists() and not (tmp_path / "run-figures").exists()     # refused before any work


def test_reading_parquet_without_pyarrow_names_the_file(tmp_path, monkeypatch):
    pytest.importorskip("pyarrow", reason="writing the Parquet file to read needs pyarrow")
    from riskrf.io.tables import read_table
    pd.DataFrame({"date": ["2020-01-01"], "volume_m3": [1.5]}).to_parquet(tmp_path / "inv.parquet")
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    with pytest.raises(MissingDependencyError, match=r"inv\.parquet: Parquet needs pyarrow.*riskrf\[parquet\]"):
        read_table(tmp_path / "inv.parquet")


def test_simulate_format_both(tmp_path, capsys):
    pytest.importorskip("pyarrow", reason="Parquet output needs pyarrow (pip install 'riskrf[parquet]')")
    out = tmp_path / "run.csv"
    assert main(["simulate", str(BARRIER), "-n", "300", "--seed", "2", "--out", str(out), "--format", "both",
                 "--no-progress"]) == 0
    figs = tmp_path / "run-figures"
    csv_table = pd.read_csv(out)
    parquet_table = pd.read_parquet(tmp_path / "run.parquet")
    pd.testing.assert_frame_equal(csv_table, parquet_table, check_dtype=False)
    for name in ("runout", "envelopes"):
        table = pd.read_parquet(figs / f"{name}.parquet")
        table = table.astype({c: str for c in table.columns if isinstance(table[c].dtype, pd.CategoricalDtype)})
        pd.testing.assert_frame_equal(pd.read_csv(figs / f"{name}.csv"), table, check_dtype=False)
    assert "run.parquet" in capsys.readouterr().out


def test_simulate_format_conflicts_and_default(tmp_path, capsys, monkeypatch):
    assert main(["simulate", str(BARRIER), "-n", "50", "--out", str(tmp_path / "a.csv"), "--format",
                 "parquet"]) == 2
    assert "--format parquet" in capsys.readouterr().err
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", str(BARRIER), "-n", "50", "--no-progress"]) == 0
    assert (tmp_path / "road_cut_barrier-crossings.csv").is_file()
    assert (tmp_path / "road_cut_barrier-crossings-figures" / "runout.csv").is_file()
    assert not list(tmp_path.rglob("*.parquet"))
