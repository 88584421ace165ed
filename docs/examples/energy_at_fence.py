"""Energy hazard at a fence: how often does an impact exceed a barrier's capacity?

Fits the power law of the real Lauterbrunnen inventory with a largest credible block of
2,000 t (``m_max``), takes 5 % of the monitored wall as the source above the road (the rate
share of the bundled demo site, an assumption), simulates blocks across the mass law's range
on the shipped road-cut slope (``simulation/scenarios/road_cut_barrier.toml``) and combines
them into the mass-coupled annual frequency of impacts above each energy at the barrier
line.  Prints the 100- and 300-year energies [kJ] and how often a 2,000 kJ and a 5,000 kJ
fence would be exceeded; writes ``energy_exceedance.png`` to the output directory (first
argument, else a new temporary directory).  20,000 blocks here; ``riskrf energy`` and the
demo use more.

Run from the repository root::

    python docs/examples/energy_at_fence.py [OUT_DIR]
"""
import sys
import tempfile
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import riskrf  # noqa: E402
import simulation  # noqa: E402
from riskrf.report import plot_energy_exceedance  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="riskrf-example-"))
out.mkdir(parents=True, exist_ok=True)

with warnings.catch_warnings():
    warnings.simplefilter("ignore", riskrf.RiskrfWarning)        # the default density, stated in the docs
    inv = riskrf.read_inventory("inventories/lauterbrunnen/lauterbrunnen_tls_2018.csv")
gr = riskrf.fit_gutenberg_richter(inv.masses, inv.duration_years, m_max=2e6)   # kg
scenario = simulation.load_scenario("simulation/scenarios/road_cut_barrier.toml")

hazard = riskrf.energy_hazard(mass=gr, scenario=scenario, collector="barrier",
                              rate_per_year=0.05 * gr.rate_min, n=20_000, seed=1)
e100, e300 = hazard.energy_at_return_period([100, 300])
print(f"100-year energy at the barrier line: {e100:,.0f} kJ; 300-year: {e300:,.0f} kJ")
for capacity in (2000, 5000):
    rate = hazard.annual_frequency(capacity)
    print(f"impacts above {capacity:,} kJ: {rate:.3f} per year (1 in {1 / rate:.0f} years)")

ax = plot_energy_exceedance(hazard, fences=(2000, 5000), n_bootstrap=50, seed=1)
ax.figure.savefig(out / "energy_exceedance.png", dpi=100)
plt.close(ax.figure)
print(f"wrote {out / 'energy_exceedance.png'}")
