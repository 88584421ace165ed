"""Numbers and tables as a reader sees them in the report."""
from pathlib import Path

import pandas as pd
import pytest

from riskrf.report.format import Document, human_header, money, sig


@pytest.mark.parametrize("value, digits, text", [
    (3.044e5, 3, "304,000"), (3.044e5, 2, "300,000"), (0.00285, 2, "0.0029"), (2.9e-6, 2, "2.9 × 10⁻⁶"),
    (999.6, 3, "1,000"), (-1234.5, 3, "−1,230"), (0.5, 3, "0.5"), (50.5, 3, "50.5"), (0.0, 3, "0"),
    (float("nan"), 3, ""), (1e13, 2, "1 × 10¹³")])
def test_significant_figures_never_use_e_notation(value, digits, text):
    assert sig(value, digits) == text
    assert "e+" not in sig(value, digits) and "e-" not in sig(value, digits)


def test_money_has_thousands_separators_and_currency():
    assert money(1234567.8, "CHF") == "1,234,568 CHF"
    assert money(-2500, "EUR") == "−2,500 EUR"


@pytest.mark.parametrize("name, header", [("energy_kj", "Energy [kJ]"), ("T_years", "T [yr]"),
                                          ("road_falls_per_year", "Road falls [1/yr]"),
                                          ("velocity_ms", "Velocity [m/s]"), ("Already readable [kJ]",
                                                                              "Already readable [kJ]")])
def test_human_headers_carry_units(name, header):
    assert human_header(name) == header


def test_document_numbers_tables_and_figures_and_escapes_text(tmp_path):
    doc = Document("<b>site</b>")
    doc.section("Data & fits")
    assert doc.next_table == "Table 1"
    html_table = doc.table(pd.DataFrame({"option": ["<i>x</i>"], "cost": [1.5e6], "ok": [True]}), "Costs",
                           money_columns=("cost",), currency="CHF")
    assert "Table 1. Costs" in html_table and "1,500,000 CHF" in html_table and ">yes<" in html_table
    assert "<i>x</i>" not in html_table and "&lt;i&gt;x&lt;/i&gt;" in html_table
    assert doc.figure(tmp_path / "missing.png", "absent") == "" and doc.n_figures == 0
    page = doc.render()
    assert "name='viewport'" in page and "@media print" in page and "href='#s1'" in page
    assert "<b>site</b>" not in page


def test_money_rounds_uncertain_amounts_to_significant_figures():
    from riskrf.report.format import money
    assert money(775390, "CHF", sig=3) == "775,000 CHF"
    assert money(6271796, "CHF", sig=3) == "6,270,000 CHF"
    assert money(999_600, "CHF", sig=3) == "1,000,000 CHF"          # rounding carries into the next digit
    assert money(-1234.5, sig=2) == "−1,200"
    assert money(0.0, "CHF", sig=3) == "0 CHF"
    assert money(1_917_312, "CHF") == "1,917,312 CHF"                # typed amounts stay exact


def test_assumption_values_read_as_text():
    from riskrf.report.html import _field_label, _plain_text
    curve = "((10.0, 0.05), (100.0, 0.3), (1000.0, 0.7), (10000.0, 1.0))"
    assert _plain_text(curve, "consequences.vulnerability_moving_vehicle") == \
        "10 kg: 0.05; 100 kg: 0.3; 1,000 kg: 0.7; 10,000 kg: 1"
    assert _plain_text("size-dependent curve " + curve, "consequences.vulnerability_moving_vehicle") == \
        "size-dependent curve 10 kg: 0.05; 100 kg: 0.3; 1,000 kg: 0.7; 10,000 kg: 1"
    assert [_plain_text(t) for t in ("True", "False", "None", "'inventory'", "[2000.0, 5000.0]")] == \
        ["yes", "no", "not given", "inventory", "2,000; 5,000"]
    assert _field_label("hazard.free_board_m").endswith("[m]") and "." not in _field_label("rates.trend")


def test_pdf_waits_for_each_figure_not_yet_written_until_the_gate_opens(tmp_path):
    """report.pdf laid out beside the figures still being drawn (``riskrf assess``): the figures known to be
    written go in at once; each other one is waited for (``wait(path)``) until a wait says the gate is open
    (every figure written), and then none is; an absent figure is left out as before."""
    from PIL import Image

    from riskrf.report.pdf_layout import _Report
    for name in ("early.png", "drawn.png", "late.png", "later.png"):
        Image.new("RGB", (40, 20), "white").save(tmp_path / name)
    calls = []

    def wait(path):
        calls.append(Path(path).name)
        return Path(path).name == "absent.png"          # the gate opened while the PDF waited for it
    tb = {k: "x" for k in ("project", "site", "location", "revision", "date", "author", "checker", "client")}
    rep = _Report(tb, wait=wait, finished=[tmp_path / "early.png"])
    rep.pdf.add_page()
    rep.figure(tmp_path / "early.png", "written before")
    assert calls == []
    rep.figure(tmp_path / "drawn.png", "appeared while waiting")
    assert calls == ["drawn.png"]
    rep.figure(tmp_path / "absent.png", "never drawn")          # waits until the gate opens, then leaves it out
    rep.figure(tmp_path / "late.png", "drawn beside")
    rep.figure(tmp_path / "later.png", "drawn beside")
    assert calls == ["drawn.png", "absent.png"] and len(rep.pdf.image_cache.images) == 4
