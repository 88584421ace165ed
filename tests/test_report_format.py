"""Numbers and tables as a reader sees them in the report (issue 15)."""
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
