"""Corridor: screen and rank 19 km of the E6 through Drivdalen (Norway).

Runs ``riskrf corridor`` on ``corridors/e6_drivdalen/e6_drivdalen.toml``: 19 sections of
1 km whose rates of rock falls reaching the road and whose mass law come from the real NVDB
slide register 2000-2014 (Statens vegvesen / NVDB, NLOD 2.0; see
``corridors/e6_drivdalen/PROVENANCE.md``), with illustrative cut geometry, traffic, costs and
RHRS classes.  Each section is scored with the Rockfall Hazard Rating System and assessed
quantitatively (mass-coupled energy hazard, road-user risk, option ranking) as one task on a
local dask cluster of one worker.  Prints the sections ranked by deaths per year of doing
nothing beside their RHRS rank, and draws both rankings along the chainage.  500 blocks per
section here (the corridor file asks for 5,000), so the figures are noisier than the
documentation's.  Writes the command's outputs and ``ranks.png`` to the output directory
(first argument, else a new temporary directory).

Run from the repository root::

    python docs/examples/corridor.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from riskrf.cli import main as riskrf_command  # noqa: E402


def main() -> int:
    """Run the corridor and draw both rankings (a function: dask's worker processes re-import this file)."""
    out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="riskrf-example-"))
    out.mkdir(parents=True, exist_ok=True)
    run = out / "e6-corridor"

    status = riskrf_command(["corridor", "corridors/e6_drivdalen/e6_drivdalen.toml", "-n", "500", "--workers", "1",
                            "--out", str(run), "--overwrite"])
    if status != 0:
        return status

    table = pd.read_csv(run / "corridor.csv")
    print(table[["rank_risk", "rank_rhrs", "id", "rhrs_score", "road_falls_per_year", "deaths_per_year",
                 "individual_risk", "best_option"]].head(8).to_string(index=False, float_format="{:.3g}".format))

    t = table.sort_values("chainage_from_m")
    km = (t["chainage_from_m"] + t["chainage_to_m"]) / 2000.0
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(km, t["rank_risk"], "o-", label="rank by deaths per year (quantitative)")
    ax.plot(km, t["rank_rhrs"], "s--", label="rank by RHRS score")
    ax.invert_yaxis()
    ax.set_xlabel("chainage [km]")
    ax.set_ylabel("rank (1 = highest)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "ranks.png", dpi=100)
    plt.close(fig)
    print(f"wrote {out / 'ranks.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
