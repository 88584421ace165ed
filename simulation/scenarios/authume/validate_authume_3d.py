"""Observed vs simulated stop positions in plan at the Authume quarry, with the 3-D kernel.

    python simulation/scenarios/authume/validate_authume_3d.py [RAW_DIR] [--n 2000]

Runs the 3-D scenario (``authume_3d.tif`` DEM, zones as materials) from each release (P1, P2) with three
material sets: the a-priori presets, and the parameters calibrated with the 2-D kernel on P1 and on P2
(``authume_p1_calibrated.toml``, ``authume_p2_calibrated.toml``; the 2-D calibration applied unchanged to
the 3-D kernel).  Compares, per release, the 41 / 48 surveyed stop points with the simulated ones:

* plan runout (horizontal distance from the release point): quantiles, Wasserstein distance W1, KS test;
* lateral offset: signed distance from the reference line of the 2-D profile (release -> medians of the
  nearest, middle and farthest third of the observed stops, as ``build_authume.py`` draws it);
* both together: the energy distance of the 2-D plan positions (Szekely & Rizzo 2013) with a permutation
  p-value;
* the share of observed stops beyond the farthest of 100 simulated blocks (plan runout), averaged over
  random sets of 100, beside the same share for the 2-D kernel on the calibrated section.

Writes ``docs/validation/authume-3d.md`` (tables) and ``docs/validation/figures/authume-3d.png``.
Caveats (PROVENANCE.md): stop points lie 2.5-3.5 m above the terrain (datum offset): only plan positions
are compared; drop heights are the shovel's Y above the DEM, as in the 2-D scenarios.
"""
from __future__ import annotations

import sys
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(HERE))

import simulation  # noqa: E402
from simulation.profile_extraction import TerrainProfile, _polyline  # noqa: E402
from build_authume_3d import _raw_dir, release_point  # noqa: E402

DOCS = REPO / "docs" / "validation"
APRIORI = {"vegetated_slope": {"preset": "soil"},
           "hard_ground": {"preset": "bedrock", "tangential": {"law": "constant", "mean": 0.55, "std": 0.12}},
           "rocky_slope": {"preset": "talus"}}


def materials_from(toml_path: Path | None) -> dict:
    """The material tables of a 2-D Authume scenario (a-priori presets where it names none)."""
    mats = {k: dict(v) for k, v in APRIORI.items()}
    if toml_path is not None:
        with open(toml_path, "rb") as f:
            mats.update(tomllib.load(f)["materials"])
    return mats


def scenario(profile: str, materials: dict, raw: Path):
    """The 3-D Authume scenario for release ``profile`` with the given materials."""
    with open(HERE / "authume_3d.toml", "rb") as f:
        data = tomllib.load(f)
    x, y, drop = release_point(raw, profile)
    dem = simulation.read_dem(HERE / "authume_dem.tif")
    ends = np.loadtxt(raw / f"Endpoints_{profile}.txt", ndmin=2)
    ln = np.log(ends[:, 3])
    data["materials"] = materials
    data["sources"].update(points=[[x, y]], height_m=drop - float(dem.elevation(x, y)),
                           mass_kg={"dist": "lognormal", "median": float(np.exp(ln.mean())),
                                    "sigma": float(ln.std(ddof=1)), "max": float(ends[:, 3].max())})
    data["collectors"] = []
    return simulation.terrain_scenario_from_dict(data, source=f"authume_3d ({profile})", base_dir=HERE, terrain=dem)


def reference_line(profile: str, raw: Path) -> TerrainProfile:
    """The 2-D profile's plan path: release -> medians of the thirds of the observed stops (by plan distance)."""
    ends = np.loadtxt(raw / f"Endpoints_{profile}.txt", ndmin=2)
    x, y, _ = release_point(raw, profile)
    r = np.array([x, y])
    stops = ends[:, [0, 2]]
    order = np.argsort(np.hypot(*(stops - r).T))
    spine = np.array([r] + [np.median(stops[g], axis=0) for g in np.array_split(order, 3)])
    p, _ = _polyline(spine)
    return TerrainProfile(distance_m=np.zeros(2), elevation_m=np.zeros(2), plan_xy=p[:2], materials=None,
                          polyline_xy=p)


def energy_distance_2d(a: np.ndarray, b: np.ndarray, n_perm: int = 300, seed: int = 0):
    """Energy distance of two plan samples (Szekely & Rizzo 2013, eq. 1): 2 E|X-Y| - E|X-X'| - E|Y-Y'| [m],
    with a permutation p-value."""
    def stat(x, y):
        dxy = np.hypot(*(x[:, None, :] - y[None, :, :]).transpose(2, 0, 1)).mean()
        dxx = np.hypot(*(x[:, None, :] - x[None, :, :]).transpose(2, 0, 1)).mean()
        dyy = np.hypot(*(y[:, None, :] - y[None, :, :]).transpose(2, 0, 1)).mean()
        return 2 * dxy - dxx - dyy
    e = stat(a, b)
    rng = np.random.default_rng(seed)
    pool = np.vstack([a, b])
    count = 0
    for _ in range(n_perm):
        perm = rng.permutation(len(pool))
        count += stat(pool[perm[:len(a)]], pool[perm[len(a):]]) >= e
    return float(e), (count + 1) / (n_perm + 1)


def beyond_farthest(observed: np.ndarray, simulated: np.ndarray, k: int = 100, reps: int = 500, seed: int = 0):
    """Mean share of observed values beyond the largest of k simulated ones (random sets of k)."""
    rng = np.random.default_rng(seed)
    return float(np.mean([(observed > rng.choice(simulated, k, replace=False).max()).mean() for _ in range(reps)]))


def main(argv) -> None:
    n = 2000
    if "--n" in argv:
        n = int(argv[argv.index("--n") + 1])
        argv = [a for i, a in enumerate(argv) if a != "--n" and (i == 0 or argv[i - 1] != "--n")]
    raw = _raw_dir(argv)
    sets = {"a priori": None, "calibrated on P1 (2-D)": HERE / "authume_p1_calibrated.toml",
            "calibrated on P2 (2-D)": HERE / "authume_p2_calibrated.toml"}
    rows, stops_for_fig = [], {}
    for prof in ("P1", "P2"):
        ends = np.loadtxt(raw / f"Endpoints_{prof}.txt", ndmin=2)
        obs = ends[:, [0, 2]]
        x, y, _ = release_point(raw, prof)
        line = reference_line(prof, raw)
        o_run = np.hypot(obs[:, 0] - x, obs[:, 1] - y)
        o_off = line.project(obs)["offset_m"].to_numpy()
        rows.append({"release": prof, "materials": "observed", "n": len(obs),
                     **{f"runout p{q}": np.percentile(o_run, q) for q in (10, 50, 90)},
                     **{f"offset p{q}": np.percentile(o_off, q) for q in (10, 50, 90)}})
        for name, path in sets.items():
            r = simulation.run_terrain(scenario(prof, materials_from(path), raw), n, seed=1)
            st = r.stops()
            sim = st[["x_m", "y_m"]].to_numpy()
            s_run = st["runout_m"].to_numpy()
            s_off = line.project(sim)["offset_m"].to_numpy()
            sub = sim[np.random.default_rng(1).choice(len(sim), min(400, len(sim)), replace=False)]
            ed, ed_p = energy_distance_2d(obs, sub)
            row = {"release": prof, "materials": name, "n": n,
                   **{f"runout p{q}": np.percentile(s_run, q) for q in (10, 50, 90)},
                   **{f"offset p{q}": np.percentile(s_off, q) for q in (10, 50, 90)},
                   "W1 runout [m]": stats.wasserstein_distance(o_run, s_run),
                   "KS p runout": stats.ks_2samp(o_run, s_run).pvalue,
                   "W1 offset [m]": stats.wasserstein_distance(o_off, s_off),
                   "KS p offset": stats.ks_2samp(o_off, s_off).pvalue,
                   "energy distance [m]": ed, "energy p": ed_p,
                   "beyond farthest of 100": beyond_farthest(o_run, s_run)}
            if name == f"calibrated on {prof} (2-D)":
                stops_for_fig[prof] = (r, obs, (x, y))
                # the 2-D kernel on the calibrated section, the same share on distance along the section
                sc2 = simulation.load_scenario(HERE / f"authume_{prof.lower()}_calibrated.toml")
                r2 = simulation.run(sc2, n, seed=1)
                obs_x = pd.read_csv(REPO / "tests" / "data" / "authume" / "observed_runout.csv")
                obs_x = obs_x.loc[obs_x["profile"] == prof, "x_stop_m"].to_numpy()
                row["beyond farthest of 100, 2-D"] = beyond_farthest(obs_x, r2.per_block["x"])
            rows.append(row)
    table = pd.DataFrame(rows)
    DOCS.mkdir(parents=True, exist_ok=True)
    (DOCS / "figures").mkdir(exist_ok=True)
    table.to_csv(HERE / "results_3d.csv", index=False)
    _figure(stops_for_fig, DOCS / "figures" / "authume-3d.png")
    print(table.to_string())


def _figure(runs: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 7))
    for ax, (prof, (r, obs, rel)) in zip(axes, sorted(runs.items())):
        r.plot(ax=ax, paths=False)
        ax.scatter(obs[:, 0], obs[:, 1], s=18, facecolor="none", edgecolor="black", label="observed stops")
        ax.plot(*rel, marker="*", color="yellow", markeredgecolor="black", markersize=14, label="release")
        ax.set_title(f"{prof}: simulated (red, calibrated on {prof} in 2-D) vs observed stops")
        ax.legend(loc="lower right", fontsize=8)
        ax.set_xlabel("raw X [m]")
        ax.set_ylabel("raw Z [m]")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv)
