"""Mitigation ranking: which option costs least once the expected losses are counted?

Runs ``riskrf decide`` on the nine mitigation options of the bundled demo site
(``riskrf/data/demo_site.toml``: do nothing, scaling, a catch ditch, two fences, scaling plus
fence, a rain closure, a rock shed and a realignment; traffic, costs and options are
illustrative) over the real Lauterbrunnen inventory and the shipped road-cut slope.  Each
option's effect is derived by re-simulating the slope it changes; the options are ranked by
expected total cost (capital + renewals + maintenance + expected losses, 50 years at 2 %)
over 1,000 joint samples of the uncertain inputs.  Fewer simulated blocks than the demo keep
this example fast, so its numbers differ a little from the documentation's tables.  Writes
the command's outputs (``ranking.csv``, ``tornado.png``, ...) and ``ranking.png`` to the
output directory (first argument, else a new temporary directory).

Run from the repository root::

    python docs/examples/mitigation_ranking.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from riskrf.cli import main  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="riskrf-example-"))
out.mkdir(parents=True, exist_ok=True)
decision = out / "decision"

status = main(["decide", "--options", "riskrf/data/demo_site.toml",
               "--inventory", "inventories/lauterbrunnen/lauterbrunnen_tls_2018.csv",
               "--scenario", "simulation/scenarios/road_cut_barrier.toml",
               "--m-max", "2e6", "--rate-scale", "0.05",           # largest credible block [kg]; share of the wall
               "-n", "5000", "--option-blocks", "3000", "--bootstrap", "50",
               "--out", str(decision), "--overwrite"])
if status != 0:
    sys.exit(status)

ranking = pd.read_csv(decision / "ranking.csv")
print(ranking[["rank", "option", "expected_total_cost", "cost_p05", "cost_p95", "probability_best",
               "individual_risk", "fn_zone"]].to_string(index=False, float_format="{:.3g}".format))

fig, ax = plt.subplots(figsize=(7, 4))
r = ranking.iloc[::-1]
ax.barh(r["option"], r["expected_total_cost"] / 1e6, color="tab:blue")
ax.errorbar(r["expected_total_cost"] / 1e6, r["option"],
            xerr=[(r["expected_total_cost"] - r["cost_p05"]) / 1e6, (r["cost_p95"] - r["expected_total_cost"]) / 1e6],
            fmt="none", ecolor="black", capsize=3)
ax.set_xlabel("expected total cost [CHF million], bars: 5-95 % of the joint samples")
fig.tight_layout()
fig.savefig(out / "ranking.png", dpi=100)
plt.close(fig)
print(f"wrote {out / 'ranking.png'}")
