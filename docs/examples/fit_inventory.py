"""Fit an inventory: the power law of the real Lauterbrunnen rock fall record.

Reads the bundled laser-scanning inventory of the Lauterbrunnen rock wall (317 falls in
5.2 years; Strunden et al. 2015, see ``inventories/README.md`` for its provenance), fits the
Gutenberg-Richter power law log10 N(>=m) = a - b log10 m by maximum likelihood above a
completeness threshold m_min found by the Kolmogorov-Smirnov search (Clauset et al. 2009),
tests the fit with a seeded bootstrap and prints the design masses [kg] for return periods of
10-1,000 years.  Writes ``magnitude_frequency.png`` to the output directory (the first
argument, else a new temporary directory).

Run from the repository root::

    python docs/examples/fit_inventory.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import riskrf  # noqa: E402
from riskrf.report import plot_magnitude_frequency  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="riskrf-example-"))
out.mkdir(parents=True, exist_ok=True)

inv = riskrf.read_inventory("inventories/lauterbrunnen/lauterbrunnen_tls_2018.csv")
print(f"{len(inv.masses)} falls with a size over {inv.duration_years:.1f} years")

gr = riskrf.fit_gutenberg_richter(inv.masses, inv.duration_years)   # m_min by the KS search, MLE
lo, hi = gr.b_ci
print(f"b = {gr.b:.3f} (95 % interval {lo:.3f}-{hi:.3f}), m_min = {gr.m_min:,.0f} kg, "
      f"{gr.rate_min:.1f} falls >= m_min per year")
test = gr.bootstrap_test(200, seed=1)                 # Clauset et al. (2009) goodness of fit
print(f"bootstrap p-value {test.p_value:.2f} ({test.n_completed} replicates): power law "
      f"{'plausible' if test.p_value > 0.1 else 'rejected'} (plausible when p > 0.1)")
for T in (10, 100, 1000):
    print(f"{T:>5}-year fall: {gr.mass_at_return_period(T):14,.0f} kg")

ax = plot_magnitude_frequency(gr)
ax.figure.savefig(out / "magnitude_frequency.png", dpi=100)
plt.close(ax.figure)
print(f"wrote {out / 'magnitude_frequency.png'}")
