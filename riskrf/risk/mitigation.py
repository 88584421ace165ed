"""Mitigation options ranked by expected total cost, with uncertainty and a recommendation.

    expected total cost = capital + PV(renewals) + PV(maintenance, repairs, replacements) + PV(expected losses)

(Wyllie 2014, 8.5.5; Wyllie, McCammon & Brumund 1980.)  The study is in three parts:

* :mod:`riskrf.risk.options`: one small class per option kind (do nothing, scaling and bolting, ditch, bench, bund,
  drape, fence, attenuator, shed, realignment, closure, combined): what it does to the falls (CLIMADA's measures:
  a measure changes the hazard, the exposure or the vulnerability), what it costs, and whether its effect is
  derived, computed or ASSUMED; :mod:`riskrf.risk.slope_models` the slope simulations its derived effects come
  from;
* :mod:`riskrf.risk.loss_engine`: the one loss engine, on typed arrays (the inputs for S samples, option costs and
  effects as columns; results (S, K) per option);
* this module: :class:`MitigationStudy`, the study: the inputs the engine varies and their uncertainty, the
  ranking, the recommendation, the tolerability and ALARP tests, the sensitivity (tornado, break-even), the value
  of information and the decision tree.

Damage states (fences, attenuators, sheds): an impact between SEL = MEL/3 and MEL is held and costs
``repair_cost_per_impact``; an impact above MEL destroys the structure, passes, costs ``replacement_cost``
(default: the capital cost) and leaves the road unprotected for ``repair_days`` (ASSUMPTION, default 30 days for
fences, 180 for sheds), during which every fall passes.  With destructive impacts at rate lambda_d the share of
time out of service is lambda_d t_r / (1 + lambda_d t_r) (alternating renewal process).

Road losses per fall reaching the road, for falls of every size (the power law above m_min and the inventory's own
smaller falls below it): a moving vehicle at the impact point (Bunce et al. 1997), a vehicle striking the rock
lying on the road, deaths with a vulnerability that depends on block mass (see :mod:`riskrf.risk.road_risk`),
vehicle damage, closure and clean-up.  All inputs come from a TOML file (README, "Mitigation files").
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np
import pandas as pd

from simulation._display import Displayed, short_repr

from ..core.format import money
from ..hazard.annual_hazard import EnergyHazard
from ..hazard.mass_models import mass_model
from .economics import pv_factor
from .error_budget import clustered_se, combined_se, sources_text
from .recommendation import RecommendationMixin
from .model_decision import evpi_estimate
from .loss_engine import LossEngine, LossResult, ParameterSpace, fragment_matrix, mass_grid, mass_pmf
from .measures import SimulationContext
from .mitigation_inputs import (  # noqa: F401  (public names of riskrf.risk.mitigation)
    BARRIER_KINDS,
    DEFAULT_REPAIR_DAYS,
    MASS_BINS,
    OPTION_KINDS,
    SLOPE_KINDS,
    Consequences,
    Criteria,
    Economics,
    Exposure,
    MitigationError,
    Option,
    Uncertainty,
    _check_combinations,
    closure_cost_per_fall,
    check_mitigation_file,
    parse_mitigation,
    parse_option,
    study_inputs,
)
from .option_result import OptionResult  # noqa: F401  (a public name of riskrf.risk.mitigation)
from .options.chain import effect_basis, effect_of, option_chain
from .road_risk import occupancy_distribution, occupant_fn
from .sensitivity import SensitivityMixin
from .slope_models import SlopeModels, quantile_map

_quantile_map = quantile_map          # the name this function had here before the split (tests use it)


@dataclass(frozen=True)
class MitigationStudy(RecommendationMixin, SensitivityMixin, Displayed):
    """A hazard at the barrier line, the road exposure, consequences, economics and options.

    ``context`` (a :class:`~riskrf.risk.measures.SimulationContext`) is the slope model used to
    derive the options' effects; ``reference`` the simulation behind the hazard (road
    velocities, run-out).  ``small_fall_masses_kg`` and ``small_falls_per_year``: the
    inventory's falls below the power law's m_min (already scaled to this site).

    The options' effects are their kinds' (:mod:`riskrf.risk.options`), derived from the slope models
    (:mod:`riskrf.risk.slope_models`); one loss engine (:mod:`riskrf.risk.loss_engine`) computes every option's
    costs and risks; this class is the study: ranking, uncertainty, recommendation, sensitivity, value of
    information and decision tree.

    Lazy: building the study only checks its inputs.  The options' effects (their simulations), the mass
    grid, the central result and the uncertainty samples are computed on first use (``functools.cached_property``)
    by whichever method needs them first (:meth:`ranking`, :meth:`summary`, ...) and kept; the inputs are frozen,
    so the cached results never go stale and every later call returns the same numbers.
    """

    hazard: EnergyHazard
    options: tuple
    exposure: Exposure = Exposure()
    consequences: Consequences = Consequences()
    economics: Economics = Economics()
    road_share: float = 1.0            # P(reaches the road | reaches the barrier line)
    source: str = "<dict>"
    defaults_used: tuple = field(default_factory=tuple)
    context: SimulationContext | None = None
    reference: object = None
    small_fall_masses_kg: np.ndarray | None = field(default=None, repr=False)
    small_falls_per_year: float = 0.0
    uncertainty: Uncertainty = Uncertainty()
    criteria: Criteria = Criteria()
    design_checks: dict = field(default_factory=dict)   # option name -> verdict of its design checks (fences)
    #: the barrier the governing design basis requires (:class:`~riskrf.risk.required_barrier.RequiredBarrier`):
    #: ranked as an option when it can be placed; the recommendation says so when it cannot.  None: not computed.
    required_barrier: object = None
    coupled_road_hits: np.ndarray | None = field(default=None, repr=False)   # per block of the mass-coupled run
    #: the study repeated with independent trajectory ensembles
    #: (:class:`~riskrf.risk.error_budget.EnsembleReplicates`): their variance enters every reported standard
    #: error; None: the ensembles are held fixed and the outputs say their error is not included
    ensemble: object = field(default=None, repr=False)

    def __post_init__(self):
        _check_combinations(self.options, self.source)
        for o in self.options:
            effect_of(o).check(self.source)      # e.g. a closure rule not yet evaluated

    @property
    def currency(self) -> str:
        """Currency of every money figure of the study (from the consequences)."""
        return self.consequences.currency

    def option(self, name: str) -> Option:
        """The option named ``name``; a MitigationError listing the options when there is none.

        Parameters
        ----------
        name : str
            Name of an option of the study.

        Returns
        -------
        Option
            The option of that name.

        Raises
        ------
        MitigationError
            When no option has that name (the message lists the options).
        """
        opt = next((o for o in self.options if o.name == name), None)
        if opt is None:
            raise MitigationError(f"no option named {name!r}; options are {[o.name for o in self.options]}")
        return opt

    # ---- the mass grid ------------------------------------------------------------------------------
    @cached_property
    def _grid(self):
        """The engine's mass bins (:class:`~riskrf.risk.loss_engine.MassGrid`: edges, representative masses [kg],
        and the fixed small-fall histogram)."""
        return mass_grid(self.hazard.mass, self.small_fall_masses_kg, self.small_falls_per_year, self.uncertainty)

    def _mass_pmf(self, b=None, m_max=None):
        """Probability of each mass bin for one fall of at least m_min; arrays (S, J) for sampled b, m_max."""
        return mass_pmf(self._grid.edges, self.hazard.mass, b, m_max)

    def _fragment_matrix(self, fractal_dimension) -> np.ndarray:
        """(S, J, J) expected fragments by mass bin of one event by mass bin (see
        :func:`riskrf.risk.loss_engine.fragment_matrix`)."""
        return fragment_matrix(self._grid, fractal_dimension, self.uncertainty.fragmentation_iterations)

    # ---- slope models: the reference and the material-parameter variants ----------------------------
    @cached_property
    def _slopes(self) -> SlopeModels:
        """The slope models behind the derived effects and what is derived from them
        (:class:`~riskrf.risk.slope_models.SlopeModels`)."""
        return SlopeModels(self.hazard, self.context, self.reference, self.uncertainty, self._grid,
                           float(self.road_share), self.coupled_road_hits, self.exposure.exposed_length_m,
                           self.source)

    @property
    def _models(self) -> list:
        """The slope models (:class:`~riskrf.risk.slope_models.SlopeModel`): [0] the reference, then the joint
        material draws, then one low and one high variant per uncertain material parameter."""
        return self._slopes.models

    @property
    def _model_arrays(self):
        """Reach probability at the barrier line and P(road | barrier) per slope model."""
        return self._slopes.arrays

    @property
    def _derived(self) -> dict:
        """Derived retentions of the slope changes: key -> (overall retention of the reference model, its Beta law,
        overall retention per slope model, retention by mass bin per slope model)."""
        return self._slopes.derived

    def material_models(self) -> pd.DataFrame:
        """The slope models used: material values, reach probability and road share of each.

        Returns
        -------
        pandas.DataFrame
            One row per slope model (the reference, the joint material draws, the low and high variants): its material
            values, reach probability at the barrier line [-] and road share [-].
        """
        return self._slopes.table()

    def road_share_by_mass(self) -> pd.DataFrame:
        """P(reaches the road | reaches the barrier line) used for each mass bin [kg] of the reference model.

        Returns
        -------
        pandas.DataFrame
            Columns ``mass_kg`` (representative mass of the bin [kg]) and ``road_share`` (P(road | barrier line) [-],
            at most 1).
        """
        mid = self._grid.mid
        return pd.DataFrame({"mass_kg": mid, "road_share": np.minimum(self.road_share * self._slopes.road_profile,
                                                                      1.0)})

    # ---- option effects (derived once per slope model) ----------------------------------------------
    def _components(self, opt: Option) -> list:
        """The options acting for ``opt``: its components for a combined option, else itself."""
        return effect_of(opt).components(self.option)

    @cached_property
    def _space(self) -> ParameterSpace:
        """Where each named input sits in the engine's typed parameters."""
        return ParameterSpace([o.name for o in self.options])

    @cached_property
    def _effects(self) -> dict:
        """Per option: its :class:`~riskrf.risk.loss_engine.OptionChain` (stages in series and components)."""
        index_of = {o.name: k for k, o in enumerate(self.options)}
        return {o.name: option_chain(o, self._components(o), self._slopes, self._space, index_of)
                for o in self.options}

    def _barrier_stage(self, opt: Option):
        """The :class:`~riskrf.risk.loss_engine.BarrierStage` of a fence, attenuator or shed."""
        index = [o.name for o in self.options].index(opt.name)
        return effect_of(opt).stages(self._slopes, self._space, index)[0]

    @cached_property
    def _engine(self) -> LossEngine:
        """The loss engine of this study (its options' chains and the site)."""
        chains = tuple(self._effects[o.name] for o in self.options)
        slopes = self._slopes
        reach, share = slopes.arrays
        return LossEngine(self._grid, self.hazard.mass, self.hazard.rate_per_year, self.small_falls_per_year,
                          reach, share, slopes.road_profile, None if slopes.by_mass is None else slopes.by_mass[2],
                          self.exposure, self.consequences, self.economics,
                          self.uncertainty.fragmentation_iterations, chains)

    #: What this study computes on first use that the repeated trajectory ensembles (``ensemble``) do not change:
    #: :meth:`with_ensemble` keeps it.
    _KEPT_WITH_ENSEMBLE = ("_grid", "_slopes", "_space", "_effects", "_engine")

    def with_ensemble(self, ensemble) -> "MitigationStudy":
        """This study with the repeated trajectory ensembles of the error budget (the ``ensemble`` field); the slope
        models, option chains and loss engine already computed are kept, not computed again.

        Parameters
        ----------
        ensemble : riskrf.risk.error_budget.EnsembleReplicates or None
            Expected costs [study currency] and P(best) [-] per replicate and option.

        Returns
        -------
        MitigationStudy
        """
        new = replace(self, ensemble=ensemble)
        for name in self._KEPT_WITH_ENSEMBLE:
            if name in self.__dict__:
                new.__dict__[name] = self.__dict__[name]
        return new

    # ---- parameters -------------------------------------------------------------------------------
    def central_parameters(self) -> dict:
        """Every input the engine varies, at its central value (names used by tornado and break-even).

        Returns
        -------
        dict
            Parameter name -> central value, in the parameter's own unit: ``rate_factor`` [-],
            ``value_of_statistical_life`` [study currency], ``vulnerability_factor`` [-], ``vehicles_per_day``
            [1/day], ``discount_rate`` [1/yr], ``b`` [-], ``m_max_kg`` [kg], the options' parameters, the derived
            retentions ``retention:<key>`` [-] and ``material_draw`` (index of the slope model, 0 the reference).
        """
        self._effects
        hz, ex, co, ec = self.hazard, self.exposure, self.consequences, self.economics
        p = {"rate_factor": 1.0, "value_of_statistical_life": co.value_of_statistical_life,
             "vulnerability_factor": 1.0, "vehicles_per_day": ex.vehicles_per_day,
             "discount_rate": ec.discount_rate}
        if self.uncertainty.fractal_dimension:
            p["fractal_dimension"] = float(np.mean(self.uncertainty.fractal_dimension))
        gr = mass_model(hz.mass).power_law
        if gr is not None:
            p["b"] = float(gr.b)
            p["rate_sampling_factor"] = 1.0
            if gr.m_max is not None:
                p["m_max_kg"] = float(gr.m_max)
        for o in self.options:
            p.update(effect_of(o).parameters())
        for key, (ret, _, _, _) in self._derived.items():
            p[f"retention:{key}"] = ret
        p["material_draw"] = 0.0           # index of the slope model (0: the reference simulation)
        return p

    def parameter_ranges(self) -> dict:
        """name -> (low, high, how): the range each uncertain input is sampled over (and the tornado uses).

        Returns
        -------
        dict
            Parameter name (as in :meth:`central_parameters`, plus ``material:<path>`` for the uncertain material
            parameters) -> ``(low, high, how)``: the 5 % and 95 % points or the stated bounds, in the parameter's own
            unit, and the sampling law and its basis in words.
        """
        from scipy import stats
        u = self.uncertainty
        c = self.central_parameters()
        out = {}
        hz = self.hazard
        if "b" in c and u.sample_power_law:
            n = mass_model(hz.mass).power_law.n_tail
            g = stats.gamma(n, scale=1.0 / n)
            out["b"] = (c["b"] * g.ppf(0.05), c["b"] * g.ppf(0.95), "b x Gamma(n)/n (Jeffreys-prior posterior of b)")
            out["rate_sampling_factor"] = (g.ppf(0.05), g.ppf(0.95),
                                           "Gamma(n)/n (posterior of the rate of n recorded falls, prior 1/rate)")
        if u.rate_factor != (1.0, 1.0):
            out["rate_factor"] = (*u.rate_factor, "uniform, stated (share of the source above the road)")
        if u.m_max_kg and "m_max_kg" in c:
            out["m_max_kg"] = (*u.m_max_kg, "log-uniform, stated")
        for name in ("value_of_statistical_life", "vehicles_per_day", "discount_rate"):
            if getattr(u, name):
                out[name] = (*getattr(u, name), "uniform, stated")
        if u.vulnerability_factor != (1.0, 1.0):
            out["vulnerability_factor"] = (*u.vulnerability_factor,
                                           "log-uniform, stated (default: the vulnerability model's range, "
                                           "riskrf.risk.road_users.DEFAULT_VULNERABILITY)")
        if u.fractal_dimension and u.fractal_dimension[0] < u.fractal_dimension[1]:
            out["fractal_dimension"] = (*u.fractal_dimension, "uniform, stated (fractal fragmentation of each "
                                        f"event volume, {u.fragmentation_iterations} generations)")
        effects = [effect_of(o) for o in self.options]
        for e in effects:
            out.update(e.stated_ranges(c))
        for e in effects:
            out.update(e.assumed_ranges())
        if self.context is not None:
            for path, rng in sorted(self._slopes.material_ranges().items()):
                out[f"material:{path}"] = rng
        if u.sample_retention:
            for key, (_, (a, b), _, _) in self._derived.items():
                d = stats.beta(a, b)
                out[f"retention:{key}"] = (float(d.ppf(0.05)), float(d.ppf(0.95)),
                                           "Beta (Monte Carlo error of the derived retention)")
        return out

    def sample_parameters(self, n: int | None = None, seed=None) -> dict:
        """Joint samples of every uncertain input (arrays of length n), the rest at central values.

        Parameters
        ----------
        n : int, optional
            Number of joint samples (default ``uncertainty.samples``).
        seed : int, optional
            Seed of the sampling (default ``uncertainty.seed``).

        Returns
        -------
        dict
            Parameter name -> numpy.ndarray of length ``n`` (units as in :meth:`central_parameters`);
            ``material_draw`` holds the index of the slope model used by each sample.
        """
        from scipy import stats
        u = self.uncertainty
        n = int(u.samples if n is None else n)
        rng = np.random.default_rng(u.seed if seed is None else seed)
        c = self.central_parameters()
        ranges = self.parameter_ranges()
        out = {k: np.full(n, float(v)) for k, v in c.items()}
        n_draws = self.uncertainty.material_draws if any(k.startswith("material:") for k in ranges) else 0
        for name in sorted(ranges):            # fixed order: same seed, same samples
            lo, hi, how = ranges[name]
            if name.startswith("material:"):
                continue
            if name in ("b", "rate_sampling_factor"):
                n_tail = mass_model(self.hazard.mass).power_law.n_tail
                g = rng.gamma(n_tail, size=n) / n_tail
                out[name] = c[name] * g if name == "b" else g
            elif name.startswith("retention:") and "Beta" in how:
                key = name.split(":", 1)[1]
                a, b = self._derived[key][1]
                out[name] = stats.beta(a, b).ppf(rng.uniform(size=n))   # shifted per slope model in the engine
            elif "log-uniform" in how:
                out[name] = np.exp(rng.uniform(np.log(lo), np.log(hi), n))
            else:
                out[name] = rng.uniform(lo, hi, n)
        if n_draws:
            out["material_draw"] = rng.integers(1, n_draws + 1, n).astype(float)
        return out

    # ---- the loss engine --------------------------------------------------------------------------
    def _evaluate(self, P: dict, *, per_bin: bool = False) -> LossResult:
        """The one loss engine (:class:`~riskrf.risk.loss_engine.LossEngine`): every option for the named parameter
        arrays ``P`` (length S, names of :meth:`central_parameters`); arrays (S, K)."""
        engine = self._engine
        return engine.evaluate(self._space.typed(P), per_bin=per_bin)

    def _central(self, overrides: dict | None = None, **kw) -> dict:
        P = {k: np.array([float(v)]) for k, v in self.central_parameters().items()}
        for k, v in (overrides or {}).items():
            if k not in P:
                raise MitigationError(f"unknown parameter {k!r}; parameters are {sorted(P)}")
            P[k] = np.atleast_1d(np.asarray(v, dtype=float))
            n = P[k].size
        if overrides:
            P = {k: np.broadcast_to(v, (n,)) if v.size == 1 else v for k, v in P.items()}
        return self._evaluate(P, **kw)

    @cached_property
    def _central_result(self):
        return self._central(per_bin=True)

    def evaluate(self, option: Option | str) -> OptionResult:
        """Central-value results of one option.

        Parameters
        ----------
        option : Option or str
            The option, or its name.

        Returns
        -------
        OptionResult
            Rates [1/yr] (road falls, repairs, replacements, vehicle hits, rock strikes, deaths), expected annual
            loss [study currency/yr], individual risk [1/yr], retention and effectiveness [-].

        Raises
        ------
        MitigationError
            When the study has no such option.

        References
        ----------
        Bunce, C.M., Cruden, D.M. & Morgenstern, N.R. (1997) Assessment of the hazard from rock fall on a highway.
        Can. Geotech. J. 34:344-356 (a moving vehicle at the impact point).
        """
        opt = self.option(option if isinstance(option, str) else option.name)
        r = self._central_result
        k = r.names.index(opt.name)
        ret = float(r.retention[0, k])
        return OptionResult(opt, float(r.road[0, k]), float(r.repairs[0, k]), float(r.replacements[0, k]),
                            float(r.hits[0, k]), float(r.strikes[0, k]), float(r.deaths[0, k]),
                            float(r.eal[0, k]), float(r.ir[0, k]), None if np.isnan(ret) else ret,
                            float(r.effectiveness[0, k]))

    # ---- uncertainty ----------------------------------------------------------------------------
    def sampled_costs(self) -> dict:
        """The joint samples' total costs alone, without the tolerability statistics of :attr:`uncertain` (for the
        repeated ensembles of the error budget, which need the expected costs and P(best) only).

        Returns
        -------
        dict
            ``names`` (options), ``total`` (S, K) [study currency], ``mean`` per option [study currency] and
            ``probability_best`` per option [-].
        """
        r = self._evaluate(self.sample_parameters())
        best = np.argmin(r.total, axis=1)
        return {"names": r.names, "total": r.total, "mean": r.total.mean(axis=0),
                "probability_best": np.bincount(best, minlength=r.total.shape[1]) / r.total.shape[0]}

    @cached_property
    def uncertain(self) -> dict:
        """Joint samples: total cost per sample and option (S, K) and the derived statistics per option.

        Returns
        -------
        dict
            ``names`` (options), ``total`` (S, K) total cost per joint sample and option [study currency, present
            value], per option ``mean``, ``p05`` and ``p95`` [study currency], ``probability_best``,
            ``expected_regret`` [study currency], ``probability_meets_individual_risk`` and
            ``probability_meets_criteria`` [-]; ``evpi`` of all sampled inputs [study currency], ``samples`` (S),
            ``clusters`` (the material re-simulation of each sample, or None), ``best`` (index of the cheapest
            option per sample) and ``se`` (per option, the standard error of ``mean`` over every Monte Carlo
            source, :mod:`riskrf.risk.error_budget`) with ``error_sources`` (which, in words).

        References
        ----------
        Wyllie, D.C. (2014) Rock Fall Engineering. CRC Press, sec. 8.5.5.  Wyllie, D.C., McCammon, N.R. &
        Brumund, W.F. (1980) Planning slope stabilization programs by using decision analysis. Transportation
        Research Record 749:34-39.
        """
        P = self.sample_parameters()
        r = self._evaluate(P, per_bin=True)
        total = r.total
        best = np.argmin(total, axis=1)
        K = total.shape[1]
        p_best = np.bincount(best, minlength=K) / total.shape[0]
        regret = (total - total.min(axis=1, keepdims=True)).mean(axis=0)
        ir_ok = r.ir <= self.criteria.individual_risk_per_year
        fn_ok = self._fn_tolerable(r)
        # the samples share material re-simulations only when the slope materials are uncertain (else every
        # sample has the reference model, index 0, and is its own cluster)
        clusters = P["material_draw"] if np.any(P.get("material_draw", 0) > 0) else None
        design = self._draw_design(clusters)
        ens = self.ensemble
        se = combined_se(clustered_se(total, clusters, design),
                         None if ens is None else np.array([ens.cost_variance(n) for n in r.names]))
        return {"names": r.names, "total": total, "mean": total.mean(axis=0), "clusters": clusters, "best": best,
                "design": design,
                "se": se, "error_sources": sources_text(total.shape[0], 0 if clusters is None else
                                                        len(np.unique(clusters)), ens),
                "probability_meets_criteria": (ir_ok & fn_ok).mean(axis=0),
                "p05": np.percentile(total, 5, axis=0), "p95": np.percentile(total, 95, axis=0),
                "probability_best": p_best, "expected_regret": regret,
                "probability_meets_individual_risk": ir_ok.mean(axis=0),
                "evpi": evpi_estimate(total).value if total.shape[0] > 1 and total.shape[1] > 1 else 0.0,
                "samples": total.shape[0]}

    def _draw_design(self, clusters):
        """The Latin-hypercube coordinates of the material draws the samples use (rows in the order of the draws
        that occur in ``clusters``), or None (no clusters, or draws from a calibration bootstrap)."""
        if clusters is None:
            return None
        D = self._slopes.draw_design()
        if D is None:
            return None
        used = np.unique(clusters).astype(int)                  # material_draw indices 1 ... G
        return D[used - 1] if used.max() <= len(D) else None

    def _fn_tolerable(self, r) -> np.ndarray:
        """Per sample and option: is the F-N curve outside the selected criteria's unacceptable region (N up to
        the occupancy of one vehicle here)?  The same F(N) as :meth:`fn_curve`, for every joint sample at once;
        always True for a criteria set without F-N lines."""
        from .road_risk import share_with_at_least
        cs = self.criteria.criteria_set
        if cs.fn_unacceptable is None:
            return np.ones(r.total.shape, dtype=bool)
        kk, pk = occupancy_distribution(self.exposure.occupants_per_vehicle, self.exposure.occupants_distribution)
        Ns = np.arange(1, int(kk.max()) + 1)
        x = r.road_bins * r.user_share[:, :, None]               # (S, K, J) falls meeting open road
        F = 0.0
        for v, p in ((r.v_d, r.p_st), (r.v_s, r.p_strike)):
            if np.array_equal(v, np.broadcast_to(v[:, :1], v.shape)):    # every option the same vulnerabilities
                F = F + np.einsum("skj,sjn->skn", x * p[:, None, None], share_with_at_least(v[:, 0], kk, pk))
            else:                                                          # e.g. fragments: each option its own
                F = F + np.einsum("skj,skjn->skn", x * p[:, None, None], share_with_at_least(v, kk, pk))
        return cs.fn_exceedance(F, Ns) <= 1.0

    # ---- societal risk -------------------------------------------------------------------------
    def fn_curve(self, option: str) -> pd.DataFrame:
        """F-N curve of an option: direct hits and strikes on fallen rocks, every block size, occupants as a
        distribution, N = 1 ... largest occupancy.

        Parameters
        ----------
        option : str
            Name of an option of the study.

        Returns
        -------
        pandas.DataFrame
            Columns ``N`` (number of deaths, 1 ... largest occupancy) and ``F`` (frequency of N or more deaths [1/yr]).

        References
        ----------
        Bunce, C.M., Cruden, D.M. & Morgenstern, N.R. (1997) Assessment of the hazard from rock fall on a highway.
        Can. Geotech. J. 34:344-356.
        """
        opt = self.option(option)
        r = self._central_result
        k = r.names.index(opt.name)
        x = r.road_bins[0, k] * r.user_share[0, k]             # falls meeting open road
        freq = np.concatenate([x * r.p_st[0], x * r.p_strike[0]])
        vul = np.concatenate([r.v_d[0, k], r.v_s[0, k]])
        kk, pk = occupancy_distribution(self.exposure.occupants_per_vehicle, self.exposure.occupants_distribution)
        return occupant_fn(freq, vul, kk, pk)

    # ---- ranking ---------------------------------------------------------------------------
    def ranking(self) -> pd.DataFrame:
        """Options ranked by expected total cost (mean over the joint samples), with the central-value
        breakdown, 5-95 % of the total, probability of being cheapest, expected regret and road-user risk.

        Returns
        -------
        pandas.DataFrame
            One row per option, cheapest expected total cost first: ``rank``, ``option``, ``kind``, the central-value
            breakdown ``capital``, ``pv_renewals``, ``pv_maintenance``, ``pv_expected_loss`` and
            ``cost_at_central_values`` [study currency], ``expected_total_cost``, ``cost_p05``, ``cost_p95`` and
            ``expected_regret`` [study currency], ``probability_best`` [-], ``road_falls_per_year``,
            ``repairs_per_year``, ``replacements_per_year``, ``deaths_per_year`` and ``individual_risk`` [1/yr],
            ``retention`` and ``effectiveness`` [-], the tolerability columns (``meets_criteria``, ``fn_zone``,
            ``F_N1_per_year`` [1/yr], ``fn_ratio_to_limit`` [-], ``alarp``), the cost-effectiveness columns
            (``benefit_cost_ratio`` [-], ``cost_per_life_saved`` [study currency], ``deaths_avoided_per_million``) and
            ``effect_basis`` / ``design_check``.

        References
        ----------
        Wyllie, D.C. (2014) Rock Fall Engineering. CRC Press, sec. 8.5.5.  Wyllie, D.C., McCammon, N.R. &
        Brumund, W.F. (1980) Planning slope stabilization programs by using decision analysis. Transportation
        Research Record 749:34-39.
        """
        r = self._central_result
        u = self.uncertain
        rows = []
        for k, opt in enumerate(self.options):
            fn = self.fn_curve(opt.name)
            ret = r.retention[0, k]
            rows.append({
                "option": opt.name, "kind": opt.kind,
                "capital": r.capital[0, k], "pv_renewals": r.pv_renewals[0, k],
                "pv_maintenance": r.pv_maintenance[0, k], "pv_expected_loss": r.pv_expected_loss[0, k],
                "cost_at_central_values": r.total[0, k],
                "expected_total_cost": u["mean"][k], "expected_total_cost_se": u["se"][k],
                "cost_p05": u["p05"][k], "cost_p95": u["p95"][k],
                "probability_best": u["probability_best"][k], "expected_regret": u["expected_regret"][k],
                "road_falls_per_year": r.road[0, k], "retention": None if np.isnan(ret) else float(ret),
                "effectiveness": r.effectiveness[0, k],
                "effect_basis": self._basis(opt),
                "repairs_per_year": r.repairs[0, k], "replacements_per_year": r.replacements[0, k],
                "deaths_per_year": r.deaths[0, k], "individual_risk": r.ir[0, k],
                "probability_meets_individual_risk": u["probability_meets_individual_risk"][k],
                "probability_meets_criteria": u["probability_meets_criteria"][k],
                "fn_zone": self.criteria.criteria_set.fn_zone(fn),
                "F_N1_per_year": float(fn["F"].iloc[0]) if len(fn) else 0.0,
                "fn_ratio_to_limit": float(self.criteria.criteria_set.fn_exceedance(
                    fn["F"].to_numpy()[None, :], fn["N"].to_numpy())[0]) if len(fn) else 0.0})
        df = pd.DataFrame(rows)
        base = df[df["kind"] == "none"]
        if len(base):
            b = base.iloc[0]
            spend = df["capital"] + df["pv_renewals"] + df["pv_maintenance"] \
                - (b["capital"] + b["pv_renewals"] + b["pv_maintenance"])
            saved = b["pv_expected_loss"] - df["pv_expected_loss"]
            with np.errstate(divide="ignore", invalid="ignore"):
                df["benefit_cost_ratio"] = np.where(spend > 0, saved / spend, np.nan)
                df["deaths_avoided_per_million"] = np.where(
                    spend > 0, (b["deaths_per_year"] - df["deaths_per_year"]) * self.economics.horizon_years
                    / spend * 1e6, np.nan)
        df["meets_criteria"] = [self._meets(row) for _, row in df.iterrows()]
        df["design_check"] = [self._design_check(o) for o in self.options]
        df["design_adequate"] = ~df["design_check"].str.contains("NOT ADEQUATE", regex=False)
        self._alarp(df)
        df = df.sort_values("expected_total_cost", kind="stable").reset_index(drop=True)
        df["rank"] = np.arange(1, len(df) + 1)
        return df

    def _basis(self, opt: Option) -> str:
        """How the option's effect is known (typed, computed, derived, or with an ASSUMED part), in words."""
        return effect_basis(opt, self._components(opt))

    def _design_check(self, opt: Option) -> str:
        """The verdict of an option's design checks (``design_checks``, e.g. a fence's 100-year energy against its
        MEL): "-" when it has none to pass, "not checked" for a barrier without one."""
        comps = self._components(opt)
        combined = comps != [opt]
        verdicts = [f"{c.name}: {self.design_checks[c.name]}" if combined else self.design_checks[c.name]
                    for c in comps if c.name in self.design_checks]
        if verdicts:
            return "; ".join(verdicts)
        return "not checked" if any(effect_of(c).needs_design_check for c in comps) else "-"

    def _meets(self, row) -> bool:
        return bool(row["individual_risk"] <= self.criteria.individual_risk_per_year
                    and row["fn_zone"] in ("ALARP", "broadly acceptable", "no societal criterion"))

    def _alarp(self, df: pd.DataFrame) -> None:
        """Cost per statistical life saved (against doing nothing) and the ALARP test of every option, in place.

        A tolerable option is ALARP when no option with fewer expected deaths saves lives at an incremental cost
        per statistical life (net of the other losses it saves) at most the threshold: the criteria's marginal
        cost per life (Swiss practice) or else the value of a statistical life, times ``disproportion_factor``."""
        from .tolerability import cost_per_statistical_life_saved
        cs = self.criteria.criteria_set
        vsl = self.consequences.value_of_statistical_life
        limit = (cs.marginal_cost_per_life or vsl) * self.criteria.disproportion_factor
        spend = (df["capital"] + df["pv_renewals"] + df["pv_maintenance"]).to_numpy()
        pvf = float(pv_factor(self.economics.discount_rate, self.economics.horizon_years))
        other = (df["pv_expected_loss"] - df["deaths_per_year"] * vsl * pvf).to_numpy()   # non-fatal losses, PV
        deaths = df["deaths_per_year"].to_numpy()
        hz = self.economics.horizon_years
        base = df.index[df["kind"] == "none"]
        if len(base):
            b = base[0]
            df["cost_per_life_saved"] = cost_per_statistical_life_saved(spend - spend[b], other[b] - other,
                                                                        deaths[b] - deaths, hz)
        notes = []
        for i in range(len(df)):
            if not df["meets_criteria"].iloc[i]:
                notes.append("not tolerable")
                continue
            better = [j for j in range(len(df)) if deaths[j] < deaths[i]]
            csls = {j: float(cost_per_statistical_life_saved(spend[j] - spend[i], other[i] - other[j],
                                                             deaths[i] - deaths[j], hz)) for j in better}
            cheap = [j for j, c in csls.items() if c <= limit]
            if cheap:
                j = min(cheap, key=lambda j: csls[j])
                cur = self.currency
                notes.append(f"not ALARP: {df['option'].iloc[j]} is safer at no extra net cost" if csls[j] <= 0 else
                             f"not ALARP: {df['option'].iloc[j]} saves lives at {money(csls[j], cur, sig=3)} per "
                             f"statistical life (threshold {money(limit, cur, sig=3)})")
            else:
                notes.append(f"ALARP: no safer option saves lives at {money(limit, self.currency, sig=3)} per "
                             "statistical life or less")
        df["alarp"] = notes

    # ---- decision tree -------------------------------------------------------------------------
    def to_tree(self):
        """The decision tree of this study at central values (costs in present value), from the same engine; its
        root says so (the ranking's expected total costs are means over the joint samples and may rank otherwise).

        Under each option a chance node gives the outcome of one fall reaching the road;
        branch costs are that outcome's mean cost (over the sizes reaching the road) times
        the discounted expected number of such falls, so the rollback equals the central
        cost of the ranking.

        Returns
        -------
        DecisionTree
            A decision node with one branch per option (its capital and present-value renewals and maintenance
            [study currency]) and under each a chance node of the outcomes of one fall reaching the road (costs in
            present value [study currency]).

        References
        ----------
        Wyllie, D.C. (2014) Rock Fall Engineering. CRC Press, sec. 8.5.5.  Wyllie, D.C., McCammon, N.R. &
        Brumund, W.F. (1980) Planning slope stabilization programs by using decision analysis. Transportation
        Research Record 749:34-39.
        """
        from .decision_tree import DecisionTree
        r = self._central_result
        ec, ex, co = self.economics, self.exposure, self.consequences
        pvf = pv_factor(ec.discount_rate, ec.horizon_years)
        k_occ, p_occ = occupancy_distribution(ex.occupants_per_vehicle, ex.occupants_distribution)
        occ = float(np.dot(k_occ, p_occ))
        p_st, p_strike = float(r.p_st[0]), float(r.p_strike[0])
        per_fall = float(closure_cost_per_fall(co, ex.vehicles_per_day))
        branches = []
        for k, opt in enumerate(self.options):
            x = r.road_bins[0, k]
            road = x.sum()
            n_pv = pvf * road
            vd = float(np.dot(x, r.v_d[0, k]) / road) if road > 0 else 0.0
            vs = float(np.dot(x, r.v_s[0, k]) / road) if road > 0 else 0.0
            u = float(r.user_share[0, k])          # a closure: share of falls meeting open road
            outcomes = [
                {"name": "vehicle hit", "probability": p_st * u,
                 "cost": n_pv * (per_fall + co.vehicle_damage + occ * vd * co.value_of_statistical_life)},
                {"name": "vehicle strikes rock on road", "probability": p_strike * u,
                 "cost": n_pv * (per_fall + co.vehicle_damage + occ * vs * co.value_of_statistical_life)},
                {"name": "closure and clean-up only", "probability": 1 - (p_st + p_strike) * u,
                 "cost": n_pv * per_fall}]
            branches.append({"name": opt.name, "cost": float(r.capital[0, k] + r.pv_renewals[0, k]
                                                             + r.pv_maintenance[0, k]),
                             "child": {"type": "chance", "name": "each fall reaching the road",
                                       "branches": outcomes}})
        return DecisionTree.from_dict({"type": "decision", "objective": "min", "branches": branches,
                                       "name": "mitigation at central values of the uncertain inputs"},
                                      source=self.source)

    def options_table(self) -> pd.DataFrame:
        """What each option is and assumes, and its effect as used.

        Returns
        -------
        pandas.DataFrame
            One row per option: ``option``, ``kind``, ``what it is and assumes``, ``retention`` and
            ``effectiveness`` [-] and ``effect_basis``.
        """
        r = self._central_result
        rows = []
        for k, o in enumerate(self.options):
            ret = r.retention[0, k]
            rows.append({"option": o.name, "kind": o.kind, "what it is and assumes": o.describe(self.currency),
                         "retention": None if np.isnan(ret) else float(ret),
                         "effectiveness": float(r.effectiveness[0, k]), "effect_basis": self._basis(o)})
        return pd.DataFrame(rows)

    # ---- notebook display --------------------------------------------------------------------
    def __repr__(self) -> str:
        return short_repr(self, f"{len(self.options)} options", repr(Path(str(self.source)).name),
                          currency=self.currency, samples=self.uncertainty.samples)

    def summary(self) -> pd.DataFrame:
        """The options ranked by expected total cost: :meth:`ranking`.

        Returns
        -------
        pandas.DataFrame
            One row per option, cheapest first (money in the study currency, rates per year).
        """
        return self.ranking()

    def plot(self, kind: str = "tornado", ax=None):
        """The study's figure, drawn by :mod:`riskrf.risk.figures`.

        Parameters
        ----------
        kind : {"tornado", "ranking"}
            ``"tornado"``: one-way sensitivity of the lowest expected total cost (:meth:`tornado`);
            ``"ranking"``: each option's expected total cost with its 5-95 % interval (:meth:`ranking`).
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes

        Raises
        ------
        MitigationError
            ``kind`` is neither ``"tornado"`` nor ``"ranking"``.
        """
        if kind not in ("tornado", "ranking"):
            raise MitigationError(f"plot: kind must be 'tornado' or 'ranking', not {kind!r}")
        from .figures import plot_study_ranking, plot_study_tornado
        return (plot_study_tornado if kind == "tornado" else plot_study_ranking)(self, ax=ax)


def load_mitigation(path, hazard: EnergyHazard, *, road_share: float = 1.0, **kw) -> MitigationStudy:
    """Read a mitigation TOML file (a site file works too) and combine it with an energy hazard.

    Keyword arguments (``context``, ``reference``, ``small_fall_masses_kg``, ``small_falls_per_year``)
    pass to :class:`MitigationStudy`.

    Parameters
    ----------
    path : str or pathlib.Path
        The mitigation or site TOML file.
    hazard : EnergyHazard
        Annual energy hazard at the barrier line (falls [1/yr], energies [kJ]).
    road_share : float, optional
        P(reaches the road | reaches the barrier line) [-] (default 1).
    **kw
        Further keyword arguments of :class:`MitigationStudy` (see above).

    Returns
    -------
    MitigationStudy
        The study (lazy: only its inputs are checked here).
    """
    path = Path(path)
    inputs, raw, rates = check_mitigation_file(path)
    if rates is not None:
        from .site_rates import evaluate_rates, inventory_record, resolve_closures
        inv = inventory_record(raw.get("inventory"))
        inputs["options"] = resolve_closures(inputs["options"], evaluate_rates(rates, path.parent, inv,
                                                                               inputs["options"]))
    return MitigationStudy(hazard=hazard, road_share=road_share, source=str(path), **inputs, **kw)
