"""Convert the Lauterbrunnen TLS rock fall volumes into riskrf inventory CSVs.

Reads the unmodified files in ``../shared/inventories-raw/lauterbrunnen-tls/``
(see PROVENANCE.md there) and writes, beside this script:

* ``lauterbrunnen_tls_2018.csv`` (+ ``.toml``): 317 volumes, 5.2-year record;
* ``lauterbrunnen_tls_2015.csv`` (+ ``.toml``): 122 volumes, 1.5-year record
  (Strunden et al. 2015).

Only the format changes: values are copied digit for digit.  Run from the
repository root: ``python inventories/lauterbrunnen/convert.py``.
"""
from __future__ import annotations

import csv
from pathlib import Path

HERE = Path(__file__).resolve().parent
RAW = HERE.parents[2] / "shared" / "inventories-raw" / "lauterbrunnen-tls"


def _rows_5yr():
    for line in (RAW / "rockfall_data_all.txt").read_text().splitlines():
        cells = [c.strip() for c in line.split("\t") if c.strip()]
        if cells:
            yield {"volume_m3": cells[0], "volume_uncertainty_m3": cells[1], "notes": ""}


def _rows_1yr():
    for line in (RAW / "rockfalls_Josy.dat").read_text().splitlines():
        if line.strip():
            yield {"volume_m3": line.strip(), "volume_uncertainty_m3": "", "notes": ""}


def _write(name: str, rows, years: float, label: str) -> None:
    rows = list(rows)
    with open(HERE / f"{name}.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, ["volume_m3", "volume_uncertainty_m3", "notes"])
        writer.writeheader()
        writer.writerows(rows)
    (HERE / f"{name}.toml").write_text(
        f"# Record period of {name}.csv ({label}); read by riskrf.read_inventory.\n"
        "[record]\n"
        f"duration_years = {years}\n"
        'site = "Lauterbrunnen Valley rock wall, Switzerland (TLS change detection)"\n'
    )
    print(f"{name}.csv: {len(rows)} rows, {years} years")


if __name__ == "__main__":
    _write("lauterbrunnen_tls_2018", _rows_5yr(), 5.2, "5.2-year TLS monitoring")
    _write("lauterbrunnen_tls_2015", _rows_1yr(), 1.5, "1.5-year TLS monitoring, Strunden et al. 2015")
