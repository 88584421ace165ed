"""The trajectory model's uncertainty as draws of material parameters: from a posterior, or the presets' spread.

A design energy or a ranking computed with one set of material values says nothing about how much the answer
depends on those values.  This module gives the draws that carry that uncertainty forward
(:mod:`riskrf.hazard.model_uncertainty`, :mod:`riskrf.risk.model_decision`):

* **a posterior sample** written by :meth:`simulation.PooledCalibration.write` (read with
  :func:`simulation.read_posterior`, checked against the scenario's materials): ``draws`` of its rows are taken,
  keeping each row whole (the parameters' correlation is kept);
* **the presets' spread**: every material of the scenario that names a preset gets a range for each of the
  parameters below, centred on the material's own value (the preset's or the scenario's override), and
  ``draws`` points are laid over the box by Latin hypercube sampling (McKay, Beckman & Conover 1979,
  Technometrics 21:239: every parameter's range is cut into ``draws`` equal slices and each slice is drawn once).

The presets (:mod:`simulation.materials`) carry the impact-to-impact spread of their laws (e_N and e_T standard
deviations, the friction angle's ``std_deg``): that is the variability of one impact, not an uncertainty of the
law's mean.  No data-derived spread of the means ships with the presets yet, so the ranges below are
**ASSUMPTIONS**, labelled as such in every output (``basis`` of :func:`preset_spread`):

============================ ============================================== ====================================
parameter                    half-width                                     reading of the sources
============================ ============================================== ====================================
ground_friction_angle_deg    4 deg (bedrock, talus, scree, pavements),      talus slopes stand at 30-38 deg
                             6 deg (soil, colluvium, meadow)                (Kirkby & Statham 1975; Evans &
                                                                            Hungr 1993); rolling friction of
                                                                            soft ground 0.5-0.8, i.e. 27-39 deg
                                                                            (Dorren 2003)
normal_restitution.mean      the published range of the preset's e_N        Rockyfor3D soil types (Dorren 2016)
(constant law only)          (scree, soil 0.03; meadow 0.02; colluvium      and CRSP colluvium, as quoted in
                             0.01)                                          :mod:`simulation.materials`
tangential.mean              0.15 (e_T 0.40-0.70 about 0.55)                Wyllie (2014) e_T 0.3-0.8 per
(constant and Coulomb laws;                                                 impact; the mean's range assumed
the data-derived bedrock)
tangential.friction_angle_deg 5 deg (bedrock, pavements)                    basic friction angle of rock
(friction law only)                                                         25-35 deg (Barton & Choubey 1977)
tangential.normal_scale_ms   from 30 m/s up to the value (a bedrock whose   Authume P1's bench landings want
(bedrock only)               table carries a finite Pfeiffer & Bowen scale  about 30 m/s in-sample, the other
                             above 30 m/s: the data-derived tables,         profile 68 m/s, CRSP 76.2 m/s
                             ``preset(name, basis="data")``, carry 76.2;    (docs/validation/trajectories.md,
                             the soil's, where catchments land, is not      section 5); no data set here says
                             varied)                                        how an earth bench or catchment
                                                                            differs from CRSP's
============================ ============================================== ====================================

**Plugging in data-derived spreads.**  :data:`PRESET_SPREAD_SOURCES` is the list of functions consulted, first to
last, for each preset: ``source(preset, table) -> {field: (low, high, basis)}`` with ``table`` the material's
resolved table (its values after overrides) and ``field`` a dotted path inside it.  The first source that gives a
field decides it.  The default list holds :func:`assumed_spread` only; a data-derived source (e.g. one reading
``simulation.materials.preset_prior``) is put in front with ``PRESET_SPREAD_SOURCES.insert(0, source)`` and its
``basis`` text then replaces the word ASSUMPTION in every output for the fields it gives.

References
----------
McKay, M.D., Beckman, R.J. & Conover, W.J. (1979) Technometrics 21:239-245.  Kirkby, M.J. & Statham, I. (1975)
J. Geol. 83:349.  Evans, S.G. & Hungr, O. (1993) Can. Geotech. J. 30:620.  Dorren, L.K.A. (2003) Progr. Phys.
Geogr. 27:69.  Barton, N. & Choubey, V. (1977) Rock Mech. 10:1.  Wyllie, D.C. (2014) Rock Fall Engineering, ch. 5.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from .materials import ALIASES, PRESETS, PresetError, parameter_sets_any, resolve_material
from .materials import _unknown as materials_unknown
from .scenario import Scenario, ScenarioError, scenario_from_dict

#: Half-widths of the ASSUMED ranges of each preset's parameters (see the module docstring): preset -> field ->
#: half-width in the field's unit.  Only fields the preset's laws use are varied.
ASSUMED_HALF_WIDTHS: dict[str, dict[str, float]] = {
    "bedrock": {"ground_friction_angle_deg": 4.0, "tangential.friction_angle_deg": 5.0, "tangential.mean": 0.15},
    "talus": {"ground_friction_angle_deg": 4.0, "tangential.mean": 0.15},
    "scree": {"ground_friction_angle_deg": 4.0, "normal_restitution.mean": 0.03, "tangential.mean": 0.15},
    "colluvium": {"ground_friction_angle_deg": 6.0, "normal_restitution.mean": 0.01, "tangential.mean": 0.15},
    "soil": {"ground_friction_angle_deg": 6.0, "normal_restitution.mean": 0.03, "tangential.mean": 0.15},
    "meadow": {"ground_friction_angle_deg": 6.0, "normal_restitution.mean": 0.02, "tangential.mean": 0.15},
    "asphalt": {"ground_friction_angle_deg": 4.0, "tangential.friction_angle_deg": 5.0},
    "concrete": {"ground_friction_angle_deg": 4.0, "tangential.friction_angle_deg": 5.0},
}

#: Low end of the ASSUMED range of the rock's Pfeiffer & Bowen scale vt0 [m/s] (the high end is the table's value,
#: CRSP's 76.2 m/s in the data-derived presets): in-sample, the vt0 under which Authume P1's blocks stop before the
#: end of the bench below its first wall as often as observed (docs/validation/presets_vt0.csv: 57 % at 30 m/s,
#: observed 59 %).
ROCK_VT0_LOW_MS = 30.0

#: Words stated beside each assumed range.
ASSUMED_BASIS = {
    "ground_friction_angle_deg": "ASSUMPTION: +-{w:g} deg about the value (talus angles of repose 30-38 deg, "
                                 "Kirkby & Statham 1975; soft-ground rolling friction 27-39 deg, Dorren 2003)",
    "normal_restitution.mean": "ASSUMPTION: the published range of the preset's e_N (+-{w:g}) taken as the range "
                               "of its mean",
    "tangential.mean": "ASSUMPTION: +-{w:g} about the mean e_T (Wyllie 2014: 0.3-0.8 impact to impact)",
    "tangential.friction_angle_deg": "ASSUMPTION: +-{w:g} deg about the value (basic friction angle of rock "
                                     "25-35 deg, Barton & Choubey 1977)",
    "tangential.normal_scale_ms": "ASSUMPTION: the rock's Pfeiffer & Bowen scale from {low:g} m/s to the value "
                                  "({high:g} m/s): how much speed a block keeps when it lands on a rock bench; "
                                  "Authume P1's bench landings want about 30 m/s, the quarry's other profile 68 m/s, "
                                  "CRSP 76.2 m/s (docs/validation/trajectories.md, section 5); earth benches and "
                                  "catchments (the soil) are not varied",
}


def _get(table: dict, field: str):
    node = table
    for key in field.split("."):
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return node if isinstance(node, (int, float)) and not isinstance(node, bool) else None


def assumed_spread(preset: str, table: dict) -> dict:
    """The ASSUMED range of each parameter of ``preset`` that ``table`` (the material's resolved table) uses:
    {field: (low, high, basis)}, centred on the table's value (see :data:`ASSUMED_HALF_WIDTHS`); bounds kept
    >= 0 (restitution coefficients, angles).  One range is one-sided: a bedrock whose table carries a finite
    Pfeiffer & Bowen scale above :data:`ROCK_VT0_LOW_MS` gets that scale from :data:`ROCK_VT0_LOW_MS` up to its
    value (at or below it, or infinite, it is not varied).

    Parameters
    ----------
    preset : str
        Name of the material preset.
    table : dict
        The material's resolved table.

    Returns
    -------
    dict
        {field: (low, high, basis)}, bounds in the field's units.
    """
    out = {}
    for field, w in ASSUMED_HALF_WIDTHS.get(ALIASES.get(preset, preset), {}).items():
        v = _get(table, field)
        if v is None:               # the law in force does not use this field (e.g. e_N of Wyllie's law)
            continue
        out[field] = (max(float(v) - w, 0.0), float(v) + w, ASSUMED_BASIS[field].format(w=w))
    vt0 = _get(table, "tangential.normal_scale_ms")
    if ALIASES.get(preset, preset) == "bedrock" and vt0 is not None and ROCK_VT0_LOW_MS < vt0 < np.inf:
        out["tangential.normal_scale_ms"] = (ROCK_VT0_LOW_MS, float(vt0), ASSUMED_BASIS["tangential.normal_scale_ms"]
                                             .format(low=ROCK_VT0_LOW_MS, high=float(vt0)))
    return out


#: Functions consulted, first to last, for the spread of a preset's parameters (see the module docstring).
PRESET_SPREAD_SOURCES: list = [assumed_spread]


def site_spread_half_width(path: str) -> float:
    """The ASSUMED site-to-site half-width of a dotted preset field ``materials.<preset>.<field>`` (in the field's
    unit): :data:`ASSUMED_HALF_WIDTHS` of that preset and field, 0.15 for an e_T mean the preset's table does not
    list (Wyllie 2014: e_T 0.3-0.8), 0 for a field with no stated spread.

    Parameters
    ----------
    path : str
        Dotted field, e.g. ``materials.soil.ground_friction_angle_deg``.

    Returns
    -------
    float
        Half-width [the field's unit].
    """
    from .materials import parameter_materials
    parts = str(path).split(".", 2)
    if len(parts) != 3 or parts[0] != "materials":
        raise ValueError(f"site spread: field {path!r} is not a dotted preset field 'materials.<preset>.<field>'")
    field = parts[2]
    # a field shared by several presets (materials.a+b.FIELD) takes the widest of their half-widths
    return max(ASSUMED_HALF_WIDTHS.get(preset, {}).get(field, 0.15 if field == "tangential.mean" else 0.0)
               for preset in parameter_materials(path))


def with_site_spread(sample: pd.DataFrame, bounds: dict, seed=1) -> pd.DataFrame:
    """Posterior draws of preset fields for a site the calibration data did not sample.

    Each value is moved by a uniform amount within :func:`site_spread_half_width` of its field and kept inside
    the prior box ``bounds``.  A posterior fitted to a few sites measures what those sites share, not how much a
    new site differs from them: the two Authume profiles alone put soil's rolling-resistance angle 6.4 deg apart
    (11.8 and 18.2 deg) where each posterior's 90 % interval is 2.5-4.9 deg wide
    (docs/validation/trajectories.md, presets_loo_parameters.csv).  The
    half-widths are the ASSUMED ranges of :data:`ASSUMED_HALF_WIDTHS`.  In the leave-one-data-set-out check they
    bring the share of Authume P2's stops beyond their release's predictive p99 from 6.2 % to 0 %.

    Parameters
    ----------
    sample : pandas.DataFrame
        Posterior draws, one column per dotted field (:func:`preset_posterior`).
    bounds : dict
        Field -> (low, high) of its prior.
    seed : int, optional
        Random seed.

    Returns
    -------
    pandas.DataFrame
        The draws with the site-to-site spread added (same shape and columns).
    """
    rng = np.random.default_rng(seed)
    out = sample.copy()
    missing = [c for c in out.columns if c not in bounds]
    if missing:
        raise ValueError(f"site spread: bounds = {sorted(bounds)!r} give no prior box for column(s) {missing!r}")
    for col in out.columns:
        w = site_spread_half_width(col)
        lo, hi = bounds[col]
        out[col] = np.clip(out[col].to_numpy(float) + rng.uniform(-w, w, len(out)), lo, hi)
    return out


def preset_posterior(presets=None, *, new_site: bool = False, seed=1):
    """The joint posterior sample of the data-derived preset fields (200 draws; rows are joint draws, keep them
    together).  Columns are dotted scenario paths ``materials.<preset>.<field>``, usable as the parameters of
    ``[uncertainty.materials]`` draws or of :func:`simulation.pooled.read_posterior`-style propagation.

    Parameters
    ----------
    presets : list of str, optional
        Keep only the columns of these presets (aliases accepted).
    new_site : bool, optional
        Add the ASSUMED site-to-site spread (:func:`simulation.material_uncertainty.with_site_spread`): the draws
        for a site the calibration data did not sample.  The posterior alone is the uncertainty within the data
        sets; the leave-one-data-set-out check shows a new site differs by more.
    seed : int, optional
        Random seed of that spread.

    Returns
    -------
    pandas.DataFrame
    """
    from . import preset_priors
    df = pd.DataFrame(preset_priors.SAMPLE)
    if presets is not None:
        keys = []
        for n in presets:
            k = ALIASES.get(n, n)
            if k not in PRESETS:
                raise PresetError(materials_unknown(n, "preset", "<preset_posterior()>"))
            keys.append(k)
        df = df[[c for c in df.columns if parameter_sets_any(c, keys)]]
    if new_site:
        df = with_site_spread(df, {k: v["bounds"] for k, v in preset_priors.SUMMARY.items()}, seed)
    return df


def _scenario_data(scenario) -> tuple[dict, str, Path | None]:
    from .parameters import scenario_dict
    data, src = scenario_dict(scenario)
    base = Path(src).parent if Path(src).is_file() else None
    return data, src, base


def preset_spread(scenario) -> pd.DataFrame:
    """The range of every material parameter of ``scenario`` (TOML path, dict or Scenario loaded from a file)
    that the presets' spread covers.

    Parameters
    ----------
    scenario : str, pathlib.Path, dict or Scenario
        The scenario.

    Returns
    -------
    pandas.DataFrame
        Index ``parameter`` (dotted path ``materials.NAME.FIELD``); columns ``material``, ``preset``, ``value``
        (the scenario's), ``low``, ``high``, ``basis`` (the words of the source; "ASSUMPTION" for the assumed
        ranges) and ``assumption`` (bool).  Empty when no material names a preset.
    """
    data, src, _ = _scenario_data(scenario)
    rows = []
    for name, spec in (data.get("materials") or {}).items():
        if not isinstance(spec, dict) or "preset" not in spec:
            continue
        preset = ALIASES.get(spec["preset"], spec["preset"])
        if preset not in PRESETS:
            continue                 # the scenario reader names an unknown preset itself
        table = resolve_material(spec, f"materials.{name}", src)
        given = {}
        for source in PRESET_SPREAD_SOURCES:
            for field, rng in (source(preset, table) or {}).items():
                given.setdefault(field, rng)
        for field, (lo, hi, basis) in given.items():
            rows.append({"parameter": f"materials.{name}.{field}", "material": name, "preset": preset,
                         "value": _get(table, field), "low": float(lo), "high": float(hi), "basis": basis,
                         "assumption": "ASSUMPTION" in basis})
    cols = ["parameter", "material", "preset", "value", "low", "high", "basis", "assumption"]
    return pd.DataFrame(rows, columns=cols).set_index("parameter")


def material_draws(scenario, draws: int, *, posterior=None, seed=1) -> pd.DataFrame:
    """``draws`` joint draws of material parameters: rows of ``posterior`` (a DataFrame of dotted
    ``materials.NAME.FIELD`` columns, as :func:`simulation.read_posterior` returns) or, without one, a Latin
    hypercube over :func:`preset_spread` (uniform within each range).

    Parameters
    ----------
    scenario : path, dict or Scenario
        The slope whose materials are drawn.
    draws : int
        Number of draws (>= 2).  From a posterior: rows chosen without replacement (all of them, in a seeded
        order, when it has no more than ``draws`` rows).
    posterior : pandas.DataFrame, optional
        The posterior sample.
    seed : int
        Seed of the choice of rows or of the hypercube.

    Returns
    -------
    pandas.DataFrame
        One row per draw, one column per parameter; ``attrs["basis"]`` says where the draws come from and
        ``attrs["ranges"]`` holds the :func:`preset_spread` table (presets' spread only).
    """
    if isinstance(draws, bool) or not isinstance(draws, (int, np.integer)) or draws < 2:
        raise ValueError(f"draws = {draws!r} must be a whole number >= 2")
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), 23]))
    if posterior is not None:
        post = pd.DataFrame(posterior)
        if len(post) < 2:
            raise ValueError(f"the posterior has {len(post)} rows; at least 2 draws are needed")
        idx = rng.permutation(len(post))[:min(int(draws), len(post))]
        out = post.iloc[np.sort(idx)].reset_index(drop=True).astype(float)
        out.attrs["basis"] = (f"{len(out)} joint rows of a posterior sample of {len(post)} draws "
                              f"(columns: {', '.join(post.columns)})")
        return out
    spread = preset_spread(scenario)
    if spread.empty:
        _, src, _ = _scenario_data(scenario)
        raise ValueError(f"{src}: no material names a preset, so there is no preset spread to draw from; give a "
                         "posterior sample of its materials (simulation.PooledCalibration.write)")
    from scipy.stats import qmc
    u = qmc.LatinHypercube(d=len(spread), seed=rng).random(int(draws))
    lo, hi = spread["low"].to_numpy(), spread["high"].to_numpy()
    out = pd.DataFrame(lo + u * (hi - lo), columns=list(spread.index))
    n_assumed = int(spread["assumption"].sum())
    out.attrs["basis"] = (f"the presets' spread: {len(out)} Latin-hypercube draws over {len(spread)} parameter "
                          f"ranges ({n_assumed} of them ASSUMPTIONS, see simulation.material_uncertainty)")
    out.attrs["ranges"] = spread
    return out


def scenario_with_values(scenario, values: dict) -> Scenario:
    """The scenario (TOML path, dict or Scenario loaded from a file) with dotted parameters set to ``values``
    (e.g. one row of :func:`material_draws`), re-read and checked (a ScenarioError names the file and field).

    Parameters
    ----------
    scenario : str, pathlib.Path, dict or Scenario
        The scenario.
    values : dict
        Dotted parameter paths (``materials.NAME.FIELD``) and their values, in the fields' units.

    Returns
    -------
    Scenario
        The checked scenario with the values set.
    """
    from .parameters import apply_parameters
    data, src, base = _scenario_data(scenario)
    try:
        return scenario_from_dict(apply_parameters(data, values, source=src), source=src, base_dir=base)
    except ValueError as exc:
        if isinstance(exc, ScenarioError):
            raise
        raise ScenarioError(str(exc)) from None


__all__ = ["ASSUMED_HALF_WIDTHS", "PRESET_SPREAD_SOURCES", "assumed_spread", "material_draws", "preset_posterior",
           "preset_spread",
           "scenario_with_values"]
