"""The machinery of report.pdf: fonts, the A4 page with its title block, tables, figures, contents, numbers.

:class:`_Report` is the fpdf2 document every section of :mod:`riskrf.report.pdf` writes into: header and footer
with the title block (:func:`title_block`, from the site file's ``[report]`` table) and "page X of N", numbered
sections in the outline, captioned tables that fit the A4 text width and figures scaled to the page.
:func:`_toc` prints the table of contents.  :func:`fmt`, :func:`year` and :func:`pct` write the numbers of the
PDF's engineering tables.

Text is set in DejaVu Sans, the font matplotlib ships (:func:`_font_paths`), so Greek letters and symbols print on
any machine; :func:`_remember_text_widths` makes fpdf2's line breaking measure each text once.
"""
from __future__ import annotations

import datetime
import math
from pathlib import Path

import numpy as np

from .format import cell, human_header


A4_TEXT_WIDTH_MM = 180.0


def _font_paths():
    import matplotlib
    d = Path(matplotlib.get_data_path()) / "fonts" / "ttf"
    return d / "DejaVuSans.ttf", d / "DejaVuSans-Bold.ttf", d / "DejaVuSans-Oblique.ttf"


def fmt(v, digits: int = 3, *, thousands: bool = True) -> str:
    """A number for an engineering table: ``digits`` significant figures, thousands separators for large values
    (never for years or identifiers: pass ``thousands=False`` or use :func:`year`), "n/a" for NaN/None.

    Parameters
    ----------
    v : float, bool, str or None
        The value (text is returned as it is, None as "").
    digits : int
        Significant figures.
    thousands : bool
        Thousands separators for large values.

    Returns
    -------
    str
    """
    if v is None or isinstance(v, str):
        return "" if v is None else v
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    x = float(v)
    if not math.isfinite(x):
        return "n/a" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    if mag >= digits - 1:
        r = int(round(x, -(mag - digits + 1)))          # no more figures than ``digits``
        return f"{r:,}" if thousands else f"{r}"
    if abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{max(digits - 1 - mag, 0)}f}"


def year(v) -> str:
    """A year or return period: an integer without thousands separator.

    Parameters
    ----------
    v : float or None
        The year or return period [yr].

    Returns
    -------
    str
        "n/a" for None or NaN.
    """
    return "n/a" if v is None or not np.isfinite(float(v)) else f"{float(v):.0f}"


def pct(v, digits: int = 1) -> str:
    """A share [-] as a percentage.

    Parameters
    ----------
    v : float or None
        The share [-].
    digits : int
        Decimals of the percentage.

    Returns
    -------
    str
        E.g. "12.5 %"; "n/a" for None or NaN.
    """
    return "n/a" if v is None or not np.isfinite(float(v)) else f"{100 * float(v):.{digits}f} %"


def _remember_text_widths(pdf) -> None:
    """Make the document's fonts measure a text from the width of the same text one character shorter.

    fpdf2's line breaking measures each line again as every character is added (the text so far, summed glyph by
    glyph), so a paragraph or table cell of n characters costs about n^2 / 2 glyph look-ups: most of the time of
    the report's PDF.  The widths are kept per font and text for this document, so each measurement adds one
    glyph to the one before.  The glyph widths are whole numbers of font units, so the sums, and the PDF, are
    the same as fpdf2's own.
    """
    from fpdf.fonts import TTFFont

    widths: dict = {}

    class _Widths(TTFFont):
        __slots__ = ()        # the layout of TTFFont, so that the document's font objects can take this class

        def get_text_width(self, text, font_size_pt, text_shaping_params):
            if text_shaping_params or self.is_symbol or not text:
                return super().get_text_width(text, font_size_pt, text_shaping_params)
            if font_size_pt > self.biggest_size_pt:
                self.biggest_size_pt = font_size_pt
            key = (self.fontkey, text)
            units = widths.get(key)
            if units is None:
                shorter = widths.get((self.fontkey, text[:-1]))
                units = shorter + self.cw[ord(text[-1])] if shorter is not None else \
                    sum(self.cw[ord(c)] for c in text)
                widths[key] = units
            return len(text), units * font_size_pt * 0.001

    for font in pdf.fonts.values():
        if type(font) is TTFFont:
            font.__class__ = _Widths


class _Report:
    """fpdf2 document with the title block in the footer and header, sections registered for the contents."""

    def __init__(self, title_block: dict, *, wait=None, finished=None):
        from fpdf import FPDF

        # figures drawn beside this work: wait(path) before each figure not known to be finished, until it says
        # the gate is open (every figure written)
        self._wait = wait
        self._finished = {str(Path(f).resolve()) for f in (finished or ())}

        tb = title_block

        class Doc(FPDF):
            def header(self):
                if self.page_no() == 1:
                    return
                self.set_font("DejaVu", "", 7.5)
                self.set_text_color(90)
                self.cell(0, 4, f"{tb['project']} - {tb['site']}", align="L")
                self.set_x(self.l_margin)
                self.cell(0, 4, f"revision {tb['revision']}, {tb['date']}", align="R",
                          new_x="LMARGIN", new_y="NEXT")
                self.line(self.l_margin, self.get_y() + 0.5, self.w - self.r_margin, self.get_y() + 0.5)
                self.ln(3)
                self.set_text_color(0)

            def footer(self):
                self.set_y(-12)
                self.set_font("DejaVu", "", 7.5)
                self.set_text_color(90)
                self.cell(0, 5, f"author {tb['author']}; checker {tb['checker']}", align="L")
                self.set_x(self.l_margin)
                self.cell(0, 5, f"page {self.page_no()} of {{nb}}", align="R")
                self.set_text_color(0)

        pdf = Doc(format="A4", unit="mm")
        regular, bold, italic = _font_paths()
        pdf.add_font("DejaVu", "", str(regular))
        pdf.add_font("DejaVu", "B", str(bold))
        pdf.add_font("DejaVu", "I", str(italic))
        _remember_text_widths(pdf)
        pdf.set_margins(15, 15, 15)
        pdf.set_auto_page_break(True, margin=16)
        pdf.alias_nb_pages()
        pdf.set_font("DejaVu", "", 9.5)
        self.pdf = pdf
        self.section_no = 0
        self.fresh_page = False

    # -- building blocks ------------------------------------------------------------------------------
    def section(self, title: str, *, new_page: bool = True, appendix: str | None = None):
        pdf = self.pdf
        if new_page and not self.fresh_page:
            pdf.add_page()
        self.fresh_page = False
        if appendix is None:
            self.section_no += 1
            label = f"{self.section_no}. {title}"
        else:
            label = f"Appendix {appendix}. {title}"
        pdf.start_section(label, level=0)
        pdf.set_font("DejaVu", "B", 13)
        pdf.multi_cell(0, 7, label, new_x="LMARGIN", new_y="NEXT")
        pdf.ln(1.5)
        pdf.set_font("DejaVu", "", 9.5)

    def heading(self, title: str):
        """A bold heading outside the outline (the title page's)."""
        self.pdf.set_font("DejaVu", "B", 10.5)
        self.pdf.multi_cell(0, 6, title, new_x="LMARGIN", new_y="NEXT")
        self.pdf.set_font("DejaVu", "", 9.5)

    def caption(self, text: str):
        """The caption of the table that follows (the same words as the HTML table's caption)."""
        pdf = self.pdf
        if pdf.get_y() > pdf.h - 40:
            pdf.add_page()
        pdf.set_font("DejaVu", "I", 8)
        pdf.multi_cell(0, 4, text, new_x="LMARGIN", new_y="NEXT")
        pdf.set_font("DejaVu", "", 9.5)

    def frame(self, df, caption: str, *, widths=None, size: float = 7.5, digits: int = 3, align=None):
        """A DataFrame as a captioned table: column names as words with units, cells as in the HTML report."""
        if df is None or len(df) == 0:
            return
        self.caption(caption)
        rows = [[cell(v, digits=digits) for v in rec] for rec in df.itertuples(index=False)]
        self.table([human_header(str(c)) for c in df.columns], rows, widths=widths, size=size, align=align)

    def figures(self, figs, section, max_height: float = 110.0):
        """The section's figures (:attr:`riskrf.report.sections.Section.figures`) that exist."""
        for name, cap in section.figures:
            self.figure(Path(figs) / name, cap, max_height=max_height)

    def sub(self, title: str):
        pdf = self.pdf
        if pdf.get_y() > pdf.h - 45:
            pdf.add_page()
        pdf.start_section(title, level=1)
        pdf.set_font("DejaVu", "B", 10.5)
        pdf.multi_cell(0, 6, title, new_x="LMARGIN", new_y="NEXT")
        pdf.set_font("DejaVu", "", 9.5)

    def text(self, s: str, size: float = 9.5, style: str = ""):
        self.pdf.set_font("DejaVu", style, size)
        self.pdf.multi_cell(0, 4.6, s, new_x="LMARGIN", new_y="NEXT")
        self.pdf.ln(1.2)
        self.pdf.set_font("DejaVu", "", 9.5)

    def table(self, header, rows, widths=None, size: float = 8.0, align=None):
        """A table that fits the A4 text width: ``header`` plain-language column names, ``rows`` of strings."""
        pdf = self.pdf
        pdf.set_font("DejaVu", "", size)
        n = len(header)
        widths = widths or [1] * n
        total = float(sum(widths))
        cw = tuple(A4_TEXT_WIDTH_MM * w / total for w in widths)
        from fpdf.fonts import FontFace
        head = FontFace(emphasis="BOLD", fill_color=(225, 228, 235))
        with pdf.table(col_widths=cw, width=A4_TEXT_WIDTH_MM, headings_style=head, line_height=1.35 * size * 0.3528 + 1,
                       text_align=align or ["LEFT"] + ["RIGHT"] * (n - 1), first_row_as_headings=True,
                       borders_layout="HORIZONTAL_LINES") as t:
            r = t.row()
            for h in header:
                r.cell(str(h))
            for row in rows:
                r = t.row()
                for c in row:
                    r.cell(str(c))
        pdf.ln(2)
        pdf.set_font("DejaVu", "", 9.5)

    def kv(self, pairs, widths=(2, 3), size: float = 8.5):
        self.table(["item", "value"], [[k, v] for k, v in pairs], widths=list(widths), size=size,
                   align=["LEFT", "LEFT"])

    def figure(self, path, caption: str, width: float = A4_TEXT_WIDTH_MM, max_height: float = 200.0):
        path = Path(path)
        if self._wait is not None and str(path.resolve()) not in self._finished and self._wait(path):
            self._wait = None
        if not path.exists():
            return
        pdf = self.pdf
        from PIL import Image
        with Image.open(path) as im:
            w_px, h_px = im.size
        h = width * h_px / w_px
        if h > max_height:
            width, h = width * max_height / h, max_height
        if pdf.get_y() + h + 12 > pdf.h - 16:
            pdf.add_page()
        x = pdf.l_margin + (A4_TEXT_WIDTH_MM - width) / 2
        pdf.image(str(path), x=x, w=width)
        pdf.set_font("DejaVu", "I", 8)
        pdf.multi_cell(0, 4, caption, new_x="LMARGIN", new_y="NEXT")
        pdf.ln(2)
        pdf.set_font("DejaVu", "", 9.5)


def _toc(pdf, outline):
    pdf.set_font("DejaVu", "B", 13)
    pdf.set_x(pdf.l_margin)
    pdf.cell(A4_TEXT_WIDTH_MM, 8, "Contents", new_x="LMARGIN", new_y="NEXT")
    pdf.ln(2)
    for s in outline:
        pdf.set_font("DejaVu", "" if s.level else "B", 9.5 if s.level == 0 else 8.5)
        indent = 6 * s.level
        pdf.set_x(pdf.l_margin + indent)
        name = s.name if len(s.name) < 86 else s.name[:83] + "..."
        pdf.cell(A4_TEXT_WIDTH_MM - indent - 15, 5.2, name, link=pdf.add_link(page=s.page_number))
        pdf.cell(15, 5.2, str(s.page_number), align="R", new_x="LMARGIN", new_y="NEXT")


def title_block(site, now: datetime.date | None = None) -> dict:
    """The title-block fields from the site file's ``[report]`` table, with their defaults.

    Parameters
    ----------
    site : Site
        The site (its ``report`` record, :data:`riskrf.core.file_schemas.SITE_RECORDS`, and its name).
    now : datetime.date, optional
        Date used when the table gives none (default: today).

    Returns
    -------
    dict
        ``project``, ``site``, ``location``, ``revision``, ``date``, ``author``, ``checker``, ``client``.
    """
    r = site.report
    d = r.date
    return {"project": str(r.project or site.name), "site": site.name,
            "location": str(r.location or "not stated"), "revision": str(r.revision or "A"),
            "date": str(d) if d is not None else (now or datetime.date.today()).isoformat(),
            "author": str(r.author or "not stated"), "checker": str(r.checker or "not stated"),
            "client": str(r.client or "not stated")}


__all__ = ["A4_TEXT_WIDTH_MM", "fmt", "pct", "title_block", "year"]
