"""Writing results: all-or-nothing output directories and JSON that carries units."""
from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import re
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from ..core.validation import RiskrfError


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def check_output(path, *, overwrite: bool = False, kind: str = "dir", option: str = "--out") -> Path:
    """Refuse an output that would clobber something, before any work starts.

    ``kind="dir"``: an existing file is always refused; an existing non-empty
    directory is refused unless ``overwrite`` (it is then replaced whole, see
    :func:`atomic_outputs`); an empty one is used.  ``kind="file"``: an existing
    directory is always refused, an existing file unless ``overwrite``.

    Parameters
    ----------
    path : str or path
        The output asked for.
    overwrite : bool
        Whether an existing output may be replaced.
    kind : {"dir", "file"}
        What the output is.
    option : str
        The command-line option that named it, for the message.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ValueError
        Naming the path and the option.
    """
    path = Path(path)
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(f"{option} {path}: {parent} is a file, not a directory")
            break
    if kind == "dir":
        if path.exists() and not path.is_dir():
            raise ValueError(f"{option} {path} is a file; name a new directory for the outputs (an existing file "
                             "is never replaced by a directory, even with --overwrite)")
        if path.is_dir() and any(path.iterdir()) and not overwrite:
            raise ValueError(f"{option} {path} already exists and is not empty; choose a new name, or pass "
                             "--overwrite to replace it whole (its current files are removed)")
    else:
        if path.is_dir():
            raise ValueError(f"{option} {path} is a directory; name a .parquet or .csv file")
        if path.exists() and not overwrite:
            raise ValueError(f"{option} {path} already exists; choose a new name, or pass --overwrite to replace it")
    return path


def _real(path) -> Path:
    return Path(os.path.realpath(os.path.abspath(os.fspath(path))))


def check_output_spares_inputs(out, inputs, *, option: str = "--out") -> Path:
    """Refuse an output that would replace, contain or sit inside one of the command's inputs, before any work.

    An output directory is replaced whole with ``--overwrite``: an ``--out`` that is an input file, the folder
    holding one (or any folder above it), or a path inside an input would delete or shadow the data the run
    reads.  ``""`` and ``"."`` (the working folder) are refused as well.

    Parameters
    ----------
    out : str or Path
        The output path as given (a directory, or a file for ``riskrf simulate``).
    inputs : mapping of str to path
        What each input is (e.g. ``"inventory"``, ``"sidecar of the inventory"``) and its path; ``None`` values
        and paths that do not exist are skipped.
    option : str
        The argument that named ``out``, for the message.

    Returns
    -------
    Path
        ``out`` as a :class:`~pathlib.Path`.

    Raises
    ------
    ValueError
        Naming the argument, its value and the input it would endanger.
    """
    text = os.fspath(out)
    if text.strip() == "":
        raise ValueError(f"{option} = {text!r}: an empty name is not an output folder; name a new folder")
    here = _real(os.curdir)
    if _real(text) == here or _real(text) in here.parents:
        above = "" if _real(text) == here else " (or a folder above it)"
        raise ValueError(f"{option} = {text!r}: the working folder{above} "
                         "would be replaced whole, with everything in it; name a new folder for the outputs")
    target = _real(text)
    for label, path in inputs.items():
        if path is None or os.fspath(path) == "":
            continue
        src = _real(path)
        if not src.exists():
            continue
        where = f"{label} {os.fspath(path)}"
        if target == src:
            raise ValueError(f"{option} = {text!r} is the {where}: the output would replace it; name a new "
                             f"{'file' if src.is_file() else 'folder'} for the outputs")
        if target in src.parents:
            raise ValueError(f"{option} = {text!r} holds the {where}: writing the outputs there would delete it "
                             "(an output folder is replaced whole); name a new folder for the outputs")
        if src in target.parents:
            raise ValueError(f"{option} = {text!r} lies inside the {where}, which is a "
                             f"{'file' if src.is_file() else 'folder'}; name a folder outside the inputs")
    return Path(text)


def files_named_in_toml(path, *, label: str = "") -> dict:
    """Every existing file a TOML input names (relative to its folder), with the TOML itself and each named
    file's sidecar ``<stem>.toml``: ``{"what it is": path}`` for :func:`check_output_spares_inputs`.

    Unreadable TOML gives just the file itself (its own reader reports the error).

    Parameters
    ----------
    path : str or path
        A TOML input (site, scenario, corridor, options).
    label : str
        What the TOML is, for the keys.

    Returns
    -------
    dict
        ``{"what it is": pathlib.Path}``.
    """
    import tomllib
    path = Path(path)
    label = label or "input file"
    found = {label: path}
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except (OSError, ValueError):
        return found

    def walk(value, key):
        if isinstance(value, dict):
            for k, v in value.items():
                walk(v, f"{key}.{k}" if key else str(k))
        elif isinstance(value, list):
            for i, v in enumerate(value):
                walk(v, f"{key}[{i}]")
        elif isinstance(value, str) and value and len(value) < 1024 and "\n" not in value:
            try:
                candidate = (path.parent / value)
                if candidate.is_file():
                    found[f"{key} of {path.name}"] = candidate
                    side = candidate.with_suffix(".toml")
                    if side.is_file() and side != candidate:
                        found[f"sidecar of {key} of {path.name}"] = side
            except (OSError, ValueError):
                pass
    walk(data, "")
    return found


_FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def _neutralise_cell(cell: str) -> str:
    if cell and cell.startswith(_FORMULA_START):
        try:
            float(cell)
            return cell
        except ValueError:
            return "'" + cell
    return cell


#: Files written by :func:`write_csv`, whose cells are already safe: ``(st_dev, st_ino)`` ->
#: ``(st_size, st_mtime_ns)`` right after writing (a rename or chmod keeps both; writing to the file changes
#: its modification time, and then :func:`_finish` neutralises it again).
_NEUTRALISED: dict[tuple[int, int], tuple[int, int]] = {}


def _stat_key(path) -> tuple[tuple[int, int], tuple[int, int]]:
    st = os.stat(path)
    return (st.st_dev, st.st_ino), (st.st_size, st.st_mtime_ns)


def _already_neutralised(path) -> bool:
    key, sig = _stat_key(path)
    return _NEUTRALISED.pop(key, None) == sig


#: Where a spreadsheet cell could start: the start of the file, or after a comma or a line end.  ``"`` opens a
#: quoted cell; the captured rest runs to the next comma, quote or line end, and the character after it is
#: captured to tell an ordinary cell from a quoted or odd one.
_CELL_START = re.compile(r'(?:\A|(?<=[,\n\r]))([=+\-@\t\r"])([^,\n\r"]*)(.?)', re.S)


def _needs_neutralising(text: str) -> bool:
    """Whether ``text`` (a whole CSV file) may hold a cell :func:`neutralise_csv` would change.

    ``False`` only when every place a cell could start with ``=``, ``+``, ``-``, ``@``, tab or carriage return
    holds an unquoted number (``-1.5``, ``+3e-2``): such a file is left exactly as it is by the full
    rewrite, so it can be skipped.  ``True`` sends the file to the exact cell-by-cell check (quoted cells and
    every other case).
    """
    for m in _CELL_START.finditer(text):
        first, rest, after = m.groups()
        if first == '"':                      # a quoted cell: unsafe when its text starts like a formula
            if (rest[:1] or after) in _FORMULA_START and (rest or after):
                return True
            continue
        if after not in ("", ",", "\n", "\r"):
            return True
        try:
            float(first + rest)
        except ValueError:
            return True
    return False


def neutralise_csv(path) -> None:
    """Prefix with ``'`` every text cell that a spreadsheet would execute as a formula (=, +, -, @).

    A cell that starts with one of ``= + - @``, tab or carriage return and is not a number (``-1.5`` stays)
    gets the prefix.  A file whose possible formula cells are all unquoted numbers is recognised from its
    text in one pass and not rewritten; any other file is read and checked cell by cell.

    Parameters
    ----------
    path : str or path
        A CSV file (UTF-8), rewritten in place when a cell changes.

    References
    ----------
    OWASP, CSV Injection (https://owasp.org/www-community/attacks/CSV_Injection).
    """
    path = Path(path)
    with open(path, newline="", encoding="utf-8", errors="surrogateescape") as fh:
        text = fh.read()
    if not _needs_neutralising(text):
        return
    rows = list(csv.reader(io.StringIO(text, newline="")))
    del text
    changed = False
    for row in rows:
        for j, cell in enumerate(row):
            new = _neutralise_cell(cell)
            if new is not cell:
                row[j] = new
                changed = True
    if changed:
        with open(path, "w", newline="", encoding="utf-8", errors="surrogateescape") as fh:
            csv.writer(fh, lineterminator="\n").writerows(rows)


def _neutralise_strings(values: pd.Series) -> pd.Series:
    """``values`` (text or missing) with every cell :func:`_neutralise_cell` would change changed; vectorised:
    only the cells starting with a formula character are looked at one by one."""
    start = values.str.startswith(_FORMULA_START, na=False).to_numpy()
    if not start.any():
        return values
    where = np.flatnonzero(start)
    values = values.astype(object)
    values.iloc[where] = [_neutralise_cell(v) for v in values.iloc[where]]
    return values


#: Characters that make the csv module quote a cell (comma, quote, line ends) or may (other control
#: characters); cells holding one are written through the csv module itself, so the quoting is its own.
_MAY_QUOTE = r'[\x00-\x1f",]'


def _csv_cells(values) -> list[str]:
    """One row of cells as the csv module writes it (QUOTE_MINIMAL, ``\n``), split back into cells' text."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    out = []
    for v in values:
        buf.seek(0)
        buf.truncate()
        w.writerow([v, ""])                   # two cells: a lone empty cell would be written as ""
        out.append(buf.getvalue()[:-2])
    return out


#: Text the csv module writes but does not read back as written (an unquoted carriage return ends the row; a
#: NUL byte is refused): such tables go through pandas and the cell-by-cell check, as before.
_UNREADABLE = r"[\r\x00]"


def _is_text_column(col: pd.Series) -> bool:
    if isinstance(col.dtype, pd.CategoricalDtype):
        return _is_text_column(pd.Series(col.cat.categories, dtype=object))
    if isinstance(col.dtype, pd.StringDtype):
        return True
    return col.dtype == object and pd.api.types.infer_dtype(col, skipna=True) in ("string", "empty")


def _fast_csv_ok(df: pd.DataFrame) -> bool:
    """Whether :func:`write_csv` can format ``df`` itself: flat text column labels, two or more columns and rows,
    and every column float, integer or bool (NumPy) or text (also categories of text) with missing values (no
    carriage return or NUL)."""
    if len(df.columns) < 2 or len(df) == 0 or isinstance(df.columns, pd.MultiIndex):
        return False
    if not all(isinstance(c, str) for c in df.columns) or df.columns.has_duplicates:
        return False
    for _, col in df.items():
        dt = col.dtype
        if isinstance(dt, np.dtype) and dt.kind in "fiub":
            continue
        text = pd.Series(col.cat.categories, dtype=object) if isinstance(dt, pd.CategoricalDtype) else col
        if not _is_text_column(col) or text.str.contains(_UNREADABLE, regex=True, na=False).any():
            return False
    return True


def _column_text(col: pd.Series) -> list[str]:
    """The cells of one column as pandas' ``to_csv`` writes them, already neutralised and quoted."""
    dt = col.dtype
    if isinstance(dt, np.dtype) and dt.kind in "fiub":
        arr = col.to_numpy()
        if dt == np.float64:
            text = list(map(float.__repr__, arr.tolist()))     # what NumPy's astype(str) gives, faster
        elif dt.kind == "f":
            text = arr.astype(str).tolist()                     # float32/16: their own shortest repr
        else:
            text = list(map(str, arr.tolist()))
        if dt.kind == "f":
            for i in np.flatnonzero(np.isnan(arr)):
                text[i] = ""
        return text
    if isinstance(dt, pd.CategoricalDtype):            # each category formatted once, then taken by code
        cats = _column_text(pd.Series(col.cat.categories, dtype=object)) + [""]
        return np.array(cats, dtype=object)[col.cat.codes.to_numpy()].tolist()
    values = _neutralise_strings(col)
    special = values.str.contains(_MAY_QUOTE, regex=True, na=False).to_numpy()
    missing = values.isna().to_numpy()
    text = values.astype(object).tolist()
    for i in np.flatnonzero(missing):
        text[i] = ""
    for i, cell in zip(np.flatnonzero(special), _csv_cells(values.iloc[np.flatnonzero(special)])):
        text[i] = cell
    return text


#: Rows formatted and written at a time by :func:`write_csv` (bounds the memory of the text).
CSV_CHUNK_ROWS = 50_000


def _arrow_float_text(arr: np.ndarray, pa, pc):
    """float64 values as Python's ``repr`` writes them (NaN empty), formatted by Arrow where both agree.

    Arrow's cast to text gives the same shortest round-trip digits as ``repr``; it differs only in layout:
    no ``.0`` after a whole number, and exponent notation at other magnitudes.  Values of magnitude in
    [1e-4, 1e16) that Arrow writes without an exponent are therefore taken from Arrow (``.0`` added to whole
    numbers, zeros included); NaN, infinities and every other value are written by ``repr`` itself.
    """
    text = pc.cast(pa.array(arr), pa.string())
    with np.errstate(invalid="ignore"):
        ax = np.abs(arr)
        plain = ((ax >= 1e-4) & (ax < 1e16)) | (ax == 0)            # Arrow: "0", "-0"
        data = text.buffers()[2]                    # the digits of every value: one scan finds any "e"
        if data is not None and (np.frombuffer(data, dtype=np.uint8) == ord("e")).any():
            plain &= ~pc.match_substring(text, "e").to_numpy(zero_copy_only=False)
        whole = plain & (arr == np.trunc(arr))      # written without an exponent, so without a fraction
    if whole.any():
        mask = pa.array(whole)
        text = pc.replace_with_mask(text, mask, pc.binary_join_element_wise(pc.filter(text, mask), ".0", ""))
    rest = np.flatnonzero(~plain)
    if rest.size:
        fixed = ["" if v != v else float.__repr__(v) for v in arr[rest].tolist()]
        text = pc.replace_with_mask(text, pa.array(~plain), pa.array(fixed, type=pa.string()))
    return text


def _arrow_column_text(col: pd.Series, pa, pc):
    """The cells of one column as :func:`_column_text` gives them, as an Arrow string array."""
    dt = col.dtype
    if dt == np.float64:
        return _arrow_float_text(col.to_numpy(), pa, pc)
    if isinstance(dt, np.dtype) and dt.kind in "iu":
        return pc.cast(pa.array(col.to_numpy()), pa.string())
    if isinstance(dt, np.dtype) and dt.kind == "b":
        return pc.if_else(pa.array(col.to_numpy()), "True", "False")
    if isinstance(dt, np.dtype) and dt.kind == "f":
        return pa.array(_column_text(col), type=pa.string())
    if isinstance(dt, pd.CategoricalDtype):
        codes, uniques = col.cat.codes.to_numpy(), pd.Series(col.cat.categories, dtype=object)
    else:                                      # text: each distinct value formatted once, then taken by code
        codes, uniques = pd.factorize(col, use_na_sentinel=True)
        uniques = pd.Series(uniques, dtype=object)
    cells = _column_text(uniques) + [""]                       # code -1 (missing) takes the last, empty cell
    codes = np.where(codes < 0, len(cells) - 1, codes)
    return pa.array(cells, type=pa.string()).take(pa.array(codes))


def _arrow_rows(part: pd.DataFrame, pa, pc):
    """The UTF-8 text of the rows of ``part`` (each ending in ``\n``), joined by Arrow: a buffer (no copy) that
    a file's ``write`` takes as it is."""
    cells = [_arrow_column_text(col, pa, pc) for _, col in part.items()]
    cells[-1] = pc.binary_join_element_wise(cells[-1], "\n", "")        # the line end on the last cell
    lines = pc.binary_join_element_wise(*cells, ",")
    offsets = np.frombuffer(lines.buffers()[1], dtype=np.int32, count=len(lines) + 1, offset=4 * lines.offset)
    return lines.buffers()[2].slice(int(offsets[0]), int(offsets[-1] - offsets[0]))


def _in_order(fn, items, *, ahead: int = 3):
    """``fn(item)`` for each of ``items``, in order, computed by two threads with at most ``ahead`` results
    waiting: Arrow's formatting releases the interpreter lock, so one chunk is formatted while the next is.  Three
    by default, so that both threads have a chunk to format while the caller writes one (two left a thread idle:
    writing both tables of ``riskrf simulate`` with 10^6 blocks took 1.74-1.81 s against 1.27-1.45 s with three)."""
    items = list(items)
    if len(items) < 2:
        yield from map(fn, items)
        return
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=2) as pool:
        pending = [pool.submit(fn, item) for item in items[:ahead]]
        for i in range(len(items)):
            result = pending.pop(0).result()
            if i + ahead < len(items):
                pending.append(pool.submit(fn, items[i + ahead]))
            yield result


def write_csv(df: pd.DataFrame, path, *, index: bool = False) -> None:
    """Write ``df`` as CSV with every text cell a spreadsheet would run as a formula prefixed with ``'``.

    The file is byte for byte what ``df.to_csv(path, index=index)`` followed by :func:`neutralise_csv` writes
    (UTF-8, ``,``, ``"`` quoting where needed, ``\n`` line ends, missing values empty, floats in their
    shortest round-trip form), but only text columns and labels are checked, in memory and vectorised;
    numeric columns never need it.  With pyarrow installed, Arrow formats the numbers and joins the cells
    (the same text; see :func:`_arrow_float_text`), chunks formatted on two threads (Arrow releases the
    interpreter lock) while this one writes, each text value once per chunk.  Tables of NumPy float, integer,
    bool and text (or categorical text) columns are formatted here, :data:`CSV_CHUNK_ROWS` rows at a time; any
    other table (dates, mixed object columns, an index) goes through pandas and the file check.
    :func:`atomic_outputs` does not check the file again.

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    path : str or path
        The file written (replaced if it exists; write into :func:`atomic_outputs`' temporary names for an
        all-or-nothing output).
    index : bool
        Whether to write the index as the first column(s), as pandas does.
    """
    path = Path(path)
    if index or not _fast_csv_ok(df):
        df.to_csv(path, index=index)
        neutralise_csv(path)
    else:
        header = _csv_cells(_neutralise_strings(pd.Series(list(df.columns), dtype=object)))
        try:                                   # Arrow formats and joins the cells (the same text, faster)
            import pyarrow as pa
            import pyarrow.compute as pc
        except ImportError:
            pa = None
        starts = range(0, len(df), CSV_CHUNK_ROWS)
        with open(path, "wb") as fh:
            fh.write((",".join(header) + "\n").encode("utf-8"))
            if pa is not None:
                for text in _in_order(lambda start: _arrow_rows(df.iloc[start:start + CSV_CHUNK_ROWS], pa, pc),
                                      starts):
                    fh.write(text)
            else:
                for start in starts:
                    cells = [_column_text(col) for _, col in df.iloc[start:start + CSV_CHUNK_ROWS].items()]
                    fh.write(("\n".join(map(",".join, zip(*cells))) + "\n").encode("utf-8"))
    key, sig = _stat_key(path)
    _NEUTRALISED[key] = sig


class MissingDependencyError(RiskrfError, ImportError, ValueError):
    """An optional package a chosen option needs is not installed (the message names the option and the
    install command).  Also an :class:`ImportError`, and a :class:`ValueError` so that the command line
    reports it in one line."""


def require_pyarrow(option: str, *, instead: str = ""):
    """Import pyarrow for ``option``, or say which extra installs it.

    Parameters
    ----------
    option : str
        What needs Parquet, for the message (e.g. ``"--format parquet"``, or the file read).
    instead : str
        An alternative offered in the message (e.g. ``"or use --format csv"``).

    Returns
    -------
    module
        :mod:`pyarrow`.

    Raises
    ------
    MissingDependencyError
        pyarrow is not installed.
    """
    try:
        import pyarrow
    except ImportError:
        raise MissingDependencyError(
            f"{option}: Parquet needs pyarrow, which is not installed: "
            f"pip install 'riskrf[parquet]' (or pip install pyarrow){', ' + instead if instead else ''}") from None
    return pyarrow


def write_parquet(df: pd.DataFrame, path, *, option: str = "Parquet output") -> None:
    """Write ``df`` as Parquet (pyarrow, no index); the values as they are (no cell is prefixed).

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    path : str or path
        The file written.
    option : str
        What asked for Parquet, for the message when pyarrow is missing.

    Raises
    ------
    MissingDependencyError
        pyarrow is not installed (``pip install 'riskrf[parquet]'``).
    """
    require_pyarrow(option)
    df.to_parquet(path, index=False)


def write_table(df: pd.DataFrame, path, *, suffix: str | None = None, option: str = "--out") -> None:
    """Write ``df`` as Parquet or CSV by ``suffix`` (default: the file's), with :func:`write_parquet` or
    :func:`write_csv`.

    Parameters
    ----------
    df : pandas.DataFrame
        The table.
    path : str or path
        The file written (inside :func:`atomic_outputs` for an all-or-nothing output).
    suffix : {".csv", ".parquet"}, optional
        The format, when the file name does not give it (a temporary name).
    option : str
        The option that named the file, for messages.

    Raises
    ------
    ValueError
        Another suffix.
    MissingDependencyError
        Parquet without pyarrow.
    """
    path = Path(path)
    suffix = (suffix or path.suffix).lower()
    if suffix == ".parquet":
        write_parquet(df, path, option=option)
    elif suffix == ".csv":
        write_csv(df, path)
    else:
        raise ValueError(f"{option} {path}: use a .parquet or .csv file name")


def _finish(tmp: Path) -> None:
    """Permissions by the user's umask (temporary names are created private) and safe CSV cells."""
    mode_dir, mode_file = 0o777 & ~_umask(), 0o666 & ~_umask()
    items = [tmp] + (sorted(tmp.rglob("*")) if tmp.is_dir() else [])
    for item in items:
        if item.is_dir():
            os.chmod(item, mode_dir)
        elif item.is_file():
            if item.suffix.lower() == ".csv" and not _already_neutralised(item):
                neutralise_csv(item)
            os.chmod(item, mode_file)


@contextlib.contextmanager
def atomic_outputs(targets, *, overwrite: bool = False, option: str = "--out"):
    """Write several outputs (directories and files) that appear together or not at all.

    ``targets`` is a list of ``(path, kind)`` with kind ``"dir"`` or ``"file"``.  Yields the
    list of temporary siblings to write into (a directory, or a file name for a file).  On
    success each is renamed into place; an existing target is replaced only with ``overwrite``
    (it is renamed aside first and restored if a later rename fails).  On any exception,
    including Ctrl-C, the temporary siblings are removed and the targets are left as they were.

    Parameters
    ----------
    targets : list of (path, str)
        Each output and its kind, ``"dir"`` or ``"file"``.
    overwrite : bool
        Whether existing targets may be replaced.
    option : str
        The command-line option that named them, for messages.

    Yields
    ------
    list of pathlib.Path
        The temporary siblings, in the order of ``targets``.
    """
    targets = [(Path(p), k) for p, k in targets]
    for p, k in targets:
        check_output(p, overwrite=overwrite, kind=k, option=option)
    tmps = []
    try:
        for p, k in targets:
            p.parent.mkdir(parents=True, exist_ok=True)
            if k == "dir":
                tmps.append(Path(tempfile.mkdtemp(prefix=f".{p.name}.partial-", dir=p.parent)))
            else:
                fd, name = tempfile.mkstemp(prefix=f".{p.stem}.partial-", suffix=p.suffix, dir=p.parent)
                os.close(fd)
                tmps.append(Path(name))
        yield tmps if len(tmps) > 1 else tmps[0]
        for (p, k), tmp in zip(targets, tmps):
            check_output(p, overwrite=overwrite, kind=k, option=option)    # nothing appeared meanwhile
            _finish(tmp)
        moved, aside = [], []
        try:
            for (p, k), tmp in zip(targets, tmps):
                if p.exists() and (k == "file" or any(p.iterdir())):
                    old = p.with_name(f".{p.name}.replaced-{os.getpid()}")
                    os.replace(p, old)
                    aside.append((p, old))
                elif p.is_dir():
                    p.rmdir()
                os.replace(tmp, p)
                moved.append(p)
        except BaseException:
            for p in moved:
                shutil.rmtree(p, ignore_errors=True) if p.is_dir() else p.unlink(missing_ok=True)
            for p, old in aside:
                os.replace(old, p)
            raise
        for _, old in aside:
            shutil.rmtree(old, ignore_errors=True) if old.is_dir() else old.unlink(missing_ok=True)
    finally:
        for tmp in tmps:
            if tmp.is_dir():
                shutil.rmtree(tmp, ignore_errors=True)
            else:
                tmp.unlink(missing_ok=True)


@contextlib.contextmanager
def atomic_output_dir(path, *, overwrite: bool = False):
    """Yield a temporary directory that replaces ``path`` only on success (see :func:`atomic_outputs`).

    An existing non-empty ``path`` is refused unless ``overwrite``, and then replaced whole
    (never merged); an existing file is always refused.

    Parameters
    ----------
    path : str or path
        The output directory.
    overwrite : bool
        Whether an existing one may be replaced.

    Yields
    ------
    pathlib.Path
        The temporary directory to write into.
    """
    with atomic_outputs([(path, "dir")], overwrite=overwrite) as tmp:
        yield tmp


def _clean(value):
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_clean(v) for v in value.tolist()]
    if isinstance(value, (np.floating, float)):
        v = float(value)
        return None if math.isnan(v) or math.isinf(v) else v
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (np.bool_,)):
        return bool(value)
    if isinstance(value, pd.DataFrame):
        return _clean(value.reset_index().to_dict(orient="records"))
    if isinstance(value, Path):
        return str(value)
    return value


def write_json(data, path) -> None:
    """Write ``data`` as indented JSON; NaN and infinity become null.

    Parameters
    ----------
    data : object
        JSON-ready values (numpy scalars and arrays, DataFrames and paths are converted).
    path : str or path
        The file written (UTF-8).
    """
    Path(path).write_text(json.dumps(_clean(data), indent=2, ensure_ascii=False) + "\n", encoding="utf-8")


#: An absolute path in text (POSIX form): a slash-separated run not preceded by a word, a URL or a
#: fraction ("km/h", "1/yr" and "http://..." are left alone).
_ABSOLUTE_PATH = re.compile(r"(?<![\w.:/&;+=,<~-])/(?:[\w.-]+/)+[\w.-]+")


def shown_path(path, base) -> str:
    """``path`` as written in outputs: relative to ``base`` (the site file's folder) when it lies there; a file
    of the installed package (bundled data, shipped scenarios) as its name inside the package
    (``riskrf/data/NAME``); anything else relative to ``base`` (with ``..``), never the machine's absolute path.

    Parameters
    ----------
    path : str or path
        The path to show.
    base : str or path
        The folder paths are relative to.

    Returns
    -------
    str
        POSIX form.
    """
    p = Path(os.path.abspath(str(path)))
    base = Path(os.path.abspath(str(base)))
    if p.is_relative_to(base):
        return p.relative_to(base).as_posix()
    root = Path(__file__).resolve().parents[2]           # the folder holding riskrf/ and simulation/
    if p.is_relative_to(root):
        return p.relative_to(root).as_posix()
    return Path(os.path.relpath(p, base)).as_posix()


def relative_paths(value, base):
    """``value`` (text, or a dict/list of them, e.g. a JSON summary) with every absolute path in its text
    written by :func:`shown_path` relative to ``base``; other values unchanged.

    Parameters
    ----------
    value : object
        Text, or nested dicts and lists holding text.
    base : str or path
        The folder paths are made relative to.

    Returns
    -------
    object
        The same structure with paths rewritten.
    """
    if isinstance(value, str):
        return _ABSOLUTE_PATH.sub(lambda m: shown_path(m.group(0), base), value)
    if isinstance(value, Path):
        return shown_path(value, base) if value.is_absolute() else value.as_posix()
    if isinstance(value, dict):
        return {k: relative_paths(v, base) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [relative_paths(v, base) for v in value]
    return value


def relative_paths_in_json_files(folder, base, *, skip=("inputs",)) -> None:
    """Rewrite every ``*.json`` below ``folder`` with :func:`relative_paths` (base: the site file's folder), so
    that no output names a directory of the machine it ran on.  Subfolders named in ``skip`` (the copy of the
    inputs and the command as typed, kept for exact reruns) are left as they are.

    Parameters
    ----------
    folder : str or path
        The output folder.
    base : str or path
        The site file's folder.
    skip : tuple of str
        Subfolders left alone.
    """
    for path in sorted(Path(folder).rglob("*.json")):
        if set(path.relative_to(folder).parts[:-1]) & set(skip):
            continue
        data = json.loads(path.read_text(encoding="utf-8"))
        fixed = relative_paths(data, base)
        if fixed != data:
            write_json(fixed, path)
