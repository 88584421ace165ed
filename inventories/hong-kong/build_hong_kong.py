"""Build the Hong Kong rock-cut inventory and the daily rainfall file from the raw government records.

Reads, unmodified, from ``<raw>`` (default ``../shared/inventories-raw/hong-kong-cedd`` beside the
repository; see PROVENANCE.md there):

- ``cedd_incidents_1984_2020.csv``: the CEDD/GEO slope incident register 1984-2020;
- ``hko_daily_rainfall_1884_2022.csv``: daily total rainfall at the Hong Kong Observatory.

Writes beside this script:

- ``hong_kong_rock_cuts_1984_2020.csv`` + ``.toml``: the 445 incidents on man-made rock cuts
  (FEATTYPE "Rock Cut"/"Rock cut") through :func:`riskrf.io.records.read_cedd_incidents`;
- ``hko_daily_rainfall_1983_2020.csv``: the Observatory's daily totals 1983-01-01 .. 2020-12-31
  in riskrf's generic rainfall format (``date,rainfall_mm,note``), read through
  :func:`riskrf.io.rainfall.read_rainfall` ("Trace" = 0 mm, flagged in ``note``).

Run from the repository root: ``python inventories/hong-kong/build_hong_kong.py [--raw DIR]``.
Rerunning reproduces the files byte for byte.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

from riskrf.io.rainfall import read_rainfall  # noqa: E402
from riskrf.io.records import read_cedd_incidents  # noqa: E402

RAW = HERE.parents[2] / "shared" / "inventories-raw" / "hong-kong-cedd"
RECORD_START, RECORD_END = "1984-01-01", "2020-12-31"
RAIN_START, RAIN_END = "1983-01-01", "2020-12-31"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--raw", type=Path, default=RAW, help=f"folder of the raw files (default {RAW})")
    args = parser.parse_args(argv)
    extract = read_cedd_incidents(args.raw / "cedd_incidents_1984_2020.csv", feature_type="rock cut")
    csv = HERE / "hong_kong_rock_cuts_1984_2020.csv"
    extract.table.to_csv(csv, index=False, lineterminator="\n")
    csv.with_suffix(".toml").write_text(
        "# Record period of hong_kong_rock_cuts_1984_2020.csv; read by riskrf.read_inventory.\n"
        "# No density was recorded: riskrf uses its default 2650 kg/m3 and says so.\n"
        "[record]\n"
        f'start = "{RECORD_START}"\n'
        f'end = "{RECORD_END}"\n'
        'site = "Hong Kong, all man-made rock cuts of the territory (CEDD/GEO incident register; regional record)"\n',
        encoding="utf-8")
    rain = read_rainfall(args.raw / "hko_daily_rainfall_1884_2022.csv")
    daily = rain.daily.loc[RAIN_START:RAIN_END]
    note = rain.flags.loc[RAIN_START:RAIN_END]
    out = daily.rename("rainfall_mm").to_frame()
    out["note"] = note
    out.index = out.index.strftime("%Y-%m-%d")
    out.index.name = "date"
    out.to_csv(HERE / "hko_daily_rainfall_1983_2020.csv", lineterminator="\n", float_format="%.1f")
    for line in extract.notes:
        print(line)
    print(extract.summary().to_string(header=False))
    print(f"hko_daily_rainfall_1983_2020.csv: {len(out)} days, {int(daily.isna().sum())} missing, "
          f"{int((note == 'trace').sum())} trace days written as 0.0")
    return 0


if __name__ == "__main__":
    sys.exit(main())
