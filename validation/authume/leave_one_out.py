"""Leave-one-dataset-out check of the pooled calibration on the two Authume profiles.

    python validation/authume/leave_one_out.py [--n-per-release 50] [--seed 1]

For each profile (P1: 41 blocks, P2: 48; tests/data/authume/observed_runout.csv) the shared parameters are fitted
with :func:`simulation.calibrate_pooled` on the OTHER profile's releases (each block its own release with its
measured mass), and the held-out profile's stops are predicted from that posterior (40 posterior draws, every
held-out release simulated with its own mass).  Also the a-priori prediction (the presets of authume_p1/p2.toml).
Writes docs/validation/trajectories_loo.csv and docs/validation/figures/trajectories_loo.png.

Data: Garcia et al. (2022) Engineering Geology 310:106855; richefeu/AuthumeQuarryRockfalls_Data-in-Brief
f695c933 (no licence file: derived runouts used with the citation).  Caveats (PROVENANCE.md): the stops are
projected on a 2-D section although they lie up to 10 m to its side; the release point is the mean of four drop
points.
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
DATA = REPO / "simulation" / "scenarios" / "authume"   # the quarry's scenarios, DEM and results
sys.path.insert(0, str(REPO))

from simulation.pooled import Release, _Pool, calibrate_pooled  # noqa: E402

PARAMETERS = {"materials.vegetated_slope.ground_friction_angle_deg": (3.0, 45.0),
              "materials.vegetated_slope.tangential.mean": (0.2, 1.0),
              "materials.hard_ground.ground_friction_angle_deg": (5.0, 50.0)}
OBSERVED = REPO / "tests" / "data" / "authume" / "observed_runout.csv"


def releases(profile):
    obs = pd.read_csv(OBSERVED)
    return [Release(name=f"{r.profile}-{r.block}", scenario=DATA / f"authume_{r.profile.lower()}.toml",
                    x_stop_m=[r.x_stop_m], mass_kg=r.mass_kg, source=str(OBSERVED))
            for r in obs.itertuples() if r.profile == profile]


def predictive(pool, draws, n_each, seed0):
    """Per release: simulated stops pooled over the parameter draws (a list of dicts)."""
    per = [[] for _ in pool.releases]
    for t, values in enumerate(draws):
        for i, s in enumerate(pool.simulate(values, n_each, seed0 + t)):
            per[i].append(s)
    return [np.concatenate(p) for p in per]


def row(dataset, model, per_release, rels):
    obs = np.array([r.x_stop_m[0] for r in rels])
    pred = np.concatenate(per_release)
    p99 = np.array([np.quantile(s, 0.99) for s in per_release])
    lo90 = np.array([np.quantile(s, 0.05) for s in per_release])
    hi90 = np.array([np.quantile(s, 0.95) for s in per_release])
    qo, qp = np.quantile(obs, [0.1, 0.5, 0.9]), np.quantile(pred, [0.1, 0.5, 0.9])
    return {"held_out": dataset, "model": model, "observed_stops": obs.size,
            "obs_p10_m": qo[0], "obs_p50_m": qo[1], "obs_p90_m": qo[2],
            "pred_p10_m": qp[0], "pred_p50_m": qp[1], "pred_p90_m": qp[2],
            "median_error_pct": 100.0 * (qp[1] / qo[1] - 1.0),
            "ks_d": stats.ks_2samp(pred, obs).statistic, "w1_m": stats.wasserstein_distance(pred, obs),
            "beyond_p99": float(np.mean(obs > p99)), "inside_90": float(np.mean((obs >= lo90) & (obs <= hi90)))}, \
        (obs, pred)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-per-release", type=int, default=50)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rows, curves = [], {}
    t0 = time.time()
    for held, train in (("P1", "P2"), ("P2", "P1")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = calibrate_pooled(releases(train), PARAMETERS, seed=args.seed, n_per_release=args.n_per_release,
                                   n_initial=128, n_per_iteration=48, iterations=3, n_predictive=0,
                                   obs_error_m=2.0)
        rels = releases(held)
        pool = _Pool(rels, PARAMETERS)
        draws = cal.posterior.sample(40, random_state=args.seed).to_dict("records")
        r, c = row(held, f"fitted on {train}", predictive(pool, draws, 10, 50_000), rels)
        rows.append(r)
        curves[(held, "fitted")] = c
        r, c = row(held, "a priori (presets)", predictive(pool, [{}], 400, 60_000), rels)
        rows.append(r)
        curves[(held, "prior")] = c
        print(held, "done", f"{time.time() - t0:.0f} s", cal.summary()[["median", "q05", "q95"]].round(3).to_dict())
    table = pd.DataFrame(rows)
    out = REPO / "docs" / "validation"
    (out / "figures").mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "trajectories_loo.csv", index=False, float_format="%.4g")
    print(table.round(3).to_string())
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, held in zip(axes, ("P1", "P2")):
        obs = np.sort(curves[(held, "fitted")][0])
        ax.step(obs, np.arange(1, obs.size + 1) / obs.size, where="post", color="k", lw=2,
                label=f"observed ({obs.size})")
        for key, label, style in (("fitted", f"predicted, fitted on {'P2' if held == 'P1' else 'P1'}", "C3"),
                                  ("prior", "predicted, presets a priori", "C0")):
            p = np.sort(curves[(held, key)][1])
            ax.plot(p, np.arange(1, p.size + 1) / p.size, color=style, label=label)
        ax.set_title(f"Authume {held} held out", fontsize="small")
        ax.set_xlabel("stop position x [m]")
        ax.set_ylabel("fraction of blocks stopped before x")
        ax.legend(fontsize="small", loc="lower right")
    fig.tight_layout()
    fig.savefig(out / "figures" / "trajectories_loo.png", dpi=120)


if __name__ == "__main__":
    main()
