"""Substrate presets from real data: a joint pooled calibration, and leave-one-dataset-out validation.

    python validation/presets/derive_presets.py fit --n-per-release 200          # the shipped priors
    python validation/presets/derive_presets.py loo --n-per-release 200 --site-spread assumed
    python validation/presets/derive_presets.py loo --kernel 3d --n-per-release 50
    python validation/presets/derive_presets.py loo --model contact-drag     # a variant: presets_loo_drag
    python validation/presets/derive_presets.py loo --model contact-measured --n-per-release 200 \
        --site-spread assumed                                              # blocks as measured: presets_loo_measured
    python validation/presets/derive_presets.py vt0 --n-per-release 50 --draws 40  # presets_vt0.csv

``--kernel 3d`` runs the Authume releases on the quarry's DEM with its zone raster (the 3-D kernel, the same
contact model; simulation/scenarios/authume/authume_3d.toml) and compares **plan runouts** (horizontal
distance of each stop from the release point: the surveyed stops lie 2.5-3.5 m above the terrain, so only plan
positions are used); Evans & Hungr's reach stays the 2-D cliff-over-talus section.  It needs the raw quarry
files (../shared/experiments-raw/authume-quarry) for the release points.

The data sets (each cited in tests/data/<source>/README.md):

* ``authume_p1``, ``authume_p2`` -- the Authume quarry block releases (Garcia et al. 2022, Engineering Geology
  310:106855; richefeu/AuthumeQuarryRockfalls_Data-in-Brief f695c933): 41 and 48 real blocks, each a release on
  its profile's 2-D section with its measured mass (``--model contact-measured``: rolling as the cylinder of its
  measured sizes, :func:`simulation.units.box_rolling_cylinder`; tests/data/authume/observed_runout.csv).  The
  zones of the terrain are mapped to presets: Blue (vegetated slope) = ``soil``, Gray (hard rock walls and
  benches) = ``bedrock``, Red (rocky slope) = ``talus``.
* ``evans_hungr_1993`` -- the empirical minimum shadow angle of talus slopes, 27.5 deg (Evans & Hungr 1993,
  Can. Geotech. J. 30:620, abstract; tests/data/evans_hungr1993/README.md), as a reach constraint
  (:class:`simulation.pooled.ReachConstraint`) on an 80 m cliff at 70 deg over a 34 deg talus 60 m high (the
  geometry of simulation/scenarios/cliff_talus_deposition.toml) with the presets ``bedrock``, ``talus`` and
  ``soil``; standard deviation 2.0 deg [assumption: the spread of the far limit between sites, chosen so that
  the fatal impacts at 30 deg or more of the same abstract lie within 1.25 sd].

Every scenario uses the presets with the contact laws of ``CONTACT_LAWS`` put over them (``--model presets``:
their own laws) and ``settings.max_rolling_slope_deg = 55`` (no rolling in contact down faces steeper than
55 deg; simulation/contact.py).  The fitted fields are the five the data constrain: the rolling-resistance
angles of soil, bedrock and talus and the tangential coefficients of soil and bedrock (with ``--model presets``
bedrock keeps Stronge's law, so its e_T is not fitted).  The shipped priors come from
``fit --n-per-release 200``: at 100 the joint fit falls back to ABC rejection with a small effective sample.

``loo`` (2-D) also predicts a data set none of the fits saw: the Modified Ritchie width of the ODOT 60 ft cut
(simulation/scenarios/odot_catchment_cut.toml, W = 0.2 H + 4.5 m = 8.16 m), from the shipped priors.

``fit`` fits all data sets jointly and writes simulation/preset_priors.py (posterior summary and a 200-draw
sample per fitted field); ``loo`` fits every data set's complement and predicts the held-out one, writing
docs/validation/presets_loo.csv, the folds' posteriors docs/validation/presets_loo_parameters.csv and
docs/validation/figures/presets_loo.png.  ``vt0`` predicts every data set in-sample from the shipped priors with
one Pfeiffer & Bowen scale put on some of the materials instead of CRSP's (:func:`vt0_sensitivity`,
docs/validation/presets_vt0.csv).
"""
from __future__ import annotations

import argparse
import copy
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(REPO))

from simulation.calibration import scenario_dict  # noqa: E402
from simulation.contact import CRSP_TANGENTIAL_SCALE_MS  # noqa: E402
from simulation.materials import material_parameter, parameter_materials, parameter_sets_any  # noqa: E402
from simulation.material_uncertainty import with_site_spread  # noqa: E402
from simulation.pooled import ReachConstraint, Release, _ConstraintPool, _density, _Pool, calibrate_pooled  # noqa: E402
from simulation.units import (DEFAULT_DENSITY_KG_M3, DENSITY_RANGE_KG_M3, block_radius,  # noqa: E402
                              box_rolling_cylinder)

AUTHUME = REPO / "simulation" / "scenarios" / "authume"          # the quarry's scenarios and DEM
AUTHUME_SCRIPTS = REPO / "validation" / "authume"                # build_authume_3d, validate_authume_3d
OBSERVED = REPO / "tests" / "data" / "authume" / "observed_runout.csv"
ZONE_PRESET = {"vegetated_slope": "soil", "hard_ground": "bedrock", "rocky_slope": "talus"}
SETTINGS = {"max_rolling_slope_deg": 55.0}

#: The contact model the data-derived presets use (``--model contact``, the default): the laws of
#: simulation/contact.py that make the contact velocity a numerical setting -- Wyllie's e_T bounded by Coulomb
#: friction (mu = tan 35 deg on natural ground, tan 30 deg on rock: the presets' friction angles) and scaled by
#: Pfeiffer & Bowen's normal-velocity factor with CRSP's published scale (76.2 m/s; not fitted), hop heights
#: equal to the preset's roughness, and the size term of the rolling resistance (K = 1: tan(phi_g) + roughness / r)
#: -- put over each preset's own table.  ``--model presets`` uses the presets' own laws unchanged.
CONTACT_LAWS = {
    "soil": {"tangential": {"law": "coulomb", "mean": 0.55, "std": 0.12, "friction_angle_deg": 35.0, "std_deg": 3.0,
                            "normal_scale_ms": CRSP_TANGENTIAL_SCALE_MS},
             "contact_hop_height_m": 0.1, "rolling_size_coefficient": 1.0},
    "bedrock": {"tangential": {"law": "coulomb", "mean": 0.55, "std": 0.12, "friction_angle_deg": 30.0,
                               "std_deg": 3.0, "normal_scale_ms": CRSP_TANGENTIAL_SCALE_MS},
                "contact_hop_height_m": 0.1, "rolling_size_coefficient": 1.0},
    "talus": {"tangential": {"law": "coulomb", "mean": 0.55, "std": 0.12, "friction_angle_deg": 35.0,
                             "std_deg": 3.0, "normal_scale_ms": CRSP_TANGENTIAL_SCALE_MS},
              "contact_hop_height_m": 0.3, "rolling_size_coefficient": 1.0},
}
MODEL = {"laws": CONTACT_LAWS, "name": "contact"}

#: The fitted preset fields and their uniform priors (wide: the published ranges sit inside them).
PARAMETERS = {"materials.soil.ground_friction_angle_deg": (3.0, 45.0),
              "materials.soil.tangential.mean": (0.2, 1.0),
              "materials.bedrock.ground_friction_angle_deg": (3.0, 65.0),
              "materials.talus.ground_friction_angle_deg": (10.0, 50.0)}
#: With the contact model the bedrock's e_T is fitted as well (with the presets' own law it is Stronge's).
CONTACT_PARAMETERS = {**PARAMETERS, "materials.bedrock.tangential.mean": (0.2, 1.0)}
#: The size dependence of the rolling resistance (simulation.contact.rolling_resistance, the bounded size law
#: mu_0 + s c / sqrt(s^2 + c^2), s = K (roughness / r)^a): its coefficient K and exponent a, each one value shared by
#: the three presets (the law is about block size against the asperities; the roughness, a property of each
#: terrain, stays per material), fitted in the shipped model (``--model contact``) with uniform priors, K on 0-3
#: (0: no size dependence; Kirkby & Statham's K is of order 1) and a on 0.25-2 (1: Kirkby & Statham's d/D; at 0
#: the term would be a constant, the same as phi_g).  The Authume blocks span 0.25-0.55 m radius, a factor of two,
#: so the data constrain K and a only jointly and weakly: their posterior spread is carried in the shipped sample
#: (simulation/preset_priors.py SAMPLE) into every prediction that draws the presets' uncertainty, and it is what
#: widens the prediction for blocks smaller than any the fit saw (validation/presets/size_extrapolation.py).
SIZE_PARAMETER = {"materials.soil+bedrock+talus.rolling_size_coefficient": (0.0, 3.0),
                  "materials.soil+bedrock+talus.rolling_size_exponent": (0.25, 2.0)}
SHIPPED_PARAMETERS = {**CONTACT_PARAMETERS, **SIZE_PARAMETER}

#: Evans & Hungr (1993), Can. Geotech. J. 30:620-636, abstract: "An empirical minimum shadow angle of 27.5 deg
#: ... is suggested"; "rockfall fragments impacted on homes at equivalent shadow angles of 30 deg or more".
EH_SHADOW_ANGLE_DEG = 27.5
EH_SD_DEG = 2.0                     # assumption (see the module docstring)
EH_APEX = (39.118, 60.0)            # top of the talus [m] (x, z)


def authume_scenario(profile: str) -> dict:
    """The Authume section of ``profile`` with its zones named and valued by the presets."""
    data, _ = scenario_dict(AUTHUME / f"authume_{profile.lower()}.toml")
    data = copy.deepcopy(data)
    mats = data["profile"].get("materials")
    data["profile"]["materials"] = [ZONE_PRESET[m] for m in mats]
    data["materials"] = {ZONE_PRESET[k]: _material(ZONE_PRESET[k]) for k in data["materials"]}
    data["name"] = f"authume_{profile.lower()}_presets"
    data.setdefault("settings", {}).update(SETTINGS)
    return data


def evans_hungr_scenario() -> dict:
    """An 80 m cliff at 70 deg over a 34 deg talus 60 m high and a flat run-out, materials by preset."""
    return {"name": "evans_hungr_talus_presets",
            "profile": {"x": [0.0, 10.0, EH_APEX[0], 128.072, 450.0], "z": [140.0, 140.0, EH_APEX[1], 0.0, 0.0],
                        "materials": ["bedrock", "bedrock", "talus", "soil"]},
            "materials": {k: _material(k) for k in ("bedrock", "talus", "soil")},
            "seeder": {"type": "line", "x": [10.2, 12.0], "height_m": 0.0,
                       "downslope_speed_ms": {"dist": "uniform", "low": 0.5, "high": 3.0},
                       "mass_kg": {"dist": "lognormal", "median": 2000, "sigma": 1.0, "max": 100000},
                       "density_kg_m3": DEFAULT_DENSITY_KG_M3},
            "settings": {"envelope_bins": 0, **SETTINGS}}


_SCEN = {}


def _material(name: str) -> dict:
    return {"preset": name, **copy.deepcopy(MODEL["laws"].get(name, {}))}


#: ``--kernel``: "2d" (the profile sections) or "3d" (the quarry DEM; see the module docstring).
KERNEL = {"name": "2d"}


def authume_scenario_3d(profile: str) -> dict:
    """The Authume DEM scenario of release ``profile`` with its zone raster mapped to the presets (Blue = soil,
    Gray = bedrock, Red = talus), each with the contact laws, and no rolling on faces steeper than 55 deg."""
    sys.path.insert(0, str(AUTHUME_SCRIPTS))
    from build_authume_3d import _raw_dir
    from validate_authume_3d import scenario_data
    data = scenario_data(profile, {k: _material(k) for k in ("soil", "bedrock", "talus")}, _raw_dir([]))
    codes = {"vegetated_slope": "soil", "hard_ground": "bedrock", "rocky_slope": "talus"}
    data["terrain"]["material_codes"] = {k: codes[v] for k, v in data["terrain"]["material_codes"].items()}
    data["name"] = f"authume_3d_{profile.lower()}_presets"
    data["settings"] = dict(SETTINGS)
    return data


def releases(profile: str, rows=None) -> list:
    """Every observed block of ``profile`` (P1 or P2) as a release with its measured mass: its stop x along the
    2-D section, or (``--kernel 3d``) its plan runout on the DEM; with ``--model contact-measured`` (2-D) each
    block rolls as the cylinder its measured sizes give (:func:`simulation.units.box_rolling_cylinder`)."""
    three_d = KERNEL["name"] == "3d"
    key = (profile, bool(MODEL["laws"]), three_d)
    if key not in _SCEN:
        _SCEN[key] = authume_scenario_3d(profile) if three_d else authume_scenario(profile)
    obs = pd.read_csv(OBSERVED) if rows is None else rows
    out = []
    for r in obs.itertuples():
        if r.profile != profile:
            continue
        body = {}
        if MODEL["name"] == "contact-measured" and not three_d:
            radius, aspect = box_rolling_cylinder(r.l1_m, r.l2_m, r.l3_m)
            body = {"radius_m": radius, "shape": "cylinder", "aspect_ratio": aspect}
            lo, hi = DENSITY_RANGE_KG_M3
            if not lo <= _density(r.mass_kg, radius, "cylinder", aspect) <= hi:
                # mass and sizes disagree (P1-3: 688 kg in a 0.75 x 0.45 x 0.40 m box, 5,097 kg/m^3): the
                # equivalent sphere of the measured mass at the presets' density
                body = {"radius_m": float(block_radius(r.mass_kg, DEFAULT_DENSITY_KG_M3)), "shape": "sphere",
                        "aspect_ratio": 1.0}
        out.append(Release(name=f"{r.profile}-{r.block}", scenario=_SCEN[key],
                           x_stop_m=[r.plan_runout_m if three_d else r.x_stop_m], mass_kg=r.mass_kg,
                           source=str(OBSERVED.relative_to(REPO)), **body))
    return out


def evans_hungr() -> ReachConstraint:
    key = ("EH", bool(MODEL["laws"]))
    if key not in _SCEN:
        _SCEN[key] = evans_hungr_scenario()
    return ReachConstraint(name="evans_hungr_1993", scenario=_SCEN[key], apex_x_m=EH_APEX[0],
                           apex_z_m=EH_APEX[1], shadow_angle_deg=EH_SHADOW_ANGLE_DEG, sd_deg=EH_SD_DEG,
                           quantile=0.99, n_blocks=200, source="tests/data/evans_hungr1993/README.md")


DATASETS = ("authume_p1", "authume_p2", "evans_hungr_1993")


def fit(datasets, n_per_release=50, seed=1, n_predictive=20, iterations=4):
    rel, con = [], []
    for d in datasets:
        if d == "evans_hungr_1993":
            con.append(evans_hungr())
        elif d == "odot_ritchie_rule":
            con.append(ritchie_constraint())
        else:
            rel.extend(releases(d.split("_")[1].upper()))
    params = {k: v for k, v in _parameters().items()
              if any(parameter_sets_any(k, r.scenario["materials"]) for r in rel)
              or any(parameter_sets_any(k, c.scenario["materials"]) for c in con)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate_pooled(rel, params, seed=seed, n_per_release=n_per_release, n_initial=1024,
                                n_per_iteration=256, iterations=iterations, n_predictive=n_predictive,
                                obs_error_m=2.0,
                                constraints=con)


#: ``--model contact-drag``: the soil's velocity-squared rolling drag kappa fitted as well (RAMMS-like ploughing of
#: soft ground; simulation.contact), a variant tried for the transfer between the two Authume profiles.
DRAG_PARAMETERS = {**CONTACT_PARAMETERS, "materials.soil.rolling_drag": (0.0, 0.05)}


#: ``--model contact-sizedrag``: the soil's rolling resistance without a constant term (phi_g = 0), only the size
#: term K roughness / r (K fitted, 0-4) and the v^2 drag kappa (fitted): resistance from asperities and from
#: ploughing or vegetation, a variant tried for the transfer between the two Authume profiles.
SIZEDRAG_PARAMETERS = {k: v for k, v in DRAG_PARAMETERS.items() if k != "materials.soil.ground_friction_angle_deg"}
SIZEDRAG_PARAMETERS["materials.soil.rolling_size_coefficient"] = (0.0, 4.0)


#: ``--model contact-vscale``: the rock's Pfeiffer & Bowen velocity scale vt0 fitted as well (instead of CRSP's
#: 76.2 m/s): how much of its tangential speed a block keeps after a hard landing on rock, a variant tried for the
#: transfer between the two Authume profiles (P1's blocks land on their rock bench after a 16 m free fall, P2's
#: reach theirs down a rocky step at a shallower angle).
VSCALE_PARAMETERS = {**CONTACT_PARAMETERS, "materials.bedrock.tangential.normal_scale_ms": (3.0, 80.0)}


#: ``--model contact-vscale-tied``: one vt0 shared by the rock and the talus (``materials.bedrock+talus....``), so that
#: the Evans & Hungr cliff's landings on its talus inform the rock's bench landings as well.
VSCALE_TIED_PARAMETERS = {**CONTACT_PARAMETERS, "materials.bedrock+talus.tangential.normal_scale_ms": (3.0, 80.0)}


#: ``--model contact-measured``: the contact model with every Authume block rolling as the cylinder of its measured
#: sizes (:func:`simulation.units.box_rolling_cylinder`) instead of the sphere of its mass, a variant tried for the
#: transfer between the two Authume profiles.  The rock's phi_g starts at 0: beside the size term roughness / r it
#: is only the resistance beyond the asperities (with the 3 deg floor of ``PARAMETERS`` the joint fit put 19 % of
#: its posterior within 1 % of it).
MEASURED_PARAMETERS = {**CONTACT_PARAMETERS, "materials.bedrock.ground_friction_angle_deg": (0.0, 65.0)}


#: ``--model`` -> (its own fitted fields, or None for those of the laws in use; the suffix of its LOO table's name).
MODELS = {"contact": (SHIPPED_PARAMETERS, ""), "presets": (None, "_own_laws"), "contact-drag": (DRAG_PARAMETERS, "_drag"),
          "contact-sizedrag": (SIZEDRAG_PARAMETERS, "_sizedrag"), "contact-vscale": (VSCALE_PARAMETERS, "_vscale"),
          "contact-vscale-tied": (VSCALE_TIED_PARAMETERS, "_vscale_tied"),
          "contact-measured": (MEASURED_PARAMETERS, "_measured")}


def _parameters() -> dict:
    own = MODELS[MODEL["name"]][0]
    if own is not None:
        return own
    return CONTACT_PARAMETERS if MODEL["laws"] else PARAMETERS


def write_priors(cal, path: Path, datasets, args):
    summ = cal.summary()
    sample = cal.posterior.sample(200, random_state=1).reset_index(drop=True)
    lines = ['"""Data-derived priors of the substrate presets -- GENERATED by',
             f'validation/presets/derive_presets.py fit --n-per-release {args.n_per_release} --seed {args.seed} '
             f'--model {args.model}' + (f' --iterations {args.iterations}' if args.iterations != 4 else ''),
             f'(data sets: {", ".join(datasets)}; do not edit by hand)."""', "",
             f"DATASETS = {tuple(datasets)!r}",
             "#: preset -> the contact laws put over the preset's table before the fitted fields (see derive_presets.py).",
             f"LAWS = {MODEL['laws']!r}",
             f"NOTES = {tuple(cal.notes)!r}",
             "#: field -> posterior summary (mean, sd, median, q05, q95) and the uniform prior's bounds.",
             "SUMMARY = {"]
    for k in summ.index:
        r = summ.loc[k]
        lines.append(f"    {k!r}: {{'mean': {r['mean']:.4g}, 'sd': {r['sd']:.4g}, 'median': {r['median']:.4g}, "
                     f"'q05': {r['q05']:.4g}, 'q95': {r['q95']:.4g}, 'bounds': {tuple(cal.bounds[k])!r}}},")
    lines.append("}")
    lines.append("#: 200 posterior draws (joint: keep rows together), one list per field.")
    lines.append("SAMPLE = {")
    for k in sample.columns:
        lines.append(f"    {k!r}: [" + ", ".join(f"{v:.4g}" for v in sample[k]) + "],")
    lines.append("}")
    path.write_text("\n".join(lines) + "\n")


def _drawn(draws) -> dict:
    """The fitted fields the posterior ``draws`` set (none for the published presets' single empty draw), with
    their prior bounds: a field only some laws take (``tangential.normal_scale_ms``) is not set over the presets'
    own laws."""
    return {k: b for k, b in _parameters().items() if any(k in d for d in draws)}


#: Blocks per release and posterior draw in the LOO predictions (40 draws: 400 per release), blocks per release
#: for the published presets (one parameter set, the same 400), and the first seed of those predictions.
N_EACH_FITTED, N_EACH_PUBLISHED, PREDICT_SEED = 10, 400, 50_000


def predict_release_stops(rels, draws, n_each, seed0):
    P = _drawn(draws)
    # a field shared by several materials (``materials.A+B.FIELD``) is set on those of them the releases' scenario
    # has: a profile without talus still takes the shared value of its soil and rock
    fitted = {m for k in P for m in parameter_materials(k)}
    pool = _Pool(rels, {k: P[k] for k in P if parameter_sets_any(k, rels[0].scenario["materials"])},
                 extra_materials=fitted)
    per = [[] for _ in rels]
    for t, values in enumerate(draws):
        vals = {k: v for k, v in values.items() if k in pool.bounds}
        for i, s in enumerate(pool.simulate(vals, n_each, seed0 + t)):
            per[i].append(s)
    return [np.concatenate(p) for p in per]


def release_quantiles(per_release, q: float) -> np.ndarray:
    """Each release's predictive ``q`` quantile: one value per release of ``per_release`` (its simulated stops
    over every posterior draw, :func:`predict_release_stops`) [m]."""
    return np.array([np.quantile(s, q) for s in per_release])


def beyond_share(observed, bound) -> float:
    """Share of the observed stops beyond their own release's predictive bound (``observed > bound``, element by
    element; the ``beyond_p95`` / ``beyond_p99`` columns of the LOO tables)."""
    return float(np.mean(np.asarray(observed) > np.asarray(bound)))


def median_error_pct(predicted_median, observed_median) -> float:
    """Relative error of the predicted median against the observed one [%] (the ``median_error_pct`` column)."""
    return 100.0 * (predicted_median / observed_median - 1.0)


def release_row(dataset, model, per_release, rels):
    obs = np.array([r.x_stop_m[0] for r in rels])
    pred = np.concatenate(per_release)
    p95 = release_quantiles(per_release, 0.95)
    p99 = release_quantiles(per_release, 0.99)
    qo, qp = np.quantile(obs, [0.1, 0.5, 0.9]), np.quantile(pred, [0.1, 0.5, 0.9])
    return {"held_out": dataset, "model": model, "observations": obs.size,
            "obs_p10": qo[0], "obs_p50": qo[1], "obs_p90": qo[2], "pred_p10": qp[0], "pred_p50": qp[1],
            "pred_p90": qp[2], "median_error_pct": median_error_pct(qp[1], qo[1]),
            "ks_d": stats.ks_2samp(pred, obs).statistic, "w1": stats.wasserstein_distance(pred, obs),
            "beyond_p95": beyond_share(obs, p95), "beyond_p99": beyond_share(obs, p99),
            "unit": "m (plan runout, 3-D)" if KERNEL["name"] == "3d" else "m (stop x)"}, (obs, pred)


#: The ODOT 60 ft cut (simulation/scenarios/odot_catchment_cut.toml): its face and catchment are the data-derived
#: bedrock and soil presets, so a posterior draw of those presets' fields is applied to the scenario's materials.
ODOT_CUT = REPO / "simulation" / "scenarios" / "odot_catchment_cut.toml"
ODOT_MATERIALS = {"bedrock": "rock", "soil": "catchment"}
ODOT_CUT_HEIGHT_M = 18.3                                  # 60 ft
#: The models whose laws are the shipped ones (those the scenario's ``preset_basis = "data"`` materials carry; the
#: fitted fields are set over them): the ODOT row is predicted for them, from the shipped priors or the model's own
#: fit on all three data sets.
ODOT_MODELS = ("contact", "contact-measured", "contact-vscale", "contact-vscale-tied")


def ritchie_row(posterior, model, n_draws, seed):
    """A data set none of the fits saw: the Modified Ritchie width of the ODOT 60 ft cut (W = 0.2 H + 4.5 m = 8.16 m,
    Ryan & Pryor 2000), against the 90 % retention width predicted from ``posterior`` (a fit on all three data
    sets), one re-simulation of 600 blocks per posterior draw (``n_draws``).  ``posterior=None``: the cut's
    presets as published (``preset_basis`` dropped, nothing fitted), ``n_draws`` runs of 600 blocks."""
    import simulation
    from riskrf.hazard.catchment import catchment_retention, modified_ritchie_width_m
    from simulation.calibration import apply_parameters
    data, _ = scenario_dict(ODOT_CUT)
    if posterior is None:
        data = copy.deepcopy(data)
        for m in ODOT_MATERIALS.values():
            data["materials"][m].pop("preset_basis", None)
        records = [{}] * n_draws
    else:
        cols = [k for k in posterior.columns if parameter_sets_any(k, ODOT_MATERIALS)]
        records = posterior[cols].sample(n_draws, random_state=seed).to_dict("records")
    widths = []
    for t, d in enumerate(records):
        vals = {material_parameter(k, ODOT_MATERIALS[m]): v for k, v in d.items() for m in parameter_materials(k)
                if m in ODOT_MATERIALS}
        sc = simulation.scenario_from_dict(apply_parameters(data, vals), str(ODOT_CUT))
        widths.append(catchment_retention(sc, n=600, seed=70_000 + t).widths[90.0])
    w = np.asarray(widths)
    obs = modified_ritchie_width_m(ODOT_CUT_HEIGHT_M)
    q = np.quantile(w, [0.1, 0.5, 0.9])
    return {"held_out": "odot_ritchie_rule", "model": model, "observations": 1,
            "obs_p10": np.nan, "obs_p50": obs, "obs_p90": np.nan, "pred_p10": q[0], "pred_p50": q[1],
            "pred_p90": q[2], "median_error_pct": median_error_pct(q[1], obs), "ks_d": np.nan,
            "w1": float(np.mean(np.abs(w - obs))), "beyond_p95": float(obs > np.quantile(w, 0.95)),
            "beyond_p99": float(obs > np.quantile(w, 0.99)),
            "unit": "m (90 % retention width, 60 ft ODOT cut)"}, w


#: ``--with-ritchie``: the Modified Ritchie width of the ODOT 60 ft cut as a fourth data set, a reach constraint
#: (the shadow angle from the cut's crest of the simulated stops' 90 % quantile, Gaussian about the angle of the
#: rule's width) with this standard deviation in width [m] -- an ASSUMPTION: the rule is a design fit to ODOT's and
#: mine benches' rollout, and its spread about them is not published in what could be read here.
RITCHIE_SD_M = 1.5


def ritchie_constraint() -> ReachConstraint:
    """The ODOT 60 ft cut (its face the ``bedrock`` preset, its catchment ``soil``, with the model's laws) and the
    Modified Ritchie width W = 0.2 H + 4.5 m = 8.16 m as the far limit of 90 % of the stops beyond the toe."""
    from riskrf.hazard.catchment import modified_ritchie_width_m
    key = ("ODOT", bool(MODEL["laws"]))
    if key not in _SCEN:
        data, _ = scenario_dict(ODOT_CUT)
        data = copy.deepcopy(data)
        preset_of = {v: k for k, v in ODOT_MATERIALS.items()}                  # rock -> bedrock, catchment -> soil
        data["profile"]["materials"] = [preset_of.get(m, m) for m in data["profile"]["materials"]]
        data["materials"] = {preset_of.get(k, k): (_material(preset_of[k]) if k in preset_of else v)
                             for k, v in data["materials"].items()}
        data["name"] = "odot_cut_presets"
        data["settings"] = {**data.get("settings", {}), **SETTINGS}
        data.pop("collectors", None)
        _SCEN[key] = data
    data = _SCEN[key]
    crest_x, crest_z = data["profile"]["x"][1], data["profile"]["z"][1]
    toe_x = data["profile"]["x"][2]
    w = modified_ritchie_width_m(ODOT_CUT_HEIGHT_M)
    angle = float(np.degrees(np.arctan2(crest_z, toe_x + w - crest_x)))
    sd = float(np.degrees(np.arctan2(crest_z, toe_x + w - RITCHIE_SD_M - crest_x))) - angle
    return ReachConstraint(name="odot_ritchie_rule", scenario=data, apex_x_m=crest_x, apex_z_m=crest_z,
                           shadow_angle_deg=angle, sd_deg=sd, quantile=0.90, n_blocks=200,
                           source="riskrf.hazard.catchment.modified_ritchie_width_m (Ryan & Pryor 2000)")


def evans_hungr_angles(draws, repeats=1):
    """The Evans & Hungr reach constraint and the shadow angle [deg] of the simulated p99 stop on its section, one
    per posterior draw and repeat (200 blocks each, seeds 30,000 + 100 t + repeat), with the laws of ``MODEL``."""
    c = evans_hungr()
    cp = _ConstraintPool([c], _drawn(draws))
    angles = [cp.far_angles(cp.simulate(v, 30_000 + 100 * t + rep))[0]
              for t, v in enumerate(draws) for rep in range(repeats)]
    return c, angles


def constraint_row(model, cons, angles):
    a = np.asarray(angles)
    q = np.quantile(a, [0.1, 0.5, 0.9])
    return {"held_out": "evans_hungr_1993", "model": model, "observations": 1, "obs_p10": np.nan,
            "obs_p50": cons.shadow_angle_deg, "obs_p90": np.nan, "pred_p10": q[0], "pred_p50": q[1],
            "pred_p90": q[2], "median_error_pct": median_error_pct(q[1], cons.shadow_angle_deg),
            "ks_d": np.nan, "w1": float(np.mean(np.abs(a - cons.shadow_angle_deg))),
            "beyond_p95": float(cons.shadow_angle_deg < np.quantile(a, 0.05)),
            "beyond_p99": float(cons.shadow_angle_deg < np.quantile(a, 0.01)),
            "unit": "deg (shadow angle of the p99 stop)"}, a


def fold_parameters(held, train, cal) -> pd.DataFrame:
    """The posterior of one fold (fitted on ``train``, ``held`` held out): one row per fitted field with its median,
    90 % interval, posterior sd / prior sd and how the posterior was drawn (``<out>_parameters.csv``)."""
    s = cal.summary()[["median", "q05", "q95", "sd_ratio"]].reset_index()
    s.insert(0, "fitted_on", " + ".join(train))
    s.insert(0, "held_out", held)
    s["posterior"] = "; ".join(cal.notes)
    return s


#: ``vt0`` mode: the Pfeiffer & Bowen scales [m/s] tried, and the materials each is put on (CRSP's 76.2 is the
#: shipped value).
VT0_VALUES_MS = (CRSP_TANGENTIAL_SCALE_MS, 50.0, 40.0, 30.0, 20.0)
VT0_MATERIALS = {"rock": ("bedrock",), "rock and talus": ("bedrock", "talus"), "soil": ("soil",),
                 "every material": ("bedrock", "talus", "soil")}
#: Where P1's stops on and above its first bench end [m along the section]: 24 of the 41 observed blocks stop
#: before it (20 on the bench by their surveyed height, 2 above it, 2 at the foot of the second wall that project
#: to 41.6 and 43.2 m, short of that wall's foot at about 44.5 m; tests/data/authume/observed_runout.csv), none
#: between 44.2 and 48.2 m.
AUTHUME_P1_BENCH_END_M = 46.0


def vt0_sensitivity(n_draws: int, n_each: int, seed: int) -> pd.DataFrame:
    """In-sample: every data set predicted from the shipped priors with one Pfeiffer & Bowen scale vt0 put on the
    materials of each :data:`VT0_MATERIALS` entry instead of CRSP's 76.2 m/s -- what a transferable hard-landing
    loss would have to be, and how each data set responds to it (``vt0`` mode; docs/validation/presets_vt0.csv).

    ``n_draws`` joint draws of the shipped posterior (the same for every row), ``n_each`` blocks per Authume
    release and draw; Evans & Hungr one 200-block run per draw; the ODOT cut one 600-block run per draw."""
    from simulation.material_uncertainty import preset_posterior
    draws = preset_posterior().sample(n_draws, random_state=seed).to_dict("records")
    shipped = copy.deepcopy(CONTACT_LAWS)
    rows = []
    try:
        for where, mats in VT0_MATERIALS.items():
            for vt0 in VT0_VALUES_MS:
                if vt0 == CRSP_TANGENTIAL_SCALE_MS and rows:
                    continue                                        # the shipped model: one row
                CONTACT_LAWS.clear()
                CONTACT_LAWS.update(copy.deepcopy(shipped))
                for m in mats:
                    CONTACT_LAWS[m]["tangential"]["normal_scale_ms"] = vt0
                _SCEN.clear()
                row = {"vt0_ms": vt0, "on": "every material (shipped)" if vt0 == CRSP_TANGENTIAL_SCALE_MS else where}
                for prof in ("P1", "P2"):
                    rels = releases(prof)
                    r, (_, pred) = release_row(prof, "", predict_release_stops(rels, draws, n_each, PREDICT_SEED), rels)
                    row[f"{prof}_median_error_pct"] = r["median_error_pct"]
                    row[f"{prof}_beyond_p99_pct"] = 100.0 * r["beyond_p99"]
                    row[f"{prof}_w1_m"] = r["w1"]
                    if prof == "P1":
                        row["P1_before_bench_end_pct"] = 100.0 * float(np.mean(pred < AUTHUME_P1_BENCH_END_M))
                _, angles = evans_hungr_angles(draws)
                row["eh_p99_shadow_angle_deg"] = float(np.median(angles))
                post = pd.DataFrame(draws)
                for m in [m for m in ODOT_MATERIALS if m in mats]:    # the ODOT cut's face and floor take it too
                    post[f"materials.{m}.tangential.normal_scale_ms"] = vt0
                r, _ = ritchie_row(post, "", n_draws, seed)
                row["odot_width_m"] = r["pred_p50"]
                row["odot_width_error_pct"] = r["median_error_pct"]
                rows.append(row)
                print({k: (round(v, 2) if isinstance(v, float) else v) for k, v in row.items()}, flush=True)
    finally:
        CONTACT_LAWS.clear()
        CONTACT_LAWS.update(shipped)
        _SCEN.clear()
    return pd.DataFrame(rows)


def plot_vt0(table: pd.DataFrame, path: Path):
    """Each data set's in-sample error against vt0 (the ``vt0`` mode's figure), the targets shaded."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from riskrf.hazard.catchment import modified_ritchie_width_m
    shipped = table[table["vt0_ms"] == CRSP_TANGENTIAL_SCALE_MS]
    obs = pd.read_csv(OBSERVED)
    p1_before = 100.0 * float(np.mean(obs.loc[obs["profile"] == "P1", "x_stop_m"] < AUTHUME_P1_BENCH_END_M))
    w_mrc = modified_ritchie_width_m(ODOT_CUT_HEIGHT_M)
    # (column, title, shaded target band, observed value or None)
    panels = [("P1_before_bench_end_pct", f"Authume P1: stops before x = {AUTHUME_P1_BENCH_END_M:g} m [%]", None,
               p1_before),
              ("P1_median_error_pct", "Authume P1: median error [%]", (-20, 20), None),
              ("P2_w1_m", "Authume P2: W1 to the observed stops [m]", None, None),
              ("eh_p99_shadow_angle_deg", "Evans & Hungr: p99 shadow angle [deg]",
               (0.8 * EH_SHADOW_ANGLE_DEG, 1.2 * EH_SHADOW_ANGLE_DEG), EH_SHADOW_ANGLE_DEG),
              ("odot_width_m", "ODOT 60 ft cut: 90 % width [m]", (0.8 * w_mrc, 1.2 * w_mrc), w_mrc)]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.8))
    for ax, (col, title, band, observed) in zip(axes, panels):
        if band is not None:
            ax.axhspan(*band, color="0.9", label="target (+-20 %)")
        if observed is not None:
            ax.axhline(observed, color="k", lw=1.5, label="observed / published")
        for (where, mats), colour in zip(VT0_MATERIALS.items(), ("C1", "C3", "C2", "C0")):
            t = pd.concat([shipped, table[table["on"] == where]]).sort_values("vt0_ms")
            ax.plot(t["vt0_ms"], t[col], "o-", color=colour, label=f"vt0 on {where}")
        ax.set_xlabel("Pfeiffer & Bowen scale vt0 [m/s] (CRSP: 76.2)")
        ax.set_title(title, fontsize="small")
    axes[0].legend(fontsize="x-small")
    fig.suptitle("In-sample, the shipped priors with one hard-landing scale vt0 (derive_presets.py vt0); lines that "
                 "coincide hide each other (P1 has no talus; the ODOT blocks land on soil)", fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["fit", "loo", "vt0"])
    ap.add_argument("--n-per-release", type=int, default=50)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--draws", type=int, default=40)
    ap.add_argument("--model", choices=list(MODELS), default="contact")
    ap.add_argument("--site-spread", choices=["none", "assumed"], default="none",
                    help="add to every posterior draw the ASSUMED site-to-site spread of "
                         "simulation.material_uncertainty (uniform, its half-widths) before predicting")
    ap.add_argument("--kernel", choices=["2d", "3d"], default="2d",
                    help="the Authume releases on their 2-D sections or on the quarry DEM (plan runouts)")
    ap.add_argument("--out", default=None,
                    help="name of the LOO table and figure in docs/validation (default: presets_loo, with _3d for "
                         "--kernel 3d and _own_laws, _drag or _sizedrag for the other models, the names the "
                         "validation page cites)")
    ap.add_argument("--with-ritchie", action="store_true",
                    help="add the Modified Ritchie width of the ODOT 60 ft cut as a fourth data set (a reach "
                         "constraint, ritchie_constraint; held out in its own fold) instead of a check no fit saw")
    ap.add_argument("--iterations", type=int, default=4,
                    help="adaptive rounds of 256 parameter sets after the 1,024-point Sobol design (default 4)")
    args = ap.parse_args()
    datasets = DATASETS + (("odot_ritchie_rule",) if args.with_ritchie else ())
    out_given = args.out
    if args.out is None:
        args.out = ("presets_loo" + MODELS[args.model][1] + ("_3d" if args.kernel == "3d" else "")
                    + ("_ritchie" if args.with_ritchie else ""))
    KERNEL["name"] = args.kernel
    MODEL["name"] = args.model
    if args.model == "presets":
        MODEL["laws"] = {}
    if args.model == "contact-sizedrag":
        MODEL["laws"] = copy.deepcopy(MODEL["laws"])
        MODEL["laws"]["soil"]["ground_friction_angle_deg"] = 0.0
    t0 = time.time()
    if args.mode == "vt0":
        given = {"--model": (args.model, "contact"), "--kernel": (args.kernel, "2d"),
                 "--with-ritchie": (args.with_ritchie, False), "--out": (out_given, None)}
        wrong = [f"{k} {v!r}" for k, (v, default) in given.items() if v != default]
        if wrong:
            ap.error(f"vt0 uses the shipped model on the 2-D sections and writes presets_vt0.csv: {', '.join(wrong)} "
                     "does not apply")
        table = vt0_sensitivity(args.draws, args.n_per_release, args.seed)
        table.to_csv(REPO / "docs" / "validation" / "presets_vt0.csv", index=False, float_format="%.4g")
        print(f"total {time.time() - t0:.0f} s")
        print(table.round(1).to_string())
        plot_vt0(table, REPO / "docs" / "validation" / "figures" / "presets_vt0.png")
        return
    if args.mode == "fit":
        cal = fit(datasets, args.n_per_release, args.seed, iterations=args.iterations)
        print(f"fit {time.time() - t0:.0f} s")
        print(cal.summary()[["median", "mean", "sd", "q05", "q95", "sd_ratio"]].round(3).to_string())
        print(cal.correlations().round(2).to_string())
        print(cal.coverage().to_dict(), cal.constraint_table.round(2).to_string(), cal.notes)
        if args.kernel == "2d" and args.model == "contact":    # the shipped priors; other fits are printed only
            write_priors(cal, REPO / "simulation" / "preset_priors.py", datasets, args)
        return
    rows, curves, folds = [], {}, []
    for held in datasets:
        train = [d for d in datasets if d != held]
        cal = fit(train, args.n_per_release, args.seed, n_predictive=0, iterations=args.iterations)
        print(held, f"fitted on {train} {time.time() - t0:.0f} s")
        print(cal.summary()[["median", "q05", "q95", "sd_ratio"]].round(3).to_string(), cal.notes)
        folds.append(fold_parameters(held, train, cal))
        draws = cal.posterior.sample(args.draws, random_state=args.seed).to_dict("records")
        label = "fitted on " + " + ".join(train)
        variants = [(label, draws, True)]
        if args.site_spread == "assumed":
            spread = with_site_spread(pd.DataFrame(draws), cal.bounds, args.seed).to_dict("records")
            variants.append((label + " + assumed site-to-site spread", spread, True))
        if held != "odot_ritchie_rule":                     # (the Ritchie row of the published presets: below)
            variants.append(("published presets", [{}], False))
        for model, ds, fitted in variants:
            laws = MODEL["laws"]
            if not fitted:
                MODEL["laws"] = {}
            if held == "odot_ritchie_rule":
                r, cv = ritchie_row(pd.DataFrame(ds), model, len(ds), args.seed)
            elif held == "evans_hungr_1993":
                c, angs = evans_hungr_angles(ds, 1 if fitted else args.draws)
                MODEL["laws"] = laws
                r, cv = constraint_row(model, c, angs)
            else:
                rels = releases(held.split("_")[1].upper())
                MODEL["laws"] = laws
                n_each = N_EACH_FITTED if fitted else N_EACH_PUBLISHED
                r, cv = release_row(held, model, predict_release_stops(rels, ds, n_each, PREDICT_SEED), rels)
            rows.append(r)
            curves[(held, model)] = cv
        print(pd.DataFrame(rows).round(3).to_string())
    if args.kernel == "2d" and args.model in ODOT_MODELS and not args.with_ritchie:
        if args.model == "contact":                           # the shipped priors are the contact model's
            from simulation.material_uncertainty import preset_posterior
            label, post = "fitted on all three (the shipped priors)", preset_posterior(list(ODOT_MATERIALS))
        else:
            label, post = "fitted on all three", fit(DATASETS, args.n_per_release, args.seed, n_predictive=0,
                                                   iterations=args.iterations).posterior
        r, cv = ritchie_row(post, label, args.draws, args.seed)
        rows.append(r)
        curves[("odot_ritchie_rule", label)] = cv
    table = pd.DataFrame(rows)
    out = REPO / "docs" / "validation"
    table.to_csv(out / f"{args.out}.csv", index=False, float_format="%.4g")
    pd.concat(folds).to_csv(out / f"{args.out}_parameters.csv", index=False, float_format="%.4g")
    print(f"total {time.time() - t0:.0f} s")
    print(table.round(3).to_string())
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = [*DATASETS, *(["odot_ritchie_rule"] if any(h == "odot_ritchie_rule" for h, _ in curves) else [])]
    fig, axes = plt.subplots(1, len(panels), figsize=(5 * len(panels), 4.2))
    for ax, held in zip(axes, panels):
        for (h, model), c in curves.items():
            if h != held:
                continue
            style = "C0" if model == "published presets" else ("C2" if "site-to-site" in model else "C3")
            if held == "odot_ritchie_rule":
                ax.hist(c, bins=12, alpha=0.5, color=style, label=model, density=True)
            elif held == "evans_hungr_1993":
                ax.hist(c, bins=15, alpha=0.5, color=style, label=model, density=True)
            else:
                obs, pred = c
                if model != "published presets" and "site-to-site" not in model:
                    o = np.sort(obs)
                    ax.step(o, np.arange(1, o.size + 1) / o.size, where="post", color="k", lw=2,
                            label=f"observed ({o.size})")
                p = np.sort(pred)
                ax.plot(p, np.arange(1, p.size + 1) / p.size, color=style, label=model)
        if held == "odot_ritchie_rule":
            from riskrf.hazard.catchment import modified_ritchie_width_m
            w_mrc = modified_ritchie_width_m(ODOT_CUT_HEIGHT_M)
            ax.axvline(w_mrc, color="k", lw=2, label=f"Modified Ritchie width {w_mrc:.2f} m")
            ax.set_xlabel("90 % retention width, ODOT 60 ft cut [m]")
            ax.set_ylabel("density over posterior draws")
        elif held == "evans_hungr_1993":
            ax.axvline(EH_SHADOW_ANGLE_DEG, color="k", lw=2, label="Evans & Hungr 27.5 deg")
            ax.set_xlabel("shadow angle of the p99 stop [deg]")
            ax.set_ylabel("density over posterior draws")
        else:
            ax.set_xlabel("plan runout [m]" if KERNEL["name"] == "3d" else "stop position x [m]")
            ax.set_ylabel("fraction of blocks stopped before x")
        ax.set_title(f"{held} held out", fontsize="small")
        ax.legend(fontsize="x-small")
    fig.tight_layout()
    fig.savefig(out / "figures" / f"{args.out}.png", dpi=110)


if __name__ == "__main__":
    main()
