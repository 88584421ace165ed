"""A synthetic check of the size law's extrapolation: fitted on large blocks, does it cover small ones?

    python validation/presets/size_extrapolation.py          # writes docs/validation/size_extrapolation.csv
                                                             # and docs/validation/figures/size_extrapolation.png

Blocks are "observed" on a known model whose size dependence differs from the shipped law's, then the shipped
law (:func:`simulation.contact.rolling_resistance`, mu_0 + s c / sqrt(s^2 + c^2), s = K h / r, capped at 38 deg)
is fitted to the large blocks only and asked to predict the small ones:

* **slope**: a 40 m soil face at 32 deg (below the cap, so the size term can hold small blocks on it) over a
  10 deg soil run-out; the data-derived soil preset (roughness 0.1 m, its contact laws), blocks released at the
  face's top with 0.5-3 m/s down it;
* **truth**: a block of radius r meets mu_true(r) -- each block is simulated on its own with the size term off
  (K = 0) and phi_g = atan(mu_true(r) exp(0.05 z)), z a standard normal deviate per block (:data:`SCATTER`), so any
  size dependence can be put in.  Two truths, both different in form
  from the shipped law: ``power`` mu_true = tan 16 deg + 0.045 / sqrt(r / 1 m) (Kirkby & Statham's size ratio to
  the power 1/2 instead of 1, unbounded), and ``steep`` mu_true = tan 18 deg + 0.012 / (r / 1 m)^2 (steeper than
  1 / r, capped at tan 45 deg), and ``exponential`` mu_true = tan 16 deg + 0.35 exp(-r / 0.12 m) (not a power of r
  at all: flat for large blocks, rising fast below 0.2 m);
* **fit** (the shipped fitting machinery, :func:`simulation.calibrate_pooled` with the shipped fits' 2 m kernel
  floor, uniform priors as the shipped presets': phi_g 3-45 deg, K 0-3, the exponent a 0.25-2): 40 blocks of
  0.25-0.55 m radius (the Authume blocks' range), one stop each;
* **prediction**: 40 blocks of 0.10-0.20 m radius the fit never saw, each simulated with 40 posterior draws x 10
  blocks; the share of their true stops beyond their own release's predictive p99 (the Must-show target: at most
  10 %), beyond p95, and the error of the pooled median.

Runs in about a minute per truth on one core.
"""
from __future__ import annotations

import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(REPO))

import simulation  # noqa: E402
from simulation.pooled import Release, _Pool, calibrate_pooled  # noqa: E402
from simulation.units import DEFAULT_DENSITY_KG_M3  # noqa: E402

SLOPE_DEG, RUNOUT_DEG, H_M = 32.0, 10.0, 40.0
X_TOE = 5.0 + H_M / math.tan(math.radians(SLOPE_DEG))
#: The fitted fields of the soil and their priors: those of the shipped presets (derive_presets.py PARAMETERS and
#: SIZE_PARAMETER).
PARAMETERS = {"materials.soil.ground_friction_angle_deg": (3.0, 45.0),
              "materials.soil.rolling_size_coefficient": (0.0, 3.0),
              "materials.soil.rolling_size_exponent": (0.25, 2.0)}
TRUTHS = {
    "power": (lambda r: math.tan(math.radians(16.0)) + 0.045 / math.sqrt(r),
              "tan 16 deg + 0.045 / sqrt(r)"),
    "steep": (lambda r: min(math.tan(math.radians(18.0)) + 0.012 / r ** 2, 1.0),
              "min(tan 18 deg + 0.012 / r^2, tan 45 deg)"),
    "exponential": (lambda r: math.tan(math.radians(16.0)) + 0.35 * math.exp(-r / 0.12),
                    "tan 16 deg + 0.35 exp(-r / 0.12 m)"),
}
N_LARGE, N_SMALL, DRAWS, N_EACH = 40, 40, 40, 10


def scenario(soil: dict | None = None) -> dict:
    """The face over the run-out with the data-derived soil, ``soil`` put over it."""
    return {"name": "size_extrapolation",
            "profile": {"x": [0.0, 5.0, X_TOE, X_TOE + 400.0],
                        "z": [H_M, H_M, 0.0, -400.0 * math.tan(math.radians(RUNOUT_DEG))],
                        "materials": ["soil", "soil", "soil"]},
            "materials": {"soil": {"preset": "soil", "preset_basis": "data", **(soil or {})}},
            "seeder": {"type": "line", "x": [5.5, 6.5], "height_m": 0.0,
                       "downslope_speed_ms": {"dist": "uniform", "low": 0.5, "high": 3.0}, "mass_kg": 1000.0,
                       "density_kg_m3": DEFAULT_DENSITY_KG_M3},
            "settings": {"envelope_bins": 0}}


def mass(r: float) -> float:
    return 4.0 / 3.0 * math.pi * r ** 3 * DEFAULT_DENSITY_KG_M3


#: Block-to-block scatter of the true resistance: each observed block meets mu_true(r) exp(SCATTER z), z a standard
#: normal deviate (heterogeneous ground and block shapes; without it rolling blocks stop almost deterministically
#: and no real data set looks like that: the Authume stops of one profile span 36-60 m between p10 and p90).
SCATTER = 0.05


def observe(truth, radii, seed0):
    """One true stop per radius: the block alone on the slope with mu_true(r) (times its scatter) and no size
    term."""
    out = []
    z = np.random.default_rng(seed0).standard_normal(len(radii))
    for i, r in enumerate(radii):
        phi = math.degrees(math.atan(truth(r) * math.exp(SCATTER * z[i])))
        sc = simulation.scenario_from_dict(scenario({"ground_friction_angle_deg": phi,
                                                     "rolling_size_coefficient": 0.0}), "<truth>")
        out.append(float(simulation.run(sc, 1, seed=seed0 + i, masses_kg=[mass(r)]).runout["x_stop_m"].iloc[0]))
    return np.array(out)


def releases(radii, stops, tag):
    data = scenario()
    return [Release(name=f"{tag}{i}", scenario=data, x_stop_m=[x], mass_kg=mass(r),
                    source="validation/presets/size_extrapolation.py") for i, (r, x) in enumerate(zip(radii, stops))]


def check(name, seed=1):
    truth, words = TRUTHS[name]
    rng = np.random.default_rng(seed)
    r_large = rng.uniform(0.25, 0.55, N_LARGE)
    r_small = rng.uniform(0.10, 0.20, N_SMALL)
    x_large = observe(truth, r_large, 1_000)
    x_small = observe(truth, r_small, 2_000)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_pooled(releases(r_large, x_large, "L"), PARAMETERS, seed=seed, n_per_release=100,
                               n_initial=1024, n_per_iteration=256, iterations=4, n_predictive=0, obs_error_m=2.0)
    draws = cal.posterior.sample(DRAWS, random_state=seed).to_dict("records")
    rels = releases(r_small, x_small, "S")
    pool = _Pool(rels, PARAMETERS)
    per = [[] for _ in rels]
    for t, values in enumerate(draws):
        for i, s in enumerate(pool.simulate(values, N_EACH, 50_000 + t)):
            per[i].append(s)
    per = [np.concatenate(p) for p in per]
    p95 = np.array([np.quantile(s, 0.95) for s in per])
    p99 = np.array([np.quantile(s, 0.99) for s in per])
    p01 = np.array([np.quantile(s, 0.01) for s in per])
    pred = np.concatenate(per)
    summ = cal.summary()
    row = {"truth": name, "mu_true": words, "fitted_on": f"{N_LARGE} blocks, r 0.25-0.55 m",
           "predicted": f"{N_SMALL} blocks, r 0.10-0.20 m",
           "phi_g_median_deg": summ.loc["materials.soil.ground_friction_angle_deg", "median"],
           "phi_g_q05_deg": summ.loc["materials.soil.ground_friction_angle_deg", "q05"],
           "phi_g_q95_deg": summ.loc["materials.soil.ground_friction_angle_deg", "q95"],
           "k_median": summ.loc["materials.soil.rolling_size_coefficient", "median"],
           "k_q05": summ.loc["materials.soil.rolling_size_coefficient", "q05"],
           "k_q95": summ.loc["materials.soil.rolling_size_coefficient", "q95"],
           "obs_small_p50_m": float(np.median(x_small)), "pred_small_p50_m": float(np.median(pred)),
           "median_error_pct": 100.0 * (np.median(pred) / np.median(x_small) - 1.0),
           "beyond_p95": float(np.mean(x_small > p95)), "beyond_p99": float(np.mean(x_small > p99)),
           "below_p01": float(np.mean(x_small < p01)), "notes": "; ".join(cal.notes)}
    curve = {"r_large": r_large, "x_large": x_large, "r_small": r_small, "x_small": x_small, "p01": p01,
             "p99": p99, "p50": np.array([np.median(s) for s in per]), "cal": cal}
    return row, curve


def main():
    t0 = time.time()
    rows, curves = [], {}
    for name in TRUTHS:
        row, curve = check(name)
        rows.append(row)
        curves[name] = curve
        print(name, f"{time.time() - t0:.0f} s", {k: (round(v, 3) if isinstance(v, float) else v) for k, v in row.items()
                                                   if k != "notes"})
    table = pd.DataFrame(rows)
    out = REPO / "docs" / "validation"
    table.to_csv(out / "size_extrapolation.csv", index=False, float_format="%.4g")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(curves), figsize=(5.5 * len(curves), 4.2))
    for ax, (name, c) in zip(np.atleast_1d(axes), curves.items()):
        ax.axhline(X_TOE, color="0.6", lw=0.8, ls=":", label="toe of the 32 deg face")
        ax.plot(c["r_large"], c["x_large"], "o", color="C0", ms=4, label="true stops, fitted on (0.25-0.55 m)")
        order = np.argsort(c["r_small"])
        rs = c["r_small"][order]
        ax.fill_between(rs, c["p01"][order], c["p99"][order], color="C3", alpha=0.25,
                        label="prediction, p1-p99 of each release")
        ax.plot(rs, c["p50"][order], "-", color="C3", lw=1, label="prediction, median")
        ax.plot(c["r_small"], c["x_small"], "s", color="k", ms=4, label="true stops, held out (0.10-0.20 m)")
        r = [x for x in rows if x["truth"] == name][0]
        ax.set_title(f"truth mu(r) = {r['mu_true']}\nbeyond p99 {r['beyond_p99']:.1%}, median error "
                     f"{r['median_error_pct']:+.0f} %", fontsize="small")
        ax.set_xlabel("block radius r [m]")
        ax.set_ylabel("stop position x [m]")
        ax.legend(fontsize="x-small")
    fig.suptitle("The shipped size law fitted on large blocks, predicting small ones it never saw "
                 "(validation/presets/size_extrapolation.py)", fontsize="small")
    fig.tight_layout()
    fig.savefig(out / "figures" / "size_extrapolation.png", dpi=110)
    print(f"total {time.time() - t0:.0f} s")
    print(table.drop(columns=["notes"]).round(3).to_string())


if __name__ == "__main__":
    main()
