"""The trajectory model's uncertainty in ``riskrf assess``: the ``[model_uncertainty]`` table of a site file.

When the table is present, after the assessment's own chain the slope is re-simulated for K draws of its material
parameters -- rows of a posterior sample (``posterior = "file.csv"``, written by
:meth:`simulation.PooledCalibration.write`) or the presets' spread (:mod:`simulation.material_uncertainty`, ASSUMED
ranges) -- and for each draw the energy hazard, the design energies and the mitigation study are computed again
(:func:`riskrf.app.assess.hazard.energy_hazard_from_inputs` and :class:`~riskrf.risk.mitigation.MitigationStudy`, used
as they are).  From the draws:

* the design energies' intervals split into the trajectory model's part and the statistical part
  (:func:`riskrf.hazard.model_uncertainty.design_energy_split`);
* the ranking over the draws: expected cost, P(best), and the share of each option's cost variance from the
  trajectory model; the EVPI of the material parameters; the EVSI of a field calibration with
  ``calibration_releases`` released blocks, weighed against ``calibration_cost``
  (:class:`riskrf.risk.model_decision.ModelUncertainRanking`): "calibrate first, then decide" or "decide now".

Every draw uses the same simulation seed (common random numbers) and the same samples of the study's other
uncertain inputs, so the differences between draws are the materials'.  The study's own material draws
(``[uncertainty.materials]`` or ``calibration_bootstrap``) are switched off inside the draws: here the draws are
the material uncertainty.
"""
from __future__ import annotations

import difflib
import time
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np
import pandas as pd

from ..core.file_schemas import MODEL_UNCERTAINTY
from ..core.schema import record_class
from ..core.format import money, sig
from ..hazard.model_uncertainty import DesignEnergySplit, ModelUncertaintyError, design_energy_split, \
    read_model_posterior
from ..risk.model_decision import CalibrationValue, ModelUncertainRanking

#: Cost of a field calibration when the site file states none [site currency]: an ASSUMPTION (the order of a
#: campaign of a few dozen test releases with a survey of where the blocks stop), labelled in every output.
DEFAULT_CALIBRATION_COST = 100_000.0

#: The table's fields and defaults (from the one declaration, riskrf.core.file_schemas.MODEL_UNCERTAINTY).
FIELDS = MODEL_UNCERTAINTY.defaults()

#: The checked table (:func:`check_model_uncertainty`): its declared fields (generated from the declaration,
#: defaults filled in) plus what the check derives: ``scenario_path`` (the resolved hazard.scenario),
#: ``posterior_table`` (the read posterior sample, None for the presets' spread), ``posterior_path`` and
#: ``calibration_cost_is_assumption`` (True when calibration_cost is the ASSUMED default).
ModelUncertaintySettings = record_class(MODEL_UNCERTAINTY, name="ModelUncertaintySettings", extra=(
    ("scenario_path", Path, None), ("posterior_table", object, None), ("posterior_path", Path, None),
    ("calibration_cost_is_assumption", bool, False)))
ModelUncertaintySettings.__module__ = __name__


def check_model_uncertainty(data, site_path: Path, hazard: dict, *, error=ModelUncertaintyError):
    """The ``[model_uncertainty]`` table checked before any work: (config with defaults, defaults used), or
    (None, []) when absent.  A posterior file is read and held against the scenario's materials here (an error
    names the file and the column); without one the scenario must name presets.

    Parameters
    ----------
    data : dict or None
        The site file's ``[model_uncertainty]`` table as parsed from TOML (None when absent).
    site_path : pathlib.Path
        The site file; relative paths (``posterior``, ``hazard.scenario``) are resolved against its folder.
    hazard : HazardTable
        The site's checked ``[hazard]`` record (its ``scenario`` [path] and ``seed`` are used).
    error : type, optional
        Exception class raised on bad input (a subclass of :class:`riskrf.RiskrfError`; default
        :class:`~riskrf.hazard.model_uncertainty.ModelUncertaintyError`).

    Returns
    -------
    cfg : ModelUncertaintySettings or None
        The table with defaults filled in, plus ``scenario_path``, ``posterior_table`` (the read posterior or None),
        ``calibration_cost`` [site currency] and ``calibration_cost_is_assumption``; None when the table is absent.
    used : list of str
        The defaults used (``model_uncertainty.<field> = <value>``), for labelling the outputs.
    """
    if data is None:
        return None, []
    where = f"{site_path}: model_uncertainty"
    if not isinstance(data, dict):
        raise error(f"{where} must be a table")
    for key in data:
        if key not in FIELDS:
            close = difflib.get_close_matches(key, list(FIELDS), n=1)
            raise error(f"{site_path}: unknown field model_uncertainty.{key!r}"
                        + (f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(FIELDS)}"))
    if hazard.scenario is None:
        raise error(f"{where}: needs hazard.scenario (the slope to re-simulate); hazard.velocities gives no "
                    "material parameters to vary")
    cfg, used = {}, []
    for key, default in FIELDS.items():
        if key in data:
            cfg[key] = data[key]
        else:
            cfg[key] = default
            if default is not None:
                used.append(f"model_uncertainty.{key} = {default!r}")
    if cfg["seed"] is None:
        cfg["seed"] = hazard.seed
    if "max_draws" in data and isinstance(cfg["max_draws"], int) and isinstance(cfg["draws"], int) \
            and cfg["max_draws"] < cfg["draws"]:
        raise error(f"{where}.max_draws = {cfg['max_draws']!r} is below model_uncertainty.draws = {cfg['draws']!r}: "
                    "the budget must allow at least the draws the study starts with")
    cfg["calibration_cost_is_assumption"] = cfg["calibration_cost"] is None
    if cfg["calibration_cost"] is None:
        cfg["calibration_cost"] = DEFAULT_CALIBRATION_COST
        used.append(f"model_uncertainty.calibration_cost = {DEFAULT_CALIBRATION_COST:g} (ASSUMED: a campaign of test "
                    "releases with a survey of the stops)")
    scenario = (site_path.parent / hazard.scenario).resolve()
    cfg["scenario_path"] = scenario
    if cfg["posterior"] is not None:
        path = (site_path.parent / cfg["posterior"]).resolve()
        if not path.is_file():
            raise error(f"{where}.posterior = {cfg['posterior']!r}: file not found ({path})")
        try:
            cfg["posterior_table"] = read_model_posterior(path, scenario)
        except ModelUncertaintyError as exc:
            raise error(f"{where}.posterior = {cfg['posterior']!r}: {exc}") from None
        cfg["posterior_path"] = path
    else:
        import simulation
        spread = simulation.preset_spread(scenario)
        if spread.empty:
            raise error(f"{where}: no posterior given and no material of {hazard.scenario} names a preset, so "
                        "there is no spread to draw from; give model_uncertainty.posterior")
        cfg["posterior_table"] = None
    return ModelUncertaintySettings(**cfg), used


@dataclass
class ModelUncertaintyStudy:
    """What the draws of the trajectory model gave (:func:`run_model_uncertainty`).

    ``draws``: material values per draw; ``energy``: the design energies' split
    (:class:`~riskrf.hazard.model_uncertainty.DesignEnergySplit`); ``ranking``:
    :class:`~riskrf.risk.model_decision.ModelUncertainRanking`; ``calibration``:
    :class:`~riskrf.risk.model_decision.CalibrationValue`; ``config``: the checked table; ``per_draw``: reach
    probability, road share and design energy per draw; ``ranges``: the presets' ranges (None for a posterior).
    """

    draws: pd.DataFrame
    basis: str
    energy: DesignEnergySplit
    ranking: ModelUncertainRanking
    calibration: CalibrationValue
    config: ModelUncertaintySettings
    per_draw: pd.DataFrame
    design_T: float
    ranges: pd.DataFrame | None = None
    timings: dict = field(default_factory=dict)
    notes: tuple = ()

    def verdict(self) -> str:
        """Calibrate first or decide now, with the numbers.

        Returns
        -------
        str
            The sentence of :meth:`riskrf.risk.model_decision.CalibrationValue.verdict` (EVSI and calibration cost in
            the site currency).
        """
        return self.calibration.verdict()

    def text(self) -> list[str]:
        """Plain-text lines for the CLI and the report.

        Returns
        -------
        list of str
            One line per entry: design energies [kJ] with their split, the ranking over the draws, the verdict.
        """
        lines = [f"Trajectory model uncertainty ({self.basis}):"]
        lines += ["  " + t for t in self.energy.text(self.design_T)]
        lines += ["  " + t for t in self.ranking.text()]
        lines.append("  " + self.verdict())
        return lines

    def to_dict(self) -> dict:
        """The lines of ``summary.json`` (``model_uncertainty``).

        Returns
        -------
        dict
            JSON-ready values: basis, draws, design energy [kJ] with its intervals and variance share, the ranking
            (expected costs [site currency/yr]), EVPI [site currency/yr], the calibration value, verdict, notes and
            timings [s].
        """
        cfg = self.config
        row = self.energy.row(self.design_T) if np.isclose(self.energy.table["T_years"], self.design_T).any() \
            else None
        rank = self.ranking.summary()
        out = {"basis": self.basis, "posterior": str(cfg.posterior) if cfg.posterior else None,
               "draws": int(self.ranking.n_draws), "blocks_per_draw": int(cfg.n_blocks),
               "option_blocks_per_draw": int(cfg.option_blocks), "seed": int(cfg.seed),
               "parameters": list(self.draws.columns),
               "assumed_ranges": None if self.ranges is None else {
                   k: {"low": r["low"], "high": r["high"], "basis": r["basis"]} for k, r in self.ranges.iterrows()},
               "design_energy": None if row is None else {
                   "T_years": self.design_T, "energy_kj_mean": row["energy_kj_mean"],
                   "energy_kj_reference": row["energy_kj_reference"],
                   "interval_kj": [row["combined_low_kj"], row["combined_high_kj"]],
                   "trajectory_model_interval_kj": [row["model_low_kj"], row["model_high_kj"]],
                   "statistical_interval_kj": [row["statistical_low_kj"], row["statistical_high_kj"]],
                   "share_of_variance_from_trajectory_model": row["share_from_trajectory_model"],
                   "level": self.energy.level},
               "design_energies": self.energy.to_dict(),
               "best_option_over_draws": self.ranking.best_now(),
               "ranking": rank.to_dict(orient="records"),
               "evpi_material_parameters": self.ranking.evpi(),
               "evpi_material_parameters_estimate": self.ranking.evpi_estimate().to_dict(),
               "calibration": self.calibration.to_dict(),
               "verdict": self.verdict(),
               "notes": list(self.notes),
               "timings_s": self.timings}
        return out

    def write(self, out_dir) -> list[Path]:
        """``model_uncertainty_ranking.csv``, ``model_uncertainty_draws.csv`` and
        ``design_energy_model_uncertainty.csv`` into ``out_dir``; returns the files written.

        Parameters
        ----------
        out_dir : str or pathlib.Path
            Existing output folder.

        Returns
        -------
        list of pathlib.Path
            The three CSV files written.
        """
        out = Path(out_dir)
        files = [out / "model_uncertainty_ranking.csv", out / "model_uncertainty_draws.csv",
                 out / "design_energy_model_uncertainty.csv"]
        self.ranking.summary().to_csv(files[0], index=False)
        self.ranking.per_draw().merge(self.per_draw, on="draw").to_csv(files[1], index=False)
        self.energy.summary().to_csv(files[2], index=False)
        return files

    def figures(self, figs) -> list[Path]:
        """The draws' design energies and costs as PNG figures in ``figs``.

        Parameters
        ----------
        figs : pathlib.Path
            Existing folder for the figures.

        Returns
        -------
        list of pathlib.Path
            ``design_energy_model_uncertainty.png`` and ``ranking_model_uncertainty.png``.
        """
        from ..report.files import save_figure
        a = figs / "design_energy_model_uncertainty.png"
        b = figs / "ranking_model_uncertainty.png"
        save_figure(self.energy.plot(self.design_T).figure, a)
        save_figure(self.ranking.plot().figure, b)
        return [a, b]


def _without_material_draws(uncertainty):
    """The study's uncertainty with its own material draws switched off (the draws here replace them)."""
    if uncertainty is None:
        return None
    names = {f.name for f in fields(uncertainty)}
    kw = {k: v for k, v in (("materials", {}), ("calibration", None)) if k in names}
    return replace(uncertainty, **kw)


def calibration_resolved(calibration) -> str:
    """Is the choice between calibrating first and deciding now resolved by the draws?  "" when not.

    Resolved as "decide now" when even the EVPI's 97.5 % upper bound (which bounds the EVSI) is below the
    calibration's cost, as "calibrate first" when the EVSI less two standard errors exceeds it, and as "no cost
    stated" without a cost (nothing to decide).

    Parameters
    ----------
    calibration : riskrf.risk.model_decision.CalibrationValue
        The value of the field calibration from the draws so far (money in the site currency).

    Returns
    -------
    str
        "decide now", "calibrate first", "no cost stated" or "" (not resolved).
    """
    cost = calibration.calibration_cost
    if cost is None:
        return "no cost stated"
    bound = calibration.evpi_upper_bound
    if np.isfinite(bound) and bound < cost:
        return "decide now"
    if calibration.evsi_estimate - 2.0 * calibration.standard_error > cost:
        return "calibrate first"
    return ""


def effort_text(rounds, budget: int, calibration) -> str:
    """The draws used and why they stopped, in one sentence.

    Parameters
    ----------
    rounds : sequence of (int, str)
        (draws so far, what resolved, "" when not) after each round.
    budget : int
        ``[model_uncertainty] max_draws`` (or ``draws`` when smaller).
    calibration : riskrf.risk.model_decision.CalibrationValue
        The final value of the calibration.

    Returns
    -------
    str
        The sentence.
    """
    n, reached = rounds[-1]
    path = " -> ".join(str(k) for k, _ in rounds)
    if reached:
        why = {"decide now": "the EVPI's upper bound is below the calibration's cost (decide now, whatever more "
                             "draws would show)",
               "calibrate first": "the EVSI exceeds the calibration's cost by more than two standard errors",
               "no cost stated": "no calibration cost is weighed"}[reached]
        return f"draws of the trajectory model: {path}; stopped because {why}"
    return (f"draws of the trajectory model: {path}; the budget (max_draws = {budget}) is used and the choice "
            f"between calibrating first and deciding now is NOT resolved: EVSI {calibration.evsi_estimate:,.0f} +- "
            f"{2 * calibration.standard_error:,.0f}, EVPI at most {calibration.evpi_upper_bound:,.0f}, against a "
            f"cost of {calibration.calibration_cost:,.0f}")


def run_model_uncertainty(site, evaluate_draw, *, reference_hazard=None, design_T: float = 100.0, T=None,
                          log=None) -> ModelUncertaintyStudy:
    """Re-simulate the site's slope for each draw of the trajectory model and carry it to the design energies,
    the ranking and the value of a field calibration (see the module docstring).

    ``evaluate_draw(scenario, n_blocks, option_blocks, seed, uncertainty)`` runs the assessment's own chain for
    one scenario and returns (EnergyHazard, MitigationStudy, SimulationResult of the scenario's seeder, road
    share) (:func:`riskrf.app.assess.decision.draw_evaluator`); ``uncertainty`` is the study's uncertainty to use (its
    material draws switched off).  ``reference_hazard``: the assessment's own hazard (reported beside the
    draws); ``T``: return periods [yr] of the design energies (default the design period).

    Parameters
    ----------
    site : Site
        The checked site (:func:`riskrf.app.site.load_site`); its ``model_uncertainty`` table (from
        :func:`check_model_uncertainty`), ``hazard`` and ``mitigation`` are used.
    evaluate_draw : callable
        ``evaluate_draw(scenario, n_blocks, option_blocks, seed, uncertainty)`` -> (EnergyHazard, MitigationStudy,
        SimulationResult, road share [-]); see above.
    reference_hazard : EnergyHazard, optional
        The assessment's own hazard, reported beside the draws.
    design_T : float, optional
        Design return period [yr] (default 100).
    T : sequence of float, optional
        Further return periods [yr] of the design energies (the design period is always included).
    log : callable, optional
        ``log(str)`` for progress lines (default silent).

    Returns
    -------
    ModelUncertaintyStudy
        Draws, design energy split [kJ], ranking over the draws [site currency/yr], calibration value, notes.
    """
    import simulation

    cfg = site.model_uncertainty
    log = log or (lambda s: None)
    seed = int(cfg.seed)
    scenario = cfg.scenario_path
    timings = {}
    t0 = time.perf_counter()
    uncertainty = _without_material_draws(site.mitigation.uncertainty)
    hazards, costs, samples, stops, rows = [], [], [], [], []
    names, parts, rounds = None, [], []
    profile = simulation.load_scenario(scenario).profile
    T = [design_T] if T is None else sorted(set(float(x) for x in T) | {float(design_T)})
    budget = max(int(cfg.max_draws or 0), int(cfg.draws))
    k_new, analysis_s = int(cfg.draws), 0.0
    while True:
        # each round adds draws of its own seed (a Latin hypercube or rows of the posterior), evaluated once
        new = simulation.material_draws(scenario, k_new, posterior=cfg.posterior_table,
                                        seed=seed if not parts else seed + 7919 * len(parts))
        if not parts:                          # where the draws come from: said once, by every output
            basis = (f"posterior {Path(cfg.posterior).name}: " if cfg.posterior else "") \
                + new.attrs.get("basis", "")
        parts.append(new)
        for values in new.to_dict(orient="records"):
            j = len(rows)
            log(f"      draw {j + 1} of the trajectory model")
            sc = simulation.scenario_with_values(scenario, values)
            hz, study, result, share = evaluate_draw(sc, int(cfg.n_blocks), int(cfg.option_blocks), seed,
                                                     uncertainty)
            u = study.uncertain
            names = tuple(u["names"]) if names is None else names
            hazards.append(hz)
            costs.append(np.asarray(u["mean"], dtype=float))
            samples.append(np.asarray(u["total"], dtype=float))
            stops.append(np.asarray(result.per_block["x"], dtype=float))
            rows.append({"draw": j, "reach_probability": hz.reach_probability, "arrivals_per_year": hz.arrival_rate,
                         "road_share": share, "median_stop_x_m": float(np.median(stops[-1]))})
            currency = study.currency
        # (pandas compares the parts' attrs when it concatenates: the ranges table is kept from the first only)
        draws = pd.concat([pd.DataFrame(p.to_dict(orient="list")) for p in parts], ignore_index=True)
        draws.attrs = dict(parts[0].attrs)
        t = time.perf_counter()
        ranking = ModelUncertainRanking(names, np.vstack(costs), draws=draws, sample_costs=np.stack(samples),
                                        currency=currency, basis=basis)
        calibration = ranking.calibration_value(stops, n_releases=int(cfg.calibration_releases),
                                                profile_range_m=(float(profile.x[0]), float(profile.x[-1])),
                                                obs_error_m=float(cfg.obs_error_m),
                                                n_datasets=int(cfg.synthetic_calibrations), seed=seed,
                                                calibration_cost=float(cfg.calibration_cost),
                                                cost_is_assumption=bool(cfg.calibration_cost_is_assumption))
        analysis_s += time.perf_counter() - t
        reached = calibration_resolved(calibration)
        rounds.append((len(draws), reached))
        if reached or len(draws) >= budget:
            break
        k_new = min(len(draws), budget - len(draws))
        log(f"      the value of calibrating is not resolved with {len(draws)} draws: {k_new} more")
    timings["draws"] = round(time.perf_counter() - t0 - analysis_s, 2)
    t = time.perf_counter()
    energy = design_energy_split(hazards, T, n_bootstrap=int(cfg.bootstrap), seed=seed,
                                 reference=reference_hazard, basis=basis)
    design_row = energy.per_draw[np.isclose(energy.per_draw["T_years"], design_T)]
    per_draw = pd.DataFrame(rows).merge(design_row[["draw", "energy_kj"]].rename(
        columns={"energy_kj": f"energy_{design_T:g}_year_kj"}), on="draw")
    timings["analysis"] = round(time.perf_counter() - t + analysis_s, 2)
    notes = [effort_text(rounds, budget, calibration),
             f"{len(draws)} draws of the material parameters ({basis}), each re-simulated with "
             f"{int(cfg.n_blocks):,} blocks and seed {seed} (common random numbers; the assessment's own run "
             f"uses {site.hazard.n_blocks:,}), its options with {int(cfg.option_blocks):,} blocks",
             "costs per draw: the mitigation study's mean over its joint samples of the other uncertain inputs "
             "(the same samples for every draw); the study's own material draws are switched off inside the draws"]
    if draws.attrs.get("ranges") is not None and draws.attrs["ranges"]["assumption"].any():
        notes.append("the presets' ranges are ASSUMPTIONS (simulation.material_uncertainty): "
                     + "; ".join(f"{k} {sig(r['low'], 3)}-{sig(r['high'], 3)}"
                                 for k, r in draws.attrs["ranges"].iterrows()))
    if cfg.calibration_cost_is_assumption:
        notes.append(f"calibration cost {money(cfg.calibration_cost)} {currency}: ASSUMED default "
                     "(model_uncertainty.calibration_cost)")
    notes += list(energy.notes) + list(calibration.notes)
    return ModelUncertaintyStudy(draws=draws, basis=basis, energy=energy, ranking=ranking, calibration=calibration,
                                 config=cfg, per_draw=per_draw, design_T=float(design_T),
                                 ranges=draws.attrs.get("ranges"), timings=timings, notes=tuple(notes))


__all__ = ["DEFAULT_CALIBRATION_COST", "ModelUncertaintyStudy", "check_model_uncertainty", "run_model_uncertainty"]
