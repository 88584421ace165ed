"""Formatting for people: human column headers, table cells, and an HTML document with a table of contents and
numbered figures and tables.

Numbers are written by :mod:`riskrf.core.format` (``sig``, ``money``, ``probability``, re-exported here): 2-3
significant figures for estimated quantities, whole units with thousands separators for money, and never
Python's ``e+05`` notation.
"""
from __future__ import annotations

import base64
import html
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..core.format import money, probability, sig  # noqa: F401  (one home: riskrf.core.format)


def escape(text) -> str:
    """HTML-escaped text of any value (user text is never markup).

    Parameters
    ----------
    text : object
        Any value; ``str()`` of it is escaped.

    Returns
    -------
    str
    """
    return html.escape(str(text))


_UNIT_SUFFIXES = [
    ("_per_year", "[1/yr]"), ("_kj", "[kJ]"), ("_kg", "[kg]"), ("_m3", "[m³]"), ("_ms", "[m/s]"),
    ("_rads", "[rad/s]"), ("_years", "[yr]"), ("_yr", "[yr]"), ("_deg", "[°]"), ("_kmh", "[km/h]"),
    ("_m", "[m]"), ("_s", "[s]"), ("_pct", "[%]"),
]
_WORDS = {"ci": "CI", "sel": "SEL", "mel": "MEL", "mle": "MLE", "ks": "KS", "aic": "AIC", "fn": "F-N",
          "uni": "UNI", "gev": "GEV", "bcr": "BCR", "pv": "PV", "evpi": "EVPI", "p05": "5 %", "p95": "95 %",
          "p50": "median", "t": "T"}


def human_header(name: str) -> str:
    """A column name as a reader expects it: ``energy_kj`` -> "Energy [kJ]", ``T_years`` -> "T [yr]".

    Names that already read as text (with spaces or brackets) are returned unchanged.

    Parameters
    ----------
    name : str
        A column name with its unit as a suffix (``_kj``, ``_kg``, ``_m3``, ``_ms``, ``_per_year`` ...).

    Returns
    -------
    str
        Words with the unit in brackets.
    """
    name = str(name)
    if " " in name or "[" in name or "(" in name:
        return name
    unit = ""
    low = name.lower()
    for suffix, u in _UNIT_SUFFIXES:
        if low.endswith(suffix) and len(low) > len(suffix):
            name, unit = name[: -len(suffix)], u
            break
    words = [_WORDS.get(w.lower(), w) for w in re.split(r"_+", name) if w]
    if not words:
        return unit
    text = " ".join(words)
    text = text[0].upper() + text[1:]
    return f"{text} {unit}".strip()


#: Columns holding years, return periods or identifiers: whole numbers printed without thousands separators.
_PLAIN_INTEGER_COLUMN = re.compile(r"(^|_)(year|years|t_years|seed|block|id|row|vertex)$", re.IGNORECASE)


def plain_integer_column(name) -> bool:
    """Whether a column holds years or identifiers (printed "2020", "1000", never "2,020").

    Parameters
    ----------
    name : str
        Column name.

    Returns
    -------
    bool
    """
    return bool(_PLAIN_INTEGER_COLUMN.search(str(name)))


def cell(value, *, digits: int = 3, money_columns: bool = False, currency: str = "") -> str:
    """One table cell as text: numbers to ``digits`` significant figures (or money), booleans as yes/no,
    dictionaries and lists as readable text.

    Parameters
    ----------
    value : object
        The cell's value.
    digits : int
        Significant figures of numbers.
    money_columns : bool
        The cell is money: whole units with the currency.
    currency : str
        Currency label of money cells.

    Returns
    -------
    str
        Empty for None or NaN.
    """
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)) and not money_columns:
        return f"{int(value):,}"
    if isinstance(value, (float, np.floating, int, np.integer)):
        return money(value, currency) if money_columns else sig(value, digits)
    if isinstance(value, dict):
        return "; ".join(f"{k}: {cell(v, digits=digits)}" for k, v in value.items())
    if isinstance(value, (list, tuple)):
        return ", ".join(cell(v, digits=digits) for v in value)
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return str(value)


@dataclass
class Document:
    """An HTML document that numbers its figures and tables and builds its own table of contents.

    ``section(title)`` starts a numbered section; ``table(...)`` and ``figure(...)`` return HTML and
    the label ("Table 3", "Figure 5") to refer to from the text (``doc.next_table`` /
    ``doc.next_figure`` give the label before the element is added).
    """
    title: str
    parts: list = field(default_factory=list)
    sections: list = field(default_factory=list)
    n_tables: int = 0
    n_figures: int = 0
    n_sections: int = 0

    @property
    def next_table(self) -> str:
        """Label of the next table to be added, for references in the text."""
        return f"Table {self.n_tables + 1}"

    @property
    def next_figure(self) -> str:
        """Label of the next figure to be added, for references in the text."""
        return f"Figure {self.n_figures + 1}"

    def add(self, *fragments: str) -> None:
        """Append HTML fragments (empty ones are skipped).

        Parameters
        ----------
        *fragments : str
            HTML text, already escaped where it holds user text.
        """
        self.parts.extend(f for f in fragments if f)

    def section(self, title: str, appendix: str | None = None) -> None:
        """Start numbered section ``title``, or appendix ``appendix`` (listed in the table of contents).

        Parameters
        ----------
        title : str
            Plain text (escaped here).
        appendix : str, optional
            Appendix letter: the heading reads "Appendix A. title" and takes no number.
        """
        if appendix is None:
            self.n_sections += 1
            anchor, label = f"s{self.n_sections}", f"{self.n_sections}. {title}"
        else:
            anchor, label = f"app{appendix}", f"Appendix {appendix}. {title}"
        self.sections.append((anchor, label))
        self.parts.append(f"<h2 id='{anchor}'>{escape(label)}</h2>")

    def table(self, df: pd.DataFrame, caption: str, *, digits: int = 3, money_columns=(), currency: str = "",
              headers: dict | None = None, index: bool = False) -> str:
        """A numbered table: human headers with units, numbers to ``digits`` significant figures,
        ``money_columns`` as whole currency units.

        Parameters
        ----------
        df : pandas.DataFrame
            The table; column names with unit suffixes become headers with units (:func:`human_header`).
        caption : str
            Caption after "Table N.".
        digits : int
            Significant figures of numbers.
        money_columns : collection of str
            Columns shown as money.
        currency : str
            Currency label of money columns.
        headers : dict, optional
            Column name → header text, overriding :func:`human_header`.
        index : bool
            Show the index as the first column.

        Returns
        -------
        str
            HTML (empty for an empty table, which is not numbered).
        """
        if df is None or len(df) == 0:
            return ""
        self.n_tables += 1
        d = df.reset_index() if index else df
        headers = headers or {}
        cols = list(d.columns)
        head = "".join(f"<th>{escape(headers.get(c, human_header(c)))}</th>" for c in cols)
        rows = []
        for rec in d.itertuples(index=False):
            cells = []
            for c, v in zip(cols, rec):
                if plain_integer_column(c) and isinstance(v, (int, float, np.integer, np.floating)) \
                        and not isinstance(v, (bool, np.bool_)) and np.isfinite(v) and float(v).is_integer():
                    text = f"{int(v)}"              # a year or an identifier: 2020, not 2,020
                else:
                    text = cell(v, digits=digits, money_columns=c in money_columns, currency=currency)
                numeric = isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))
                cells.append(f"<td class='{'num' if numeric else 'txt'}'>{escape(text)}</td>")
            rows.append("<tr>" + "".join(cells) + "</tr>")
        return (f"<div class='table'><table id='t{self.n_tables}'><caption>Table {self.n_tables}. "
                f"{escape(caption)}</caption><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody>"
                "</table></div>")

    def figure(self, path: Path, caption: str) -> str:
        """A numbered figure embedded as a data URI (the report needs no network); empty if the file is absent.

        Parameters
        ----------
        path : path
            PNG file.
        caption : str
            Caption after "Figure N.".

        Returns
        -------
        str
            HTML ``<figure>`` (empty when the file is absent).
        """
        path = Path(path)
        if not path.exists():
            return ""
        self.n_figures += 1
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        return (f"<figure id='f{self.n_figures}'><img alt='{escape(caption)}' src='data:image/png;base64,{data}'>"
                f"<figcaption>Figure {self.n_figures}. {escape(caption)}</figcaption></figure>")

    def render(self, *, header: str = "", footer: str = "") -> str:
        """The whole page: head with viewport and print styles, title, table of contents, body.

        Parameters
        ----------
        header, footer : str
            HTML placed before the table of contents and after the body.

        Returns
        -------
        str
            A complete HTML document.
        """
        toc = "".join(f"<li><a href='#{a}'>{escape(t)}</a></li>" for a, t in self.sections)
        return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
                "<meta name='viewport' content='width=device-width, initial-scale=1'>"
                f"<title>{escape(self.title)}</title><style>{CSS}</style></head><body>"
                f"{header}<nav class='toc'><b>Contents</b><ol>{toc}</ol></nav>" + "\n".join(self.parts)
                + f"{footer}</body></html>")


CSS = """
body{font-family:Georgia,'Times New Roman',serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;
line-height:1.45}
h1{font-size:1.6em;border-bottom:2px solid #444;padding-bottom:.2em}
h2{font-size:1.3em;margin-top:2em;border-bottom:1px solid #aaa}h3{font-size:1.05em}
.table{overflow-x:auto;max-width:100%}
table{border-collapse:collapse;margin:.6em 0;font-size:.85em;font-family:Helvetica,Arial,sans-serif}
caption{caption-side:top;text-align:left;font-size:.95em;color:#333;padding:.2em 0;font-style:italic}
th,td{border:1px solid #ccc;padding:.25em .5em}th{background:#eee;text-align:left;vertical-align:bottom}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}td.txt{text-align:left}
.box{background:#f4f7fb;border:1px solid #9ab;padding:.8em 1.2em;margin:1em 0}
.warn{background:#fff6e5;border:1px solid #e0b060;padding:.6em 1.2em}
figure{margin:1em 0;text-align:center}figure img{max-width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:.85em;color:#555}.toc{border:1px solid #ccc;padding:.5em 1.2em;margin:1em 0;
background:#fafafa}.toc ol{margin:.3em 0;padding-left:1.5em}
.ok{color:#17692a;font-weight:bold}.fail{color:#a4161a;font-weight:bold}code{font-size:.9em;word-break:break-all}
@media (max-width:600px){body{margin:1em auto;padding:0 .6em;font-size:15px}h1{font-size:1.3em}
table{font-size:.75em}}
@media print{@page{size:A4;margin:18mm 15mm}body{max-width:none;margin:0;padding:0;font-size:10.5pt}
h2,h3{break-after:avoid;page-break-after:avoid}tr,figure,.box{break-inside:avoid;page-break-inside:avoid}
thead{display:table-header-group}.toc{break-after:page}a{color:inherit;text-decoration:none}
.table{overflow:visible}}
"""
