"""Reading tables as practitioners export them: one set of rules for every table riskrf reads.

The rules (also in the documentation, File formats, "Input formats"):

* **Files**: CSV/TXT/TSV, Excel (``.xlsx``/``.xlsm``; ``sheet`` by name or 1-based number,
  ``header_row`` the 1-based spreadsheet row holding the column names) and Parquet.
* **Separator**: the most frequent of ``;``, tab, ``|`` and ``,`` on the header line.
* **Encoding**: UTF-8 with or without a byte-order mark; a file that is not valid UTF-8 is
  read as Windows-1252 (cp1252, the Western-European Excel default) and a note says so.
  ``encoding`` overrides.
* **Numbers** (:func:`parse_numbers`): the decimal mark is decided per column: a value
  holding both ``.`` and ``,`` decides (the last one is the decimal mark, the other the
  thousands separator); otherwise a column whose values use only commas has decimal commas
  and one whose values use only dots has decimal points; a column mixing ``1,5`` and
  ``1.192`` is refused (pass ``decimal``).  Commas followed by exactly three digits are
  ambiguous (``146,402``: US thousands or a European decimal): a column holding
  ``1,234,567`` reads them as thousands; a column where every comma is one followed by
  three digits is refused unless ``decimal`` says which.  Apostrophes and spaces as thousands
  separators (``1'192.5``, ``1 192,5``) are removed.
* **Dates** (:func:`parse_dates`): ``YYYY-MM-DD`` (ISO), ``DD.MM.YYYY`` (dots are
  always day first), a four-digit year alone, and month names are unambiguous.
  ``NN/NN/YYYY`` (or ``NN-NN-YYYY``) takes one order for the whole file: day first when
  some first number exceeds 12, month first when some second number does; a file where
  no value decides, or where both occur, is refused unless ``date_format`` (a
  ``strftime`` pattern such as ``"%d/%m/%Y"``) is given, which then applies to every
  date of the file.  A time of day after the date is ignored.  A file is never read
  partly day-first and partly month-first.
"""
from __future__ import annotations

import re
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd

TEXT_SUFFIXES = (".csv", ".txt", ".tsv")
EXCEL_SUFFIXES = (".xlsx", ".xlsm")
DELIMITERS = (";", "\t", "|", ",")


def _header_line(text: str, header_row: int | None) -> str:
    lines = text.splitlines()
    i = (header_row or 1) - 1
    return lines[i] if i < len(lines) else ""


def sniff_delimiter(path, *, encoding: str | None = None, header_row: int | None = None) -> str:
    """The most frequent of ``;``, tab, ``|`` and ``,`` on the header line (outside quotes); ``,`` when none.

    Parameters
    ----------
    path : str or path
        A text table.
    encoding : str, optional
        Its encoding (default: detected, as :func:`read_table` does).
    header_row : int, optional
        1-based line of the header (default: the first non-empty line).

    Returns
    -------
    str
        The delimiter.
    """
    return _sniff_text(_decode(Path(path).read_bytes()[:65536], encoding, path)[0], header_row)


def _sniff_text(text: str, header_row: int | None) -> str:
    line = re.sub(r'"[^"]*"', "", _header_line(text, header_row))
    counts = {d: line.count(d) for d in DELIMITERS}
    best = max(DELIMITERS, key=lambda d: counts[d])
    return best if counts[best] else ","


#: Openings of binary files a table reader may be handed by mistake: zip (xlsx), Parquet, PDF, PNG, ELF, gzip,
#: OLE (xls), GIF, JPEG, TIFF.
_BINARY_MAGIC = (b"PK\x03\x04", b"PAR1", b"%PDF", b"\x89PNG", b"\x7fELF", b"\x1f\x8b", b"\xd0\xcf\x11\xe0",
                 b"GIF8", b"\xff\xd8\xff", b"II*\x00", b"MM\x00*")


def _looks_binary(sample: bytes) -> bool:
    """A binary file, not text: a known binary opening, or control characters (other than tab, line ends and
    form feed) in more than 1 % of the bytes once NUL bytes are set aside.  NUL padding alone does not make a
    file binary: the real Hong Kong CEDD register export pads rows with runs of NUL bytes."""
    if sample.startswith(_BINARY_MAGIC):
        return True
    if sample.startswith((b"\xff\xfe", b"\xfe\xff")):        # UTF-16 text holds NUL bytes by design
        return False
    text = sample.replace(b"\x00", b"")
    if not text.strip():
        return bool(sample)
    control = sum(text.count(bytes([c])) for c in range(32) if c not in (9, 10, 12, 13))
    return control > 0.01 * len(text)


def _decode(data: bytes, encoding: str | None, path=None) -> tuple[str, str]:
    if _looks_binary(data[:65536]):
        raise ValueError(f"{path or 'the file'}: is a binary file, not a text table (an Excel "
                         "workbook needs the .xlsx suffix, a Parquet file .parquet)")
    if encoding:
        try:
            return data.decode(encoding), encoding
        except (UnicodeDecodeError, LookupError) as exc:
            raise ValueError(f"{path or 'the file'}: cannot read as {encoding} text ({exc}); pass the file's "
                             "encoding (CLI --encoding)") from None
    try:
        return data.decode("utf-8-sig"), "utf-8"
    except UnicodeDecodeError as exc:
        if exc.start >= len(data) - 3 and len(data) == 65536:     # a sample cut inside a character
            return data[:exc.start].decode("utf-8-sig"), "utf-8"
        return data.decode("cp1252", errors="replace"), "cp1252"


def _check_row(header_row, path):
    if header_row is None:
        return None
    if isinstance(header_row, bool) or not isinstance(header_row, (int, np.integer)) or header_row < 1:
        raise ValueError(f"{path}: header_row = {header_row!r} must be a row number >= 1 (1 = the first row)")
    return int(header_row)


def read_table(path, *, sheet=None, header_row: int | None = None, encoding: str | None = None,
               what: str = "table", comment: str | None = None) -> tuple[pd.DataFrame, int, list]:
    """Read a CSV, Excel or Parquet file with every cell as text (missing cells are ``""``).

    Returns ``(table, first_row, notes)``: ``first_row`` is the file line (spreadsheet row)
    of the first data row, so that row ``i`` of the table is line ``first_row + i``
    (Parquet rows count from 1).  Raises ``ValueError`` naming the file for anything unreadable.
    ``comment`` (text files): lines starting with it (after blanks) are read as empty rows,
    so line numbers stay the file's; without ``header_row`` the header is then the first
    line that is neither empty nor a comment.

    Parameters
    ----------
    path : str or path
        CSV/TXT (any of ``;``, tab, ``|``, ``,``), Excel (.xlsx, .xls) or Parquet file.
    sheet : str or int, optional
        Excel sheet (default: the first).
    header_row : int, optional
        1-based line (spreadsheet row) of the header.
    encoding : str, optional
        Text encoding (default: UTF-8, a byte-order mark skipped; cp1252 when the file is not UTF-8).
    what : str
        What the table is, for messages (``"inventory"``, ``"velocity"`` ...).
    comment : str, optional
        Comment marker of text files.

    Returns
    -------
    tuple of (pandas.DataFrame, int, list of str)
        The table (text cells), the file line of its first data row, and notes (e.g. the encoding used).
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{what} file not found: {path}")
    if path.is_dir():
        raise ValueError(f"{path} is a directory, not a {what} file")
    header_row = _check_row(header_row, path)
    suffix = path.suffix.lower()
    notes = []
    if suffix in TEXT_SUFFIXES:
        if sheet is not None:
            raise ValueError(f"{path}: sheet = {sheet!r} applies to Excel workbooks only")
        raw = path.read_bytes()
        text, used = _decode(raw, encoding, path)
        if comment:
            lines = text.splitlines()
            lines = ["" if ln.lstrip().startswith(comment) else ln for ln in lines]
            if header_row is None:
                header_row = next((i + 1 for i, ln in enumerate(lines) if ln.strip()), 1)
            text = "\n".join(lines) + "\n"
            sep = _sniff_text(text, header_row)
        if used == "cp1252" and not encoding:
            notes.append(f"{path}: not valid UTF-8; read as Windows-1252 (cp1252). Pass encoding= "
                         "(CLI --encoding) if that is wrong")
        n_lines = len(text.splitlines())
        if header_row is not None and header_row > n_lines:
            raise ValueError(f"{path}: header_row = {header_row} is beyond the file's {n_lines} line(s)")
        if not comment:
            sep = sniff_delimiter(path, encoding=used if used != "utf-8" else "utf-8-sig", header_row=header_row)
        try:
            import io
            table = pd.read_csv(io.StringIO(text), sep=sep, dtype=str, skip_blank_lines=False,
                                keep_default_na=False, skiprows=(header_row or 1) - 1)
        except (pd.errors.ParserError, pd.errors.EmptyDataError, ValueError, csv_error()) as exc:
            raise ValueError(f"{path}: cannot read as a {sep!r}-separated table: {exc}") from None
        first = (header_row or 1) + 1
    elif suffix in EXCEL_SUFFIXES:
        try:
            book = pd.ExcelFile(path)
        except (zipfile.BadZipFile, KeyError, ValueError, OSError) as exc:
            raise ValueError(f"{path}: cannot read as an Excel workbook ({type(exc).__name__}: {exc})") from None
        names = book.sheet_names
        if sheet is None:
            name = names[0]
        elif isinstance(sheet, (int, np.integer)) and not isinstance(sheet, bool) or \
                (isinstance(sheet, str) and sheet.isdigit() and sheet not in names):
            k = int(sheet)
            if not 1 <= k <= len(names):
                raise ValueError(f"{path}: sheet = {sheet!r} does not exist: the workbook has {len(names)} "
                                 f"sheet(s) {names} (sheets count from 1)")
            name = names[k - 1]
        elif sheet in names:
            name = sheet
        else:
            raise ValueError(f"{path}: sheet = {sheet!r} is not a sheet of the workbook; its sheets are {names}")
        try:
            table = pd.read_excel(book, sheet_name=name, header=(header_row or 1) - 1, dtype=object,
                                  keep_default_na=False)
        except (ValueError, IndexError) as exc:
            raise ValueError(f"{path}: sheet {name!r}: cannot read (header_row = {header_row}): {exc}") from None
        # Number cells stay numbers (their decimal mark is not text to interpret); dates become ISO text.
        table = table.apply(lambda c: c.map(_excel_cell))
        table.columns = [str(c).strip() for c in table.columns]
        return table.reset_index(drop=True), (header_row or 1) + 1, notes
        first = (header_row or 1) + 1
    elif suffix == ".parquet":
        if sheet is not None or header_row is not None:
            raise ValueError(f"{path}: sheet and header_row apply to Excel and text tables, not Parquet")
        from .outputs import require_pyarrow
        require_pyarrow(str(path), instead="or save the table as .csv or .xlsx")
        try:
            table = pd.read_parquet(path)
        except Exception as exc:      # pyarrow raises its own classes for corrupt files
            raise ValueError(f"{path}: cannot read as Parquet ({type(exc).__name__}: {exc})") from None
        table = table.astype(object).where(table.notna(), "").astype(str)
        first = 1
    else:
        raise ValueError(f"{path}: unsupported {what} format {suffix!r}; use .csv, .txt, .tsv, .xlsx or .parquet")
    table.columns = [str(c).strip() for c in table.columns]
    return table.reset_index(drop=True), first, notes


def _excel_cell(v):
    if v is None or (isinstance(v, float) and np.isnan(v)):
        return ""
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, (int, float, np.integer, np.floating)):
        return float(v)
    if hasattr(v, "isoformat"):
        return v.isoformat(sep=" ") if hasattr(v, "hour") else v.isoformat()
    return str(v)


def is_blank(table: pd.DataFrame) -> pd.Series:
    """Rows whose every cell is empty text.

    Parameters
    ----------
    table : pandas.DataFrame
        A table of text cells (:func:`read_table`).

    Returns
    -------
    pandas.Series of bool
    """
    return (table.astype(str).apply(lambda c: c.str.strip()) == "").all(axis=1)


def csv_error():
    """The csv module's error class (imported on demand), for ``except`` clauses around CSV reading.

    Returns
    -------
    type
        :class:`csv.Error`.
    """
    import csv
    return csv.Error


_THOUSANDS_JUNK = r"[\s\u00a0\u202f'’]"     # a pattern string: pyarrow runs it vectorised
_BOTH_COMMA_LAST = re.compile(r"^[+-]?\d{1,3}(\.\d{3})+,\d*([eE][+-]?\d+)?$")
_BOTH_DOT_LAST = re.compile(r"^[+-]?\d{1,3}(,\d{3})+\.\d*([eE][+-]?\d+)?$")


def _where(path, row, col):
    return f"{path}: row {row}, column {col!r}"


#: A number written with thousands separators: 1-3 leading digits (not a lone 0) and groups of three after commas.
_GROUPED_BY_COMMA = r"^[+-]?[1-9]\d{0,2}(,\d{3})+$"


def _comma_meaning(text, raw, has_comma, path, col, rows) -> str:
    """The decimal mark of a column whose numbers hold commas but no dots: ``","`` (decimal commas) or ``"."``
    (the commas separate thousands).

    ``146,402`` is 146.402 in a European export and 146402 in a US one; the file alone cannot tell when every
    comma is followed by exactly three digits.  A column holding a number with two or more commas
    (``1,234,567``) groups thousands, so all its commas do; a column where some comma is followed by other than
    three digits (``1,5``, ``0,125``) has decimal commas.  A column where every value is one comma followed by
    three digits is refused, naming the column and how to say which (never read silently as decimals: that
    would make masses 1,000 times too small).
    """
    commas = text[has_comma]
    grouped = commas.str.match(_GROUPED_BY_COMMA)
    several = commas.str.count(",") > 1
    fix = ("pass decimal='.' if the commas separate thousands (146,402 = 146402) or decimal=',' if they are "
           "decimal commas (146,402 = 146.402) (CLI --decimal, or decimal = ... in the sidecar [record] or the "
           "site file's [inventory])")
    if grouped.all():
        if several.any():
            return "."
        i = commas.index[0]
        raise ValueError(f"{path}: column {col!r}: every number with a comma has exactly three digits after it "
                         f"(such as {raw[i]!r}, row {rows[i]}): thousands separators or decimal commas?  {fix}")
    if several.any():
        i, j = several.idxmax(), (~grouped).idxmax()
        raise ValueError(f"{_where(path, rows[i], col)}: {raw[i]!r} separates thousands with commas, but row "
                         f"{rows[j]} ({raw[j]!r}) has a decimal comma; the column is ambiguous: {fix}")
    return ","


def parse_numbers(raw: pd.Series, path, col: str, rows, *, decimal: str | None = None,
                  errors: str = "raise") -> pd.Series:
    """Numbers from text cells with the decimal-mark rule of this module; ``""`` gives NaN.

    ``rows`` holds the file line of each cell, for messages.  Raises ``ValueError`` naming the
    file, row, column and value of the first cell that is not a number; with
    ``errors="coerce"`` such cells give NaN instead (a column mixing decimal marks is
    still refused: that is a property of the file, not of one cell).

    Parameters
    ----------
    raw : pandas.Series
        Text cells.
    path : str or path
        The file, for messages.
    col : str
        The column, for messages.
    rows : array_like of int
        File line of each cell.
    decimal : {".", ","}, optional
        Decimal mark, when the file's is known; default: decided from the column.
    errors : {"raise", "coerce"}
        What a cell that is not a number does.

    Returns
    -------
    pandas.Series
        Floats (unit as written in the file), NaN for empty cells.
    """
    if errors not in ("raise", "coerce"):
        raise ValueError(f"errors = {errors!r} is not 'raise' or 'coerce'")
    if decimal not in (None, ".", ","):
        raise ValueError(f"decimal = {decimal!r} is not '.' or ','")
    if pd.api.types.is_numeric_dtype(raw) and not pd.api.types.is_bool_dtype(raw):
        return pd.to_numeric(raw).astype(float)
    if pd.api.types.infer_dtype(raw, skipna=True) in ("string", "empty"):
        is_num = pd.Series(False, index=raw.index)
    else:     # Excel: number cells are numbers, not text to interpret
        is_num = raw.map(lambda v: isinstance(v, (float, int, np.floating, np.integer)) and not isinstance(v, bool))
    text = raw.where(~is_num, "").astype(str).str.strip()
    text = text.str.replace(_THOUSANDS_JUNK, "", regex=True)
    has_comma = text.str.contains(",", regex=False)
    has_dot = text.str.contains(".", regex=False)
    if decimal is None:
        both = has_comma & has_dot
        comma_last = text[both].str.match(_BOTH_COMMA_LAST)
        dot_last = text[both].str.match(_BOTH_DOT_LAST)
        if comma_last.any() and not dot_last.any():
            decimal = ","
        elif dot_last.any() and not comma_last.any():
            decimal = "."
        elif comma_last.any() and dot_last.any():
            i = dot_last.index[dot_last][0] if comma_last.index[comma_last][0] < dot_last.index[dot_last][0] \
                else comma_last.index[comma_last][0]
            raise ValueError(f"{_where(path, rows[i], col)}: {raw[i]!r} uses a different decimal mark from the "
                             "rows above; pass decimal='.' or ',' (CLI --decimal)")
        elif has_comma.any() and has_dot.any():
            first_comma, first_dot = has_comma.idxmax(), has_dot.idxmax()
            i = max(first_comma, first_dot)
            raise ValueError(f"{_where(path, rows[i], col)}: {raw[i]!r} uses a decimal mark ('{'.' if i == first_dot else ','}') "
                             f"different from row {rows[min(first_comma, first_dot)]} "
                             f"({raw[min(first_comma, first_dot)]!r}); the column is ambiguous: pass "
                             "decimal='.' or ',' (CLI --decimal)")
        elif has_comma.any():
            decimal = _comma_meaning(text, raw, has_comma, path, col, rows)
        else:
            decimal = "."
    if decimal == ",":
        text = text.str.replace(".", "", regex=False).str.replace(",", ".", regex=False)
    else:
        text = text.str.replace(",", "", regex=False)
    values = pd.to_numeric(text.where(text != "", np.nan), errors="coerce")
    if is_num.any():
        values = values.astype(float)
        values[is_num] = raw[is_num].astype(float)
    bad = values.isna() & (text != "") & ~is_num
    lowered = text.str.lower()
    bad |= lowered.isin(["nan", "+nan", "-nan"])
    if errors == "coerce":
        return values.astype(float).where(~bad, np.nan)
    if bad.any():
        i = bad.idxmax()
        raise ValueError(f"{_where(path, rows[i], col)}: {raw[i]!r} is not a number")
    return values.astype(float)


def read_numeric_table(path, *, decimal: str | None = None, numeric=(), **kwargs) -> pd.DataFrame:
    """:func:`read_table`, with every column whose filled cells are all numbers (by the decimal-mark rule)
    converted to float; other columns stay text.  Rows wholly empty are dropped; the index holds each
    row's file line (spreadsheet row; Parquet rows count from 1).  Columns named in ``numeric`` must be
    numbers: the first cell that is not raises ``ValueError`` naming the file, row, column and value.

    Parameters
    ----------
    path : str or path
        The table file.
    decimal : {".", ","}, optional
        Decimal mark, when known.
    numeric : collection of str
        Columns that must be numbers.
    **kwargs
        Passed to :func:`read_table`.

    Returns
    -------
    pandas.DataFrame
        Numeric columns as float, others as text; indexed by file line.
    """
    table, first, _ = read_table(path, **kwargs)
    rows = np.arange(len(table)) + first
    keep = ~is_blank(table).to_numpy() if len(table) else np.ones(0, bool)
    table, rows = table[keep].reset_index(drop=True), rows[keep]
    out = {}
    for col in table.columns:
        try:
            out[col] = parse_numbers(table[col], path, col, rows, decimal=decimal).to_numpy()
        except ValueError:
            if col in numeric:
                raise
            out[col] = table[col].to_numpy()
    return pd.DataFrame(out, index=pd.Index(rows, name="row"))


_YEAR = re.compile(r"^(\d{4})(?:\.0)?$")
_YMD = re.compile(r"^(\d{4})[-/.](\d{1,2})[-/.](\d{1,2})(?:[ T].*)?$")
_DMY_DOT = re.compile(r"^(\d{1,2})\.(\d{1,2})\.(\d{4})(?:[ T].*)?$")
_NN_YEAR = re.compile(r"^(\d{1,2})[/-](\d{1,2})[/-](\d{4})(?:[ T].*)?$")


def _to_dates(year, month, day) -> pd.Series:
    return pd.to_datetime(pd.DataFrame({"year": year.astype(int), "month": month.astype(int),
                                        "day": day.astype(int)}), errors="coerce").astype("datetime64[ns]")


def parse_dates(raw: pd.Series, path, col: str, rows, *, date_format: str | None = None):
    """Dates and years from text cells by the date rule of this module.

    Raises ``ValueError`` naming the file, row, column and value for an unreadable or
    ambiguous date, or a date in the future.

    Parameters
    ----------
    raw : pandas.Series
        Text cells (ISO dates, day-first or month-first dates when unambiguous, years alone).
    path : str or path
        The file, for messages.
    col : str
        The column, for messages.
    rows : array_like of int
        File line of each cell.
    date_format : str, optional
        An explicit :func:`~datetime.datetime.strptime` format.

    Returns
    -------
    tuple of pandas.Series
        (dates, years): datetime64 (NaT for a year alone or an empty cell) and Int64 years.
    """
    # Dates repeat: parse each distinct value once (in order of first appearance, so that messages
    # name the first row holding a value) and spread the results over the rows.
    codes, uniques = pd.factorize(raw.astype(str), use_na_sentinel=False)
    if len(uniques) < len(raw):
        first = np.unique(codes, return_index=True)[1]
        sub = raw.iloc[first]
        d_u, y_u = parse_dates(sub.reset_index(drop=True), path, col, np.asarray(rows)[first],
                               date_format=date_format)
        dates = pd.Series(d_u.to_numpy()[codes], index=raw.index, dtype="datetime64[ns]")
        years = pd.Series(pd.array(y_u.to_numpy()[codes], dtype="Int64"), index=raw.index)
        return dates, years
    text = raw.astype(str).str.strip()
    years = pd.Series(pd.NA, index=text.index, dtype="Int64")
    dates = pd.Series(pd.NaT, index=text.index, dtype="datetime64[ns]")
    nonempty = text != ""
    year_only = text.str.match(_YEAR) & nonempty
    years[year_only] = text[year_only].str.slice(0, 4).astype(int)
    todo = nonempty & ~year_only
    hint = "(use YYYY-MM-DD, DD.MM.YYYY or a four-digit year, or give date_format, CLI --date-format)"
    if date_format is not None:
        if not isinstance(date_format, str) or "%" not in date_format:
            raise ValueError(f"date_format = {date_format!r} is not a strftime pattern such as '%d.%m.%Y'")
        got = pd.to_datetime(text[todo], format=date_format, errors="coerce")
        bad = got.isna()
        if bad.any():
            i = bad.idxmax()
            raise ValueError(f"{_where(path, rows[i], col)}: date {raw[i]!r} does not match date_format "
                             f"{date_format!r}")
        dates[todo] = got
    else:
        parts = {}
        for name, rx in (("ymd", _YMD), ("dot", _DMY_DOT), ("nn", _NN_YEAR)):
            m = text[todo].str.extract(rx)
            mask = m[0].notna()
            parts[name] = m[mask]
            todo_idx = todo.copy()
            todo_idx[mask.index[mask]] = False
            todo = todo_idx
        ymd, dot, nn = parts["ymd"], parts["dot"], parts["nn"]
        this_year = pd.Timestamp.today().year
        for part, col_year in ((ymd, 0), (dot, 2), (nn, 2)):
            late = part[col_year].astype(int) > this_year
            if late.any():
                i = late.idxmax()
                raise ValueError(f"{_where(path, rows[i], col)}: date {raw[i]!r} is in the future")
        if len(ymd):
            dates[ymd.index] = _to_dates(ymd[0], ymd[1], ymd[2]).to_numpy()
        if len(dot):
            dates[dot.index] = _to_dates(dot[2], dot[1], dot[0]).to_numpy()
        if len(nn):
            a, b = nn[0].astype(int), nn[1].astype(int)
            day_first, month_first = a > 12, b > 12
            if day_first.any() and month_first.any():
                i = max(day_first.idxmax(), month_first.idxmax())
                j = min(day_first.idxmax(), month_first.idxmax())
                raise ValueError(f"{_where(path, rows[i], col)}: date {raw[i]!r} can only be month first, but "
                                 f"row {rows[j]} ({raw[j]!r}) can only be day first; a file must use one order "
                                 "(fix the rows or give date_format, CLI --date-format)")
            if not (day_first.any() or month_first.any()):
                i = nn.index[0]
                raise ValueError(f"{path}: column {col!r}: dates such as {raw[i]!r} (row {rows[i]}) are ambiguous: "
                                 "no value shows whether the day or the month comes first; give "
                                 "date_format='%d/%m/%Y' or '%m/%d/%Y' (CLI --date-format, sidecar date_format)")
            d, m = (a, b) if day_first.any() else (b, a)
            dates[nn.index] = _to_dates(nn[2], m, d).to_numpy()
        # Anything else: only spelled-out months are accepted (e.g. '5 March 2019').
        for i in text.index[todo]:
            s = text[i]
            stamp = pd.NaT
            if re.search(r"[A-Za-z]{3}", s):
                try:
                    stamp = pd.Timestamp(s)
                except (ValueError, TypeError, OverflowError):
                    stamp = pd.NaT
            if pd.isna(stamp):
                raise ValueError(f"{_where(path, rows[i], col)}: cannot read date {raw[i]!r} {hint}")
            dates[i] = stamp
        bad = nonempty & ~year_only & dates.isna()
        if bad.any():
            i = bad.idxmax()
            raise ValueError(f"{_where(path, rows[i], col)}: cannot read date {raw[i]!r} {hint}")
    has = dates.notna()
    years[has] = dates[has].dt.year.astype(int)
    today = pd.Timestamp.today().normalize()
    future = (has & (dates > today)) | (years.notna() & (years.fillna(0) > today.year))
    if future.any():
        i = future.idxmax()
        raise ValueError(f"{_where(path, rows[i], col)}: date {raw[i]!r} is in the future")
    return dates, years


__all__ = ["is_blank", "parse_dates", "parse_numbers", "read_table", "sniff_delimiter"]
