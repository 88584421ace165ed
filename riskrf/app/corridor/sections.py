"""One corridor section assessed: its mass-coupled hazard, its options' study and one row of the corridor table.

:func:`assess_section` is the task a dask worker runs for each section (see :mod:`riskrf.app.corridor.run`):
hazard at the barrier line as ``riskrf assess`` computes it, the release rate behind recorded road falls,
the mitigation study of the section's options and the ranking reduced to plain numbers and strings.
Rates per year, risks deaths per year, money in the corridor currency.
"""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import pandas as pd

from .model import Corridor, Section, _section_seed


def rhrs_columns(rating) -> dict:
    """RHRS columns of a section's result row: ``rhrs_<category>`` whole-point score of every category and
    ``rhrs_total`` (their sum, as a rating sheet prints it); empty (NaN) without a rating.  The category set is
    the union of both geologic cases, so every section's row has the same columns.

    Parameters
    ----------
    rating : RHRSRating or None
        The section's RHRS rating.

    Returns
    -------
    dict
        ``rhrs_<category>`` and ``rhrs_total`` scores [points] (NaN without a rating).
    """
    cats = ("slope_height", "ditch_effectiveness", "average_vehicle_risk", "percent_decision_sight_distance",
            "roadway_width", "structural_condition", "rock_friction", "difference_in_erosion_rates",
            "block_size_or_volume", "climate_and_water", "rockfall_history")
    if rating is None:
        return {**{f"rhrs_{c}": np.nan for c in cats}, "rhrs_total": np.nan}
    pts = rating.integer_scores
    return {**{f"rhrs_{c}": float(pts[c]) if c in pts else np.nan for c in cats},
            "rhrs_total": float(rating.integer_total)}


#: Per-option fields kept in a result row (``options_json``) for the budget programme.
OPTION_FIELDS = ("option", "kind", "capital", "pv_renewals", "pv_maintenance", "deaths_per_year", "individual_risk",
                 "expected_total_cost", "meets_criteria")


def _options_json(rk: pd.DataFrame, base) -> str:
    """Every option of a section's ranking as a JSON list (plain numbers): what the programme chooses among."""
    import json
    recs = []
    for _, r in rk.iterrows():
        recs.append({k: (bool(r[k]) if k == "meets_criteria" else str(r[k]) if k in ("option", "kind")
                         else float(r[k])) for k in OPTION_FIELDS})
    return json.dumps(recs, sort_keys=True)


def _road_reach(hazard, result, mm) -> float:
    """P(a fall of mass model ``mm`` reaches the road line) from the mass-coupled run ``result`` behind ``hazard``
    (the same blocks and mass classes as the hazard's barrier samples, reach counted per class)."""
    from ...hazard.mass_coupling import MassCoupledSamples
    s = hazard.velocity
    road = np.full(result.n, np.nan)
    road[np.unique(result.collector("road", first_only=True)["block"].to_numpy())] = 1.0
    return float(MassCoupledSamples(s.mass_kg, road, road, s.edges_kg, "road").reach_probability(mm))


def _section_row(section: Section, corridor: Corridor, n: int, s_seed: int) -> dict:
    """The columns of a section's result row known before any simulation.

    Parameters
    ----------
    section : Section
        The section.
    corridor : Corridor
        Its corridor.
    n : int
        Blocks simulated per run.
    s_seed : int
        The section's seed.

    Returns
    -------
    dict
        Id, chainage [m], lengths [m], geometry, RHRS columns, given rate [1/yr] and its source, rate basis,
        ``n_blocks`` and ``seed``.
    """
    return {"id": section.id, "chainage_from_m": section.chainage_from_m, "chainage_to_m": section.chainage_to_m,
            "length_m": section.length_m, "cut_length_m": section.works_length_m, "geometry": section.geometry,
            "rhrs_score": section.rating.total if section.rating is not None else np.nan,
            **rhrs_columns(section.rating),
            "rate_given_per_year": section.falls_per_year, "rate_source": section.rate_source,
            "rate_basis": corridor.rate_basis, "n_blocks": n,
            "seed": s_seed}


def _section_hazard(section: Section, corridor: Corridor, mm, n: int, s_seed: int):
    """The section's mass-coupled hazard at the barrier line, at its release rate, and the reach probabilities.

    Parameters
    ----------
    section : Section
        The section.
    corridor : Corridor
        Its corridor (mass law, rate basis).
    mm : MassModel
        The corridor's mass model (for the share reaching the road).
    n : int
        Blocks simulated.
    s_seed : int
        The section's seed.

    Returns
    -------
    hazard : EnergyHazard or None
        The hazard at the release rate [1/yr]; None when no simulated block reaches the barrier line
        (``rate_basis = "release"`` only).
    reach : dict
        ``reach_barrier`` and ``reach_road`` [-] and ``release_falls_per_year`` [1/yr] (empty with no hazard).

    Raises
    ------
    ValueError
        For ``rate_basis = "road"`` when no simulated block reaches the road line.
    """
    from ...hazard.mass_coupling import NoArrivalsError
    from ...hazard.simulated import simulate_energy_hazard
    try:
        # the simulated mass range is chosen at the given rate (for a truncated law, as the corridors ship, it is
        # m_min-m_max whatever the rate; beyond it the hazard's notes state the extrapolated share)
        hazard, coupled = simulate_energy_hazard(corridor.mass, section.scenario, "barrier",
                                                 rate_per_year=section.falls_per_year, n=n, seed=s_seed)
    except NoArrivalsError:
        if corridor.rate_basis == "road":
            raise ValueError(f"section {section.id!r}: no simulated block of {n:,} reached the barrier line (nor the "
                             "road), so the release rate behind the recorded road falls cannot be derived; check "
                             "the geometry or use rate_basis = 'release'") from None
        return None, {}
    reach_barrier = float(hazard.reach_probability)
    reach_road = min(_road_reach(hazard, coupled, mm), reach_barrier)
    if corridor.rate_basis == "road":
        if reach_road == 0:
            raise ValueError(f"section {section.id!r}: no simulated block of {n:,} reached the road, so the release "
                             "rate behind the recorded road falls cannot be derived; check the geometry or use "
                             "rate_basis = 'release'")
        release = section.falls_per_year / reach_road
    else:
        release = section.falls_per_year
    reach = {"reach_barrier": reach_barrier, "reach_road": reach_road, "release_falls_per_year": release}
    return replace(hazard, rate_per_year=release), reach


def _no_arrival_values(section: Section) -> dict:
    """The result columns of a section whose simulated blocks never reach the barrier line: nothing to mitigate.

    Parameters
    ----------
    section : Section
        The section (its given rate is the release rate).

    Returns
    -------
    dict
        Zero reach, road falls, risks and costs; doing nothing as the best option.
    """
    return {"reach_barrier": 0.0, "reach_road": 0.0, "release_falls_per_year": section.falls_per_year,
            "road_falls_per_year": 0.0, "deaths_per_year": 0.0, "individual_risk": 0.0,
            "expected_annual_loss": 0.0, "best_option": "do nothing (no block reaches the barrier line)",
            "best_option_capital": 0.0, "best_option_total_cost": 0.0, "best_deaths_per_year": 0.0,
            "best_individual_risk": 0.0, "meets_criteria": True, "note": "no simulated block reached the line",
            "options_json": "[]"}


def _section_options(section: Section, corridor: Corridor) -> tuple:
    """The corridor's options offered on a section, per-metre costs paid on its cut length.

    Parameters
    ----------
    section : Section
        The section (its option names and cut length [m]).
    corridor : Corridor
        Its corridor (options with their per-metre costs).

    Returns
    -------
    tuple
        The section's options; a shed covers the whole cut length.
    """
    works = section.works_length_m           # per-metre costs are paid on the cut, not on the whole section
    opts = []
    for o, pm in corridor.options:
        if o.name not in section.options:
            continue
        upd = {k: v * works for k, v in pm.items()}
        if o.kind == "shed":
            upd["covered_length_m"] = works
        opts.append(replace(o, **upd))
    return tuple(opts)


def _section_study(section: Section, corridor: Corridor, hazard, reach: dict, n: int, s_seed: int):
    """The section's mitigation study; a run of ``n`` blocks with the scenario's own seeder is its reference.

    Parameters
    ----------
    section : Section
        The section (scenario, traffic, options).
    corridor : Corridor
        Its corridor (consequences, economics, uncertainty, criteria).
    hazard : EnergyHazard
        The hazard at the barrier line at the release rate [1/yr].
    reach : dict
        ``reach_barrier`` and ``reach_road`` [-] of the hazard's run.
    n : int
        Blocks of the reference run.
    s_seed : int
        The section's seed.

    Returns
    -------
    MitigationStudy
        The road-user risk of every option of the section.
    """
    import simulation

    from ...risk.measures import SimulationContext
    from ...risk.mitigation import MitigationStudy

    result = simulation.run(section.scenario, n=n, seed=s_seed, record_paths=0)    # the seeder's run: option effects
    opts = _section_options(section, corridor)
    exposure = replace(corridor.study["exposure"], vehicles_per_day=section.vehicles_per_day,
                       speed_kmh=section.speed_kmh, exposed_length_m=section.length_m)
    unc = replace(corridor.study["uncertainty"], seed=s_seed % (2 ** 32))
    return MitigationStudy(hazard=hazard, options=opts, exposure=exposure,
                           consequences=corridor.study["consequences"], economics=corridor.study["economics"],
                           road_share=reach["reach_road"] / reach["reach_barrier"], source=str(corridor.path),
                           context=SimulationContext(section.scenario, "barrier", "road",
                                                     n_blocks=corridor.option_blocks, seed=s_seed % (2 ** 32),
                                                     threads=1),     # parallel across sections, not within
                           reference=result, uncertainty=unc, criteria=corridor.study["criteria"])


def _ranking_values(rk: pd.DataFrame, corridor: Corridor) -> dict:
    """The result columns of a section's option ranking: doing nothing, the best option and what it buys.

    Parameters
    ----------
    rk : pandas.DataFrame
        The study's ranking (cheapest expected total cost first).
    corridor : Corridor
        Its corridor (criteria, economics).

    Returns
    -------
    dict
        Road falls [1/yr], risks [deaths/yr], costs in the corridor currency; the best option is the cheapest
        that meets the criteria (the cheapest of all, with a note, when none does).
    """
    lim = corridor.study["criteria"].individual_risk_per_year
    none = rk[rk["kind"] == "none"]
    base = none.iloc[0] if len(none) else rk.iloc[-1]
    ok = rk[rk["meets_criteria"]]
    best = ok.iloc[0] if len(ok) else rk.iloc[0]
    years = corridor.study["economics"].horizon_years
    spend = best["capital"] + best["pv_renewals"] + best["pv_maintenance"] \
        - (base["capital"] + base["pv_renewals"] + base["pv_maintenance"])
    avoided = float(base["deaths_per_year"] - best["deaths_per_year"])
    return {
        "road_falls_per_year": float(base["road_falls_per_year"]), "deaths_per_year": float(base["deaths_per_year"]),
        "individual_risk": float(base["individual_risk"]),
        "expected_annual_loss_pv": float(base["pv_expected_loss"]),
        "do_nothing_total_cost": float(base["expected_total_cost"]),
        "best_option": str(best["option"]), "best_option_kind": str(best["kind"]),
        "best_option_capital": float(best["capital"]), "best_option_total_cost": float(best["expected_total_cost"]),
        "best_option_spend": float(spend), "best_deaths_per_year": float(best["deaths_per_year"]),
        "best_individual_risk": float(best["individual_risk"]), "deaths_avoided_per_year": avoided,
        "deaths_avoided_per_million": avoided * years / spend * 1e6 if spend > 0 else np.nan,
        "meets_criteria": bool(best["meets_criteria"]),
        "cheapest_option": str(rk.iloc[0]["option"]),
        "options_json": _options_json(rk, base),
        "note": "" if len(ok) else f"no option meets the criteria (individual risk <= {lim:g}/yr and F-N); "
                                   "cheapest shown"}


def assess_section(section: Section, corridor: Corridor, n_blocks: int | None = None, seed: int | None = None) -> dict:
    """The whole chain for one section; returns one row of the corridor table (plain numbers and strings).

    The hazard at the barrier line is mass-coupled exactly as in ``riskrf assess``
    (:func:`riskrf.hazard.simulated.simulate_energy_hazard`: ``n`` blocks with masses log-uniform over the corridor's
    mass law, reach and speed by mass class).  The share of falls reaching the road and, for ``rate_basis = "road"``,
    the release rate behind the recorded road falls (given / P(reach road)) come from the same mass-coupled run.
    A second run of ``n`` blocks with the scenario's own seeder is the reference of the option effects
    (:class:`~riskrf.risk.mitigation.MitigationStudy` ``reference`` and ``context``), as in ``riskrf assess``.
    Deterministic given the corridor seed and the section id (see the module docstring).

    Parameters
    ----------
    section : Section
        The section to assess.
    corridor : Corridor
        The corridor it belongs to (mass law, traffic, consequences, economics, criteria).
    n_blocks : int, optional
        Blocks simulated per run (default: the corridor's).
    seed : int, optional
        Corridor seed (default: the corridor's).

    Returns
    -------
    dict
        One row of the corridor table: rates [1/yr], risks [deaths/yr], costs in the corridor currency, the best
        option and the RHRS columns.
    """
    from ...hazard.mass_models import mass_model

    n = int(n_blocks or corridor.n_blocks)
    s_seed = _section_seed(corridor.seed if seed is None else seed, section.id)
    t0 = time.perf_counter()
    mm = mass_model(corridor.mass)
    row = _section_row(section, corridor, n, s_seed)
    hazard, reach = _section_hazard(section, corridor, mm, n, s_seed)
    if hazard is None:
        row.update(_no_arrival_values(section))
    else:
        row.update(reach)
        row.update(_ranking_values(_section_study(section, corridor, hazard, reach, n, s_seed).ranking(), corridor))
    row["seconds"] = time.perf_counter() - t0
    return row
