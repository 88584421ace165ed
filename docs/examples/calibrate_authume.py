"""Calibrate a slope to observed stops: the Authume quarry, profile P1.

89 real boulders (170-1,869 kg) were dropped at two positions of the Authume quarry (France)
and their stop points surveyed (Garcia et al. 2022, *Engineering Geology* 310:106855; data
``richefeu/AuthumeQuarryRockfalls_Data-in-Brief``, used with the citation; see
``tests/data/authume/README.md`` for its caveats: stop points lie 2.5-3.5 m above the terrain
model, so only horizontal positions are compared).  The 41 stops of profile P1 are fitted
here: two material values of the 2-D profile are searched within bounds so that the
simulated stop positions [m] come closest (1-Wasserstein distance) to the observed ones.
The presets put the simulated stops far short of the real ones; after calibration they
match.  A small search (300 blocks per evaluation, 6 generations, 50 bootstrap replicates)
keeps this example fast; the study (``validation/authume/calibrate_authume.py``) uses 2,000 blocks.
Writes ``runout_cdf.png`` to the output directory (first argument, else a new temporary
directory).

Run from the repository root::

    python docs/examples/calibrate_authume.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

import simulation  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="riskrf-example-"))
out.mkdir(parents=True, exist_ok=True)

observed = pd.read_csv("tests/data/authume/observed_runout.csv")
observed = observed[observed["profile"] == "P1"]            # 41 real stops, x_stop_m [m] along the path
cal = simulation.calibrate(
    "simulation/scenarios/authume/authume_p1.toml", observed,
    {"materials.vegetated_slope.tangential.mean": (0.2, 1.0),        # e_T of the vegetated slope
     "materials.hard_ground.ground_friction_angle_deg": (5, 50)},    # rolling resistance of the hard ground [deg]
    n=300, seed=1, maxiter=6, n_bootstrap=50)
print(cal.summary().to_string(float_format="{:.3g}".format))
print(cal.comparison().to_string(float_format="{:.3g}".format))

ax = cal.plot()
ax.figure.savefig(out / "runout_cdf.png", dpi=100)
plt.close(ax.figure)
print(f"wrote {out / 'runout_cdf.png'}")
