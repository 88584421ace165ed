"""Coverage by block size: the leave-one-dataset-out check of the presets, uncalibrated beside calibrated.

    python validation/presets/coverage_by_size.py                  # the whole table and figure (about 4 min, 2 cores)
    python validation/presets/coverage_by_size.py --figure-only    # the figure again from coverage_by_size.csv

For every data set the presets can be checked against (those of derive_presets.py: the Authume quarry releases of
profiles P1 and P2, Evans & Hungr's 1993 minimum shadow angle, and the Modified Ritchie width of the ODOT 60 ft
cut) and every model, the share of the observed stops beyond their own release's predictive p95 and p99 and the
median error, for the whole data set and, on the Authume releases (the only data set with a measured mass per
block), by block-size range: the mass terciles of each profile (``small``, ``medium``, ``large``; the simulator
rolls each block as the sphere of its measured mass).  Evans & Hungr and the ODOT cut are one number each (a far
limit, a width): they give one row, over all sizes.

The models (``calibration`` column):

* ``uncalibrated`` -- what a user meets before fitting anything: the **published presets** (``preset_basis``
  left at its default, ``"published"``; no parameter spread beyond the presets' own per-impact scatter), and the
  **data-derived presets** (``preset_basis = "data"``) with their stated spread, the 40 draws of the shipped
  posterior (:func:`simulation.material_uncertainty.preset_posterior`) and of the posterior with the assumed
  new-site spread (``preset_posterior(new_site=True)``).  The shipped posterior was fitted on Authume P1, P2 and
  Evans & Hungr, so on those three it is an **in-sample** check (``in_sample`` True); on the ODOT cut, which no fit
  saw, it is a prediction.
* ``calibrated`` -- fitted on the other data sets (derive_presets.py's ``loo`` fold: the same fit, draws, seeds and
  blocks per release), with and without the assumed site-to-site spread.  These rows are the ``presets_loo.csv``
  rows of the same model, split by size; ``tests/test_coverage_by_size.py`` checks that they pool to them.

"Predictive" is the model's per-release simulated distribution over its parameter draws (40 draws x 10 blocks per
release, or 400 blocks of the published presets), each Authume block with its own mass
(:func:`derive_presets.predict_release_stops`).  The target the rows are judged against: at most 10 % of the
observed stops beyond their release's predictive p99 and the median within +-25 % (``meets_target``).

Writes docs/validation/coverage_by_size.csv (the table), docs/validation/coverage_by_size_releases.csv (each
Authume release's observed stop and predictive p50 / p95 / p99 per model, from which the table's shares are
recomputed by the test) and docs/validation/figures/coverage_by_size.png.

Data caveats (tests/data/authume/README.md and the raw files' PROVENANCE.md): the Authume stops are projected on
each profile's 2-D section (blocks spread laterally by up to +-22 m, one P2 block by 32 m); the release point is
the mean of the four drop points; the surveyed stops lie 2.5-3.5 m above the terrain model, so only horizontal
positions are compared; the repository has no licence file and is used with its citation (Garcia et al. 2022,
Engineering Geology 310:106855).  Evans & Hungr's 27.5 deg is from the paper's abstract and its 2.0 deg spread is
an assumption (tests/data/evans_hungr1993/README.md).  The Modified Ritchie width is a design rule fitted to
ODOT's rollout tests (Ryan & Pryor 2000), not a measured deposit.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import derive_presets as dp  # noqa: E402

REPO = dp.REPO
OUT = REPO / "docs" / "validation"
TABLE = OUT / "coverage_by_size.csv"
RELEASES = OUT / "coverage_by_size_releases.csv"
FIGURE = OUT / "figures" / "coverage_by_size.png"

SIZE_RANGES = ("small", "medium", "large")       # mass terciles of each Authume profile
ALL_SIZES = "all"
#: The target: at most this share of the observed stops beyond their release's predictive p99 ...
TARGET_BEYOND_P99 = 0.10
#: ... and the predicted median within this many percent of the observed one.
TARGET_MEDIAN_PCT = 25.0
#: Datasets checked: the three of derive_presets.DATASETS and the ODOT cut no fit saw.
HELD_OUT = (*dp.DATASETS, "odot_ritchie_rule")

PUBLISHED = "published presets"
SHIPPED = "data-derived presets (shipped posterior)"
NEW_SITE = "data-derived presets + assumed new-site spread"


def size_ranges(masses) -> np.ndarray:
    """The block-size range of each block: the tercile of its mass [kg] within its data set (``small``,
    ``medium``, ``large``)."""
    return np.asarray(pd.qcut(np.asarray(masses, dtype=float), 3, labels=SIZE_RANGES).astype(str))


def meets_target(beyond_p99: float, median_error_pct: float) -> bool:
    """At most :data:`TARGET_BEYOND_P99` beyond the release p99 and the median within :data:`TARGET_MEDIAN_PCT`."""
    return bool(beyond_p99 <= TARGET_BEYOND_P99 and abs(median_error_pct) <= TARGET_MEDIAN_PCT)


def size_rows(held, model, per_release, rels):
    """The table's rows of one Authume held-out profile and model: all sizes (:func:`derive_presets.release_row`,
    the LOO table's definitions) and each size range; and each release's row of the per-release table."""
    mass = np.array([r.mass_kg for r in rels])
    obs = np.array([r.x_stop_m[0] for r in rels])
    rng = size_ranges(mass)
    p95, p99 = dp.release_quantiles(per_release, 0.95), dp.release_quantiles(per_release, 0.99)
    whole, _ = dp.release_row(held, model, per_release, rels)
    rows = [{**_common(whole), "size_range": ALL_SIZES, "mass_min_kg": mass.min(), "mass_max_kg": mass.max()}]
    for s in SIZE_RANGES:
        k = rng == s
        pred = np.concatenate([p for p, keep in zip(per_release, k) if keep])
        q = np.quantile(pred, [0.1, 0.5, 0.9])
        o50 = float(np.median(obs[k]))
        rows.append({"held_out": held, "model": model, "size_range": s, "mass_min_kg": mass[k].min(),
                     "mass_max_kg": mass[k].max(), "observations": int(k.sum()), "obs_p50": o50,
                     "pred_p10": q[0], "pred_p50": q[1], "pred_p90": q[2],
                     "median_error_pct": dp.median_error_pct(q[1], o50),
                     "beyond_p95": dp.beyond_share(obs[k], p95[k]), "beyond_p99": dp.beyond_share(obs[k], p99[k]),
                     "unit": whole["unit"]})
    per = pd.DataFrame({"held_out": held, "model": model, "block": [r.name for r in rels], "mass_kg": mass,
                        "size_range": rng, "observed_m": obs,
                        "pred_p50_m": dp.release_quantiles(per_release, 0.5), "pred_p95_m": p95, "pred_p99_m": p99})
    return rows, per


def _common(row: dict) -> dict:
    keep = ("held_out", "model", "observations", "obs_p50", "pred_p10", "pred_p50", "pred_p90", "median_error_pct",
            "beyond_p95", "beyond_p99", "unit")
    return {k: row[k] for k in keep}


def _published(fn):
    """``fn()`` with the presets' own (published) laws in derive_presets.MODEL, as its ``loo`` mode does."""
    laws = dp.MODEL["laws"]
    dp.MODEL["laws"] = {}
    try:
        return fn()
    finally:
        dp.MODEL["laws"] = laws


def models(held, draws, seed, n_per_release, iterations):
    """(label, calibration, in_sample, draws or None for the published presets) of every model for ``held``."""
    from simulation.material_uncertainty import preset_posterior, with_site_spread
    shipped_in_sample = held in dp.DATASETS
    out = [(PUBLISHED, "uncalibrated", False, None)]
    if held == "odot_ritchie_rule":
        post = preset_posterior(list(dp.ODOT_MATERIALS))
        new = preset_posterior(list(dp.ODOT_MATERIALS), new_site=True, seed=seed)
        return out + [(SHIPPED + "; no fit saw this data set", "uncalibrated",
                       False, post),
                      (NEW_SITE, "uncalibrated", False, new)]
    out += [(SHIPPED + " (in-sample: fitted on this data set too)", "uncalibrated", shipped_in_sample,
             preset_posterior().sample(draws, random_state=seed).to_dict("records")),
            (NEW_SITE + " (in-sample)", "uncalibrated", shipped_in_sample,
             preset_posterior(new_site=True, seed=seed).sample(draws, random_state=seed).to_dict("records"))]
    train = [d for d in dp.DATASETS if d != held]
    t0 = time.time()
    cal = dp.fit(train, n_per_release, seed, n_predictive=0, iterations=iterations)
    print(f"{held}: fitted on {train} in {time.time() - t0:.0f} s; {'; '.join(cal.notes)}", flush=True)
    fold = cal.posterior.sample(draws, random_state=seed).to_dict("records")
    label = "fitted on " + " + ".join(train)
    spread = with_site_spread(pd.DataFrame(fold), cal.bounds, seed).to_dict("records")
    return out + [(label, "calibrated", False, fold),
                  (label + " + assumed site-to-site spread", "calibrated", False, spread)]


def run(held_out, draws=40, seed=1, n_per_release=200, iterations=4):
    """The table and the per-release table (see the module docstring)."""
    rows, per = [], []
    for held in held_out:
        for model, calibration, in_sample, ds in models(held, draws, seed, n_per_release, iterations):
            extra = {"calibration": calibration, "in_sample": in_sample}
            if held == "odot_ritchie_rule":
                if ds is None:
                    r, _ = dp.ritchie_row(None, model, draws, seed)
                else:
                    r, _ = dp.ritchie_row(ds, model, draws, seed)
                rows.append({**_common(r), "size_range": ALL_SIZES, **extra})
            elif held == "evans_hungr_1993":
                if ds is None:
                    c, angles = _published(lambda: dp.evans_hungr_angles([{}], draws))
                else:
                    c, angles = dp.evans_hungr_angles(ds)
                r, _ = dp.constraint_row(model, c, angles)
                rows.append({**_common(r), "size_range": ALL_SIZES, **extra})
            else:
                prof = held.split("_")[1].upper()
                if ds is None:
                    rels = _published(lambda: dp.releases(prof))
                    stops = dp.predict_release_stops(rels, [{}], dp.N_EACH_PUBLISHED, dp.PREDICT_SEED)
                else:
                    rels = dp.releases(prof)
                    stops = dp.predict_release_stops(rels, ds, dp.N_EACH_FITTED, dp.PREDICT_SEED)
                r, p = size_rows(held, model, stops, rels)
                rows.extend({**x, **extra} for x in r)
                per.append(p)
            print(pd.DataFrame(rows[-4:]).round(3).to_string(), flush=True)
    table = pd.DataFrame(rows)
    table["meets_target"] = [meets_target(b, m) for b, m in zip(table["beyond_p99"], table["median_error_pct"])]
    cols = ["held_out", "model", "calibration", "in_sample", "size_range", "mass_min_kg", "mass_max_kg",
            "observations", "obs_p50", "pred_p10", "pred_p50", "pred_p90", "median_error_pct", "beyond_p95",
            "beyond_p99", "meets_target", "unit"]
    return table[cols], pd.concat(per, ignore_index=True)


def _generic(model: str) -> str:
    """A fold's label without the data sets it names (the figure's legend serves both held-out profiles)."""
    return ("fitted on the other two data sets" + model.split("evans_hungr_1993", 1)[1]
            if model.startswith("fitted on") else model)


def plot(table: pd.DataFrame, path: Path):
    """Beyond p99 (bars; p95 as dots) and median error by size range, each Authume profile held out."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    auth = table[table["held_out"].str.startswith("authume")]
    helds = list(dict.fromkeys(auth["held_out"]))
    fig, axes = plt.subplots(2, len(helds), figsize=(7.5 * len(helds), 9.0), squeeze=False)
    ranges = [*SIZE_RANGES, ALL_SIZES]
    for j, held in enumerate(helds):
        t = auth[auth["held_out"] == held]
        labels = list(dict.fromkeys(t["model"]))
        width = 0.8 / len(labels)
        for i, model in enumerate(labels):
            m = t[t["model"] == model].set_index("size_range").loc[ranges]
            x = np.arange(len(ranges)) + (i - (len(labels) - 1) / 2) * width
            colour = f"C{i}"
            cal = m["calibration"].iloc[0]
            hatch = None if cal == "calibrated" else "//"
            axes[0, j].bar(x, 100 * m["beyond_p99"], width, color=colour, hatch=hatch, alpha=0.8, zorder=2,
                           label=f"{_generic(model)} [{cal}]" if j == 0 else None)
            axes[0, j].plot(x, 100 * m["beyond_p95"], "o", color="k", ms=3, zorder=3,
                            label="beyond p95" if i == 0 and j == 0 else None)
            axes[1, j].bar(x, m["median_error_pct"], width, color=colour, hatch=hatch, alpha=0.8, zorder=2)
        names = [f"{s}\n{m0:.0f}-{m1:.0f} kg" for s, m0, m1 in
                 t.drop_duplicates("size_range").set_index("size_range").loc[ranges][["mass_min_kg",
                                                                                       "mass_max_kg"]].itertuples()]
        for ax in axes[:, j]:
            ax.set_xticks(np.arange(len(ranges)), names, fontsize="small")
        axes[0, j].axhline(100 * TARGET_BEYOND_P99, color="k", lw=1, ls="--", zorder=1,
                           label="target: at most 10 % beyond p99" if j == 0 else None)
        axes[0, j].set_ylabel("observed stops beyond their release's p99 [%]\n(dots: beyond p95)")
        axes[0, j].set_ylim(0, 105)
        axes[0, j].set_title(f"{held} held out: beyond the predictive p99, by mass tercile", fontsize="small")
        axes[1, j].axhspan(-TARGET_MEDIAN_PCT, TARGET_MEDIAN_PCT, color="0.9", zorder=0,
                           label="target: median within +-25 %" if j == 0 else None)
        axes[1, j].axhline(0, color="k", lw=0.8)
        axes[1, j].set_ylabel("median error, predicted against observed [%]")
        axes[1, j].set_title(f"{held} held out: median error, by mass tercile", fontsize="small")
    fig.suptitle("Coverage by block size (validation/presets/coverage_by_size.py); hatched: uncalibrated",
                 fontsize="small")
    fig.legend(loc="lower center", ncol=2, fontsize="small")
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n-per-release", type=int, default=200, help="blocks per release in the fold fits (200)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--draws", type=int, default=40, help="posterior draws per prediction (40)")
    ap.add_argument("--iterations", type=int, default=4, help="adaptive rounds of the fold fits (4)")
    ap.add_argument("--held-out", nargs="+", choices=HELD_OUT, default=list(HELD_OUT))
    ap.add_argument("--figure-only", action="store_true", help="redraw the figure from coverage_by_size.csv")
    args = ap.parse_args()
    if not args.figure_only:
        t0 = time.time()
        table, per = run(args.held_out, args.draws, args.seed, args.n_per_release, args.iterations)
        for frame, path in ((table, TABLE), (per, RELEASES)):
            tmp = path.with_suffix(".tmp")
            frame.to_csv(tmp, index=False, float_format="%.4g")
            tmp.replace(path)
        print(f"total {time.time() - t0:.0f} s")
        print(table.drop(columns=["unit"]).round(3).to_string())
    plot(pd.read_csv(TABLE), FIGURE)


if __name__ == "__main__":
    main()
