"""The value of a release campaign, priced from the mitigation study's own material draws.

A site whose trajectory model is uncalibrated (its slope materials are presets) is assessed with the materials'
stated ranges (``[uncertainty.materials]``): the study re-simulates the slope for ``G`` joint draws of them (a
Latin hypercube, :class:`~riskrf.risk.slope_models.SlopeModels`).  Those draws are a prior over the trajectory
model, and each carries its own simulated stops.  That is all a preposterior analysis of a field calibration
needs, so the value of calibrating first can be stated beside every ranking at no extra simulation:

* the expected total cost ``C[j, k]`` of option ``k`` under draw ``j`` is the study's joint samples evaluated
  with every sample's slope model set to draw ``j`` (the same samples of the other inputs for every draw: common
  random numbers, so that the differences between rows are the materials');
* the stops of draw ``j`` are the blocks of its re-simulation (the scenario's seeder run under that draw);
* :meth:`riskrf.risk.model_decision.ModelUncertainRanking.calibration_value` then gives the EVSI of releasing
  ``N`` blocks and observing where they stop, with its Monte Carlo error, the EVPI of the material parameters as
  its ceiling, and the verdict against the campaign's cost.

The draws' prior is the stated ranges, uniform: the value is as good as those ranges.  The ``[model_uncertainty]``
table of a site file does the same analysis with a posterior or the presets' spread and draws of its own; where it
is present its figures are the ones reported.

References
----------
Raiffa, H. & Schlaifer, R. (1961) Applied Statistical Decision Theory. Harvard, ch. 4 (preposterior analysis).
Ades, A.E., Lu, G. & Claxton, K. (2004) Medical Decision Making 24:207-227 (EVSI by simulation).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .model_decision import CalibrationValue, ModelUncertainRanking

#: Cost of a release campaign when the site file states none [site currency]: an ASSUMPTION, labelled in every
#: output (the order of a few dozen test releases with a survey of where the blocks stop).  The same default as the
#: ``[model_uncertainty]`` table's ``calibration_cost``.
DEFAULT_CAMPAIGN_COST = 100_000.0

#: Blocks released and observed in the campaign priced by default (the ``[model_uncertainty]`` table's default).
DEFAULT_CAMPAIGN_RELEASES = 20

#: Most simulated stops per draw that the likelihood's kernel density is built from (the ``[model_uncertainty]``
#: table's default blocks per draw): a draw's re-simulation with more blocks is thinned to this many of its
#: quantiles, which keeps its distribution and costs the density a fifth of the time on the demo.
MAX_STOPS_PER_DRAW = 2000


def material_draw_ranking(study) -> ModelUncertainRanking | None:
    """The study's expected costs under each of its joint material draws.

    Parameters
    ----------
    study : riskrf.risk.mitigation.MitigationStudy
        A study whose slope materials are uncertain (``[uncertainty.materials]`` or a calibration bootstrap).

    Returns
    -------
    ModelUncertainRanking or None
        Costs (draws x options) [study currency], the joint samples under each draw and the draws' material
        values; None when the study has no material draws.
    """
    P = study.sample_parameters()
    if "material_draw" not in P:
        return None
    draws = [m for m in study._models[1:] if m.label == "draw"]
    G = len(draws)
    if G < 2:
        return None
    costs, samples, names = [], [], None
    for j in range(1, G + 1):
        r = study._evaluate({**P, "material_draw": np.full_like(P["material_draw"], float(j))})
        names = tuple(r.names)
        samples.append(r.total)
        costs.append(r.total.mean(axis=0))
    table = pd.DataFrame([m.values for m in draws])
    table.attrs["basis"] = "the study's joint material draws (stated ranges, uniform, a Latin hypercube)"
    return ModelUncertainRanking(names, np.vstack(costs), draws=table, sample_costs=np.stack(samples),
                                 currency=study.currency, basis=table.attrs["basis"])


def draw_stops(study) -> list:
    """Per joint material draw, the stop positions x [m] of its re-simulation's blocks.

    Parameters
    ----------
    study : riskrf.risk.mitigation.MitigationStudy
        A study with material draws.

    Returns
    -------
    list of numpy.ndarray
        One array of stop positions [m] per draw, in the order of :func:`material_draw_ranking`; at most
        :data:`MAX_STOPS_PER_DRAW` of them, the evenly spaced quantiles of a larger re-simulation.
    """
    out = []
    for m in study._models[1:]:
        if m.label != "draw":
            continue
        x = np.sort(np.asarray(m.result.per_block["x"], dtype=float))
        if x.size > MAX_STOPS_PER_DRAW:
            x = x[((np.arange(MAX_STOPS_PER_DRAW) + 0.5) * x.size / MAX_STOPS_PER_DRAW).astype(int)]
        out.append(x)
    return out


def release_campaign_value(study, *, n_releases: int = DEFAULT_CAMPAIGN_RELEASES,
                           calibration_cost: float | None = None, obs_error_m: float = 0.5,
                           n_datasets: int = 200, seed: int | None = None) -> CalibrationValue | None:
    """EVSI of a release campaign of ``n_releases`` blocks on the study's slope, from the study's material draws.

    Parameters
    ----------
    study : riskrf.risk.mitigation.MitigationStudy
        A study with joint material draws (see :func:`material_draw_ranking`) and a simulated slope.
    n_releases : int, optional
        Blocks released and observed (default 20).
    calibration_cost : float, optional
        The campaign's cost [study currency]; default :data:`DEFAULT_CAMPAIGN_COST`, labelled ASSUMED.
    obs_error_m : float, optional
        Observation error of a stop position [m] (smallest kernel width of the likelihood; default 0.5).
    n_datasets : int, optional
        Synthetic campaigns per draw taken as the truth (default 200).
    seed : int, optional
        Seed of the synthetic campaigns (default: the study's sampling seed).

    Returns
    -------
    CalibrationValue or None
        The EVSI [study currency] with its standard error, the EVPI of the material parameters and the verdict;
        None when the study has no material draws or no simulated slope.
    """
    ranking = material_draw_ranking(study)
    if ranking is None:
        return None
    models = [m for m in study._models[1:] if m.label == "draw"]
    if any(m.result is None or m.scenario is None for m in models):
        return None
    profile = models[0].scenario.profile
    assumed = calibration_cost is None
    return ranking.calibration_value(
        draw_stops(study), n_releases=int(n_releases), profile_range_m=(float(profile.x[0]), float(profile.x[-1])),
        obs_error_m=float(obs_error_m), n_datasets=int(n_datasets),
        seed=int(study.uncertainty.seed if seed is None else seed),
        calibration_cost=DEFAULT_CAMPAIGN_COST if assumed else float(calibration_cost), cost_is_assumption=assumed)


__all__ = ["DEFAULT_CAMPAIGN_COST", "DEFAULT_CAMPAIGN_RELEASES", "MAX_STOPS_PER_DRAW", "draw_stops", "material_draw_ranking",
           "release_campaign_value"]
