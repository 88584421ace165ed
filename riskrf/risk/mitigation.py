"""Mitigation options ranked by expected total cost, with uncertainty and a recommendation.

    expected total cost = capital + PV(renewals) + PV(maintenance, repairs, replacements) + PV(expected losses)

(Wyllie 2014, 8.5.5; Wyllie, McCammon & Brumund 1980.)  Each option is a
transformation of the site (CLIMADA's measures: a measure changes the hazard, the
exposure or the vulnerability; one engine computes the losses):

* ``none``: the site as it is;
* ``scaling`` (scaling and bolting): removes the release of blocks between ``min_mass_kg``
  and ``max_mass_kg`` from the source zone ``zone_x_m`` (the share of the release line it
  covers follows from the scenario's seeder);
* ``ditch``: a catchment dug into the profile (``x_m``, ``width_m``, ``depth_m``); its
  retention is derived by re-simulating the scenario with the new profile;
* ``fence`` / ``attenuator``: a barrier line (``capacity_kj`` = MEL, ``height_m``) at the
  barrier collector; falls pass over (the block's underside, simulated centre height minus
  the radius of a block of that mass, above the fence: the simulator's own barrier rule,
  ``simulation.kernel.barrier_outcome``) or through (energy above MEL, from the simulated
  velocities and the mass model, block by block);
* ``shed``: covers ``covered_length_m`` of the exposed road (``traffic.exposed_length_m``)
  with a capacity ``capacity_kj``;
* ``realignment``: moves the road to ``road_x_m`` on the profile (share of falls still
  reaching it from the simulated run-out), or away from the slope altogether;
* ``combined``: several of the above (``options = [...]``) in series, each acting on the
  falls the previous ones let through, costs added: no double counting.

Damage states (fences, attenuators, sheds): an impact between SEL = MEL/3 and MEL is
held and costs ``repair_cost_per_impact``; an impact above MEL destroys the structure,
passes, costs ``replacement_cost`` (default: the capital cost) and leaves the road
unprotected for ``repair_days`` (ASSUMPTION, default 30 days for fences, 180 for sheds),
during which every fall passes.  With destructive impacts at rate lambda_d the share of
time out of service is lambda_d t_r / (1 + lambda_d t_r) (alternating renewal process).

A typed ``retention`` (ditch, fence) or ``rate_reduction`` (scaling) replaces the derived
effect; it is then an assumption and says so in every output.

Road losses per fall reaching the road, for falls of every size (the power law above
m_min and the inventory's own smaller falls below it): a moving vehicle at the impact
point (Bunce et al. 1997), a vehicle striking the rock lying on the road, deaths with a
vulnerability that depends on block mass (see :mod:`riskrf.risk.road_risk`), vehicle damage,
closure and clean-up.  All inputs come from a TOML file (README, "Mitigation files").
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np
import pandas as pd

from ..hazard.annual_hazard import EnergyHazard
from ..hazard.barriers import damage_state_shares, out_of_service_share
from .economics import pv_factor, renewal_factor
from ..hazard.impact_energy import mass_model
from .measures import (
    Ditch,
    MeasureError,
    SimulationContext,
    effective_samples,
    material_value,
    road_crossings,
    runout_beyond,
    scenario_with_ditches,
    scenario_with_materials,
    seeder_share,
)
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
    parse_mitigation,
    parse_option,
)
from ..frequency.power_law import GutenbergRichterFit
from ..core.format import money, probability
from .road_users import lane_hit_probability, lane_strike_probability
from .road_risk import (
    commuter_passage_probability,
    commuter_strike_probability,
    occupancy_distribution,
    occupant_fn,
    vulnerability_by_mass,
)
from ..core.units import kinetic_energy_kj


@dataclass(frozen=True)
class OptionResult:
    """Central-value results of one option (rates per year, money in the study currency)."""

    option: Option
    road_falls_per_year: float
    repairs_per_year: float
    replacements_per_year: float
    vehicle_hits_per_year: float
    rock_strikes_per_year: float
    deaths_per_year: float
    expected_annual_loss: float
    individual_risk: float
    retention: float | None
    effectiveness: float

    @property
    def held_impacts_above_sel_per_year(self) -> float:
        """Impacts per year [1/yr] held by the barrier above its service energy level (SEL = MEL / 3), each
        needing a repair; the same number as ``repairs_per_year``.
        """
        return self.repairs_per_year


@dataclass(frozen=True)
class _Stage:
    """One element acting on the falls in series (see ``_chain``)."""

    kind: str                  # "release", "ditch", "barrier", "exposure", "closure"
    option: str
    multiplier: np.ndarray | None = None      # release: per mass bin
    param: str | None = None                  # parameter holding a sampled retention / rate reduction
    passing: np.ndarray | None = None         # barrier: per mass bin, working structure
    held_sel: np.ndarray | None = None
    destroy: np.ndarray | None = None
    coverage: float = 1.0
    after_road: bool = False
    factor: object = 0.0                      # exposure: share per slope model; ditch: retention shift per model


@dataclass(frozen=True)
class MitigationStudy:
    """A hazard at the barrier line, the road exposure, consequences, economics and options.

    ``context`` (a :class:`~riskrf.risk.measures.SimulationContext`) is the slope model used to
    derive the options' effects; ``reference`` the simulation behind the hazard (road
    velocities, run-out).  ``small_fall_masses_kg`` and ``small_falls_per_year``: the
    inventory's falls below the power law's m_min (already scaled to this site).

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
    coupled_road_hits: np.ndarray | None = field(default=None, repr=False)   # per block of the mass-coupled run

    def __post_init__(self):
        _check_combinations(self.options, self.source)
        for o in self.options:
            if o.kind == "closure" and o.share_while_closed is None:
                raise MitigationError(
                    f"{self.source}: option {o.name!r}: its closure rule ({o.rule_text()}) has not been evaluated: "
                    "the share of falls while closed and the closure hours are computed from a daily rate model "
                    "(a site file's [rates] table, riskrf assess; or riskrf.risk.site_rates.resolve_closures)")

    @property
    def currency(self) -> str:
        """Currency of every money figure of the study (from the consequences)."""
        return self.consequences.currency

    def option(self, name: str) -> Option:
        """The option named ``name``; a MitigationError listing the options when there is none."""
        opt = next((o for o in self.options if o.name == name), None)
        if opt is None:
            raise MitigationError(f"no option named {name!r}; options are {[o.name for o in self.options]}")
        return opt

    # ---- mass grid ----------------------------------------------------------------------
    @cached_property
    def _grid(self):
        """Mass bins [kg]: edges, representative masses, and the fixed small-fall histogram."""
        mm = mass_model(self.hazard.mass)
        gr = self.hazard.mass if isinstance(self.hazard.mass, GutenbergRichterFit) else None
        lo_candidates = [float(mm.isf(1 - 1e-9))] if gr is None else [gr.m_min]
        if self.small_fall_masses_kg is not None and len(self.small_fall_masses_kg):
            lo_candidates.append(float(np.min(self.small_fall_masses_kg)))
        lo = 0.999 * min(lo_candidates)
        if self.uncertainty.fractal_dimension:     # fragments keep their own masses: down to the finest generation
            lo /= 8.0 ** self.uncertainty.fragmentation_iterations
        if gr is not None:
            tops = [gr.m_max or gr.m_min * 1e6]
            if self.uncertainty.m_max_kg:
                tops.append(self.uncertainty.m_max_kg[1])
            hi = max(tops)
        else:
            hi = float(mm.isf(1e-9))
        edges = np.geomspace(lo, hi, MASS_BINS + 1)
        mid = np.sqrt(edges[:-1] * edges[1:])
        small = np.zeros(MASS_BINS)
        if self.small_fall_masses_kg is not None and len(self.small_fall_masses_kg) and self.small_falls_per_year > 0:
            small = np.histogram(np.clip(self.small_fall_masses_kg, lo, hi), edges)[0].astype(float)
            small /= small.sum()
        return edges, mid, small

    def _mass_pmf(self, b=None, m_max=None):
        """Probability of each mass bin for one fall of at least m_min; arrays (S, J) for sampled b, m_max."""
        edges = self._grid[0]
        m = self.hazard.mass
        if isinstance(m, GutenbergRichterFit) and b is not None:
            b = np.atleast_1d(b)[:, None]
            top = np.atleast_1d(m_max if m_max is not None else np.inf)[:, None]
            z = np.clip(edges[None, :], m.m_min, top)
            with np.errstate(divide="ignore"):
                t = np.where(np.isfinite(top), top ** -b, 0.0)
            sf = (z ** -b - t) / (m.m_min ** -b - t)
            sf[:, -1] = 0.0                                     # the last bin takes the tail
            return np.clip(-np.diff(sf, axis=1), 0.0, None)
        sf = mass_model(m).sf(edges)
        sf[-1] = 0.0
        return np.clip(-np.diff(sf), 0.0, None)[None, :]

    # ---- slope models: the reference and the material-parameter variants ------------------
    @cached_property
    def _models(self) -> list:
        """Slope models behind the derived effects: [0] the reference (the hazard's own simulation), then the
        joint material draws, then one low and one high variant per uncertain material parameter (tornado)."""
        models = [self._reference_model()]
        u = self.uncertainty
        ranges = self._material_ranges()
        if ranges and self.context is not None:
            ctx = self.context
            rng = np.random.default_rng(np.random.SeedSequence([u.seed, 13]))
            names = sorted(ranges)
            if u.calibration is not None:
                rows = u.calibration
                pick = rng.choice(len(rows), size=u.material_draws, replace=len(rows) < u.material_draws)
                draws = [{n: float(rows.iloc[i][f"materials.{n}"]) for n in names} for i in pick]
            else:
                draws = [{n: float(rng.uniform(*ranges[n][:2])) for n in names} for _ in range(u.material_draws)]
            central = {n: material_value(ctx.scenario, n) for n in names}
            variants = [(vals, "draw") for vals in draws] + \
                [({**central, n: v}, f"{n} {end}") for n in names for end, v in (("low", ranges[n][0]),
                                                                                 ("high", ranges[n][1]))]
            scenarios = [scenario_with_materials(ctx.scenario, vals, where=f"{self.source}: uncertainty.materials")
                         for vals, _ in variants]
            for (vals, label), sc, res in zip(variants, scenarios, ctx.run_many(scenarios)):
                models.append(self._simulated_model(vals, label, sc, res))
        return models

    def _material_ranges(self) -> dict:
        """"material.field" -> (low, high, how) of the uncertain slope material parameters."""
        u = self.uncertainty
        if u.calibration is not None:
            out = {}
            for col in u.calibration.columns:
                x = u.calibration[col].to_numpy(dtype=float)
                how = (f"joint rows of the calibration bootstrap {u.calibration_source} ({len(x)} replicates; "
                       f"5-95 %); {u.material_draws} re-simulations")
                out[col.removeprefix("materials.")] = (float(np.quantile(x, 0.05)), float(np.quantile(x, 0.95)), how)
            return out
        return {k: (lo, hi, f"uniform, stated; {u.material_draws} joint re-simulations")
                for k, (lo, hi) in u.materials.items()}

    def _reference_model(self) -> dict:
        v = self.hazard.velocity
        v = np.asarray(getattr(v, "velocity_ms", v), dtype=float)
        h = self.hazard.heights_m
        ctx = self.context
        m = {"label": "reference", "values": {}, "barrier": (v, None if h is None else np.asarray(h, dtype=float)),
             "reach": float(self.hazard.reach_probability), "road_share": float(self.road_share),
             "scenario": None if ctx is None else ctx.scenario, "result": self.reference}
        if self.reference is not None and ctx is not None and \
                ctx.road_collector in [c.name for c in self.reference.scenario.collectors]:
            m["road"] = effective_samples(self.reference, ctx.road_collector)
        return m

    def _simulated_model(self, values: dict, label: str, sc, res) -> dict:
        ctx = self.context
        v, h = effective_samples(res, ctx.barrier_collector)
        reach = max(v.size, 1) / res.n
        road = effective_samples(res, ctx.road_collector)
        share = min(road[0].size / v.size, 1.0) if v.size else 1.0
        return {"label": label, "values": values, "barrier": (v, h), "road": road, "reach": reach,
                "road_share": share, "scenario": sc, "result": res}

    @cached_property
    def _model_arrays(self):
        """Reach probability at the barrier line and P(road | barrier) per slope model."""
        ms = self._models
        reach = np.array([m["reach"] for m in ms])
        if self._by_mass is not None and len(ms) > 1:
            # mass-coupled: a variant's reach relative to the unmodified slope simulated alike (seeder masses),
            # times the hazard's mass-averaged reach (see _by_mass)
            res = self._reference_run
            base = effective_samples(res, self.context.barrier_collector)[0].size / res.n
            reach[1:] = reach[1:] * reach[0] / base if base > 0 else reach[1:]
        return reach, np.array([m["road_share"] for m in ms])

    def material_models(self) -> pd.DataFrame:
        """The slope models used: material values, reach probability and road share of each."""
        return pd.DataFrame([{"model": i, "label": m["label"], **m["values"], "reach_probability": m["reach"],
                              "road_share": m["road_share"]} for i, m in enumerate(self._models)])

    # ---- option effects (derived once per slope model) --------------------------------------
    def _barrier_stage(self, opt: Option) -> _Stage:
        mid = self._grid[1]
        cap = opt.capacity_kj
        fence_lines = self._fence_samples_at(opt) if opt.x_m is not None and opt.kind != "shed" else None
        out = []
        for m in self._models:
            if opt.kind == "shed":
                v, h = m.get("road", m["barrier"])
                over = np.zeros(v.size, dtype=bool)
            else:
                v, h = fence_lines[len(out)] if opt.x_m is not None else m["barrier"]
                if h is None or len(h) != len(v):
                    raise MitigationError(f"{self.source}: option {opt.name!r}: fences and attenuators need simulated "
                                          "velocities paired with bounce heights (a scenario, or a velocity file with "
                                          "height_m)")
                if opt.x_m is None and self._by_mass is not None:
                    out.append(self._damage_by_mass(m, v, h, opt.height_m, cap))
                    continue
                over = np.asarray(h)[:, None] - self._radius_m[None, :] > opt.height_m
            # energies of every (block, mass bin) pair [kJ]: E = 1/2 m v^2; damage states from riskrf.hazard.barriers
            out.append(damage_state_shares(kinetic_energy_kj(mid[None, :], v[:, None]), over, cap))
        passing, held_sel, destroy = (np.array([o[i] for o in out]) for i in range(3))
        coverage = min(opt.covered_length_m / self.exposure.exposed_length_m, 1.0) \
            if opt.kind == "shed" and opt.covered_length_m else 1.0
        return _Stage("barrier", opt.name, passing=passing, held_sel=held_sel, destroy=destroy, coverage=coverage,
                      after_road=opt.kind == "shed",
                      param=f"retention:{opt.name}" if opt.retention is not None else None)

    @cached_property
    def _radius_m(self) -> np.ndarray:
        """Radius [m] of a block of each mass bin's representative mass: the scenario's block shape and density
        (its seeder) when there is a slope model, else a sphere of 2,650 kg/m3.  A block passes over a fence when
        its underside (centre height - radius) clears the fence top, as in the simulator's barrier."""
        mid = self._grid[1]
        seeder = getattr(getattr(self.context, "scenario", None), "seeder", None)
        if seeder is not None:
            return np.asarray(seeder.radius(mid), dtype=float)
        from ..core.units import DEFAULT_DENSITY_KG_M3
        return (3.0 * mid / (4.0 * np.pi * DEFAULT_DENSITY_KG_M3)) ** (1.0 / 3.0)

    @cached_property
    def _by_mass(self):
        """For a mass-coupled hazard: per mass bin, its simulated mass class's arriving blocks (effective speeds
        [m/s], bounce heights [m], paired) and P(reach | class) over the hazard's mean reach probability; else None.

        The reference slope model's fence impacts and arrivals then follow block mass (heavier blocks arrive more
        often and faster).  A material variant keeps this mass dependence, changed as its pooled samples changed
        from those of the unmodified slope simulated alike (:attr:`_reference_run`: same blocks, seed and seeder
        masses; the hazard's own samples are another mass mixture): speeds by the ratio of the medians, bounce
        heights by quantile mapping (:func:`_quantile_map`; a ratio of medians is 0 or unbounded when most blocks
        roll, h = 0), reach by the ratio of the mean reach probabilities (:attr:`_model_arrays`).
        """
        hz = self.hazard
        if not hz.mass_coupled:
            return None
        vel = hz.velocity
        mid = self._grid[1]
        cls = vel.class_of(mid)
        k = vel.class_of(vel.mass_kg)
        arrived = vel.reached
        samples = {c: (vel.speed_ms[arrived & (k == c)], vel.height_m[arrived & (k == c)]) for c in np.unique(cls)}
        profile = vel.reach_by_class[cls] / max(float(hz.reach_probability), 1e-300)
        return cls, samples, profile

    @cached_property
    def _road_profile(self) -> np.ndarray:
        """Per mass bin: P(road | barrier line) of the bin's simulated mass class over the study's ``road_share``
        (ones without a mass-coupled hazard or its road crossings).

        One road share for all block sizes over-counts small falls at the road and under-counts large ones (large
        blocks run further); the blocks of each mass class of the hazard's mass-coupled run that crossed the barrier
        line and then the road line (``coupled_road_hits``) give each class its own share.  A class with fewer than
        20 blocks at the barrier line keeps the overall share."""
        mid = self._grid[1]
        ones = np.ones(mid.size)
        hits = self.coupled_road_hits
        if self._by_mass is None or hits is None or self.road_share <= 0:
            return ones
        vel = self.hazard.velocity
        hits = np.asarray(hits, dtype=bool)
        if hits.size != np.size(vel.mass_kg):
            raise MitigationError(f"{self.source}: coupled_road_hits has {hits.size} blocks; the hazard's mass-coupled "
                                  f"run has {np.size(vel.mass_kg)}")
        at_b = np.asarray(vel.reached, dtype=bool)
        k_blocks = vel.class_of(vel.mass_kg)
        cls = self._by_mass[0]
        out = ones.copy()
        for c in np.unique(cls):
            n_b = int((at_b & (k_blocks == c)).sum())
            if n_b >= 20:
                out[cls == c] = (hits & at_b & (k_blocks == c)).sum() / n_b / self.road_share
        return out

    def road_share_by_mass(self) -> pd.DataFrame:
        """P(reaches the road | reaches the barrier line) used for each mass bin [kg] of the reference model."""
        mid = self._grid[1]
        return pd.DataFrame({"mass_kg": mid, "road_share": np.minimum(self.road_share * self._road_profile, 1.0)})

    @cached_property
    def _variant_classes(self) -> dict:
        """id(slope model) -> per mass class (speeds [m/s], bounce heights [m]) at the barrier line as that model
        changes them (see :attr:`_by_mass`); filled once per model, shared by every barrier option."""
        return {}

    def _class_samples(self, model: dict, v, h) -> dict:
        cached = self._variant_classes.get(id(model))
        if cached is not None:
            return cached
        samples = self._by_mass[1]
        if model is not self._models[0]:                    # the reference slope model keeps its own samples
            ref_v, ref_h = self._reference_barrier
            sv = float(np.median(v) / np.median(ref_v)) if len(v) and len(ref_v) else 1.0
            mapped = len(h) and len(ref_h)
            samples = {c: (sv * vc, _quantile_map(hc, ref_h, h) if mapped else hc) for c, (vc, hc) in samples.items()}
        self._variant_classes[id(model)] = samples
        return samples

    def _damage_by_mass(self, model: dict, v, h, height_m: float, cap: float):
        """damage_state_shares per mass bin with the speeds and heights of the bin's own mass class (see _by_mass)."""
        cls = self._by_mass[0]
        mid = self._grid[1]
        shares = [np.zeros(mid.size) for _ in range(3)]
        for c, (vc, hc) in self._class_samples(model, v, h).items():
            j = cls == c
            over = np.asarray(hc)[:, None] - self._radius_m[j][None, :] > height_m
            got = damage_state_shares(kinetic_energy_kj(mid[j][None, :], vc[:, None]), over, cap)
            for out, part in zip(shares, got):
                out[j] = part
        return tuple(shares)

    def _fence_samples_at(self, opt: Option) -> list:
        """Per slope model: (effective speeds [m/s], bounce heights [m]) at the option's own line x_m."""
        import simulation.scenario as sc_mod
        ctx = self._need_context(opt, "x_m")
        prof = ctx.scenario.profile
        if not prof.x[0] < opt.x_m < prof.x[-1]:
            raise MitigationError(f"{self.source}: option {opt.name!r}: x_m = {opt.x_m:g} m is outside the profile "
                                  f"({prof.x[0]:g}, {prof.x[-1]:g}) m")
        col = sc_mod.Collector(f"{opt.name} line", float(opt.x_m))
        runs = ctx.run_many(replace(m["scenario"], collectors=m["scenario"].collectors + (col,)) for m in self._models)
        return [effective_samples(res, col.name) for res in runs]

    def _need_context(self, opt, fld):
        if self.context is None:
            raise MitigationError(f"{self.source}: option {opt.name!r}: {fld} needs the slope scenario to derive its "
                                  "effect (run with a scenario, or type an effectiveness as an assumption)")
        return self.context

    @cached_property
    def _reference_run(self):
        """The unmodified scenario with the re-simulation blocks and seed (the common random numbers)."""
        return self.context.run(self.context.scenario)

    @cached_property
    def _reference_barrier(self):
        """(effective speeds [m/s], bounce heights [m]) at the barrier line of :attr:`_reference_run`."""
        return effective_samples(self._reference_run, self.context.barrier_collector)

    @cached_property
    def _reference_road_blocks(self):
        return road_crossings(self._reference_run, self.context.road_collector)

    def _ditch_retentions(self, ditches) -> list:
        """:meth:`_ditch_retention` for every slope model (the changed profiles simulated at once): ditches
        (:class:`~riskrf.measures.Ditch`) and benches, bunds and drapes
        (:class:`~riskrf.risk.geometry_measures.SlopeMeasure`)."""
        from .geometry_measures import scenario_with_measures
        ctx = self.context
        try:
            if all(isinstance(d, Ditch) for d in ditches):
                scenarios = [scenario_with_ditches(m["scenario"], ditches, where=self.source,
                                                   road_collector=ctx.road_collector) for m in self._models]
            else:
                scenarios = [scenario_with_measures(m["scenario"], ditches, where=self.source,
                                                    road_collector=ctx.road_collector) for m in self._models]
        except (MeasureError, ValueError) as exc:
            raise MitigationError(str(exc)) from exc
        return [self._ditch_retention(m, i, res) for i, (m, res) in
                enumerate(zip(self._models, ctx.run_many(scenarios)))]

    def _ditch_retention(self, model: dict, index: int, ditched):
        """Share of the falls that would reach the road that the ditches stop (common random numbers): overall,
        its Monte Carlo Beta law, and by block mass (5 strata of the simulated masses, interpolated in log mass
        onto the mass grid and held constant beyond the simulated range)."""
        ctx = self.context
        base_res = self._reference_run if index == 0 else model["result"]
        base = self._reference_road_blocks if index == 0 else road_crossings(base_res, ctx.road_collector)
        kept = road_crossings(ditched, ctx.road_collector)
        mid = self._grid[1]
        k_b = base.size
        if k_b == 0:
            return 0.0, (0.5, 0.5), np.zeros(mid.size)
        mass = base_res.blocks["mass"]
        reached = np.zeros(mass.size, dtype=bool)
        reached[base] = True
        now = np.zeros(mass.size, dtype=bool)
        now[kept] = True
        stopped, extra = reached & ~now, now & ~reached        # extra: deflected onto the road by the ditch
        r = max(int(stopped.sum()) - int(extra.sum()), 0)
        edges = np.quantile(mass[reached], np.linspace(0, 1, 6))
        centres, rets = [], []
        for lo, hi in zip(edges[:-1], edges[1:]):
            s = (mass >= lo) & (mass <= hi)
            n_s = int((reached & s).sum())
            if n_s:
                centres.append(float(np.median(mass[reached & s])))
                rets.append(max(int((stopped & s).sum()) - int((extra & s).sum()), 0) / n_s)
        by_mass = np.interp(np.log(mid), np.log(centres), rets) if centres else np.full(mid.size, r / k_b)
        return r / k_b, (r + 0.5, k_b - r + 0.5), by_mass

    @cached_property
    def _derived(self) -> dict:
        """Derived ditch retentions: key -> (overall retention of the reference model, its Beta law, overall
        retention per slope model, retention by mass bin per slope model); filled by ``_effects``."""
        return {}

    @cached_property
    def _effects(self) -> dict:
        """Per option: the chain of stages in series and its component options."""
        out = {}
        for opt in self.options:
            comps = [self.option(n) for n in opt.options] if opt.kind == "combined" else [opt]
            out[opt.name] = (self._chain(opt, comps), comps)
        return out

    def _chain(self, opt: Option, comps) -> list:
        mid = self._grid[1]
        stages = []
        for c in comps:
            if c.kind == "scaling":
                if c.rate_reduction is not None:
                    stages.append(_Stage("release", c.name, param=f"rate_reduction:{c.name}"))
                else:
                    share = 1.0
                    if c.zone_x_m is not None:
                        ctx = self._need_context(c, "zone_x_m")
                        try:
                            share = seeder_share(ctx.scenario, c.zone_x_m, f"{self.source}: option {c.name!r}")
                        except MeasureError as exc:
                            raise MitigationError(str(exc)) from exc
                    lo, hi = c.min_mass_kg or 0.0, c.max_mass_kg or np.inf
                    inside = (mid >= lo) & (mid <= hi)
                    # the targeted releases (derived: zone and mass range) times the ASSUMED mean effectiveness
                    stages.append(_Stage("release", c.name, param=f"scaling_effectiveness:{c.name}",
                                         factor=share * inside.astype(float)))
        ditches = [c for c in comps if c.kind in ("ditch",) + SLOPE_KINDS]
        typed = [c for c in ditches if c.retention is not None]
        for c in typed:
            stages.append(_Stage("ditch", c.name, param=f"retention:{c.name}"))
        geo = [c for c in ditches if c.retention is None]
        if geo:
            self._need_context(geo[0], "x_m")
            from .geometry_measures import SlopeMeasure
            ds = [Ditch(c.x_m, c.width_m, c.depth_m, c.inner_slope_hv or 0.25,
                        1.0 if c.outer_slope_hv is None else c.outer_slope_hv, c.material, c.name)
                  if c.kind == "ditch" else
                  SlopeMeasure(c.kind, c.name, c.x_m, c.width_m, c.height_m, c.zone_x_m, c.inner_slope_hv,
                               c.outer_slope_hv, c.material) for c in geo]
            key = "+".join(c.name for c in geo)
            if key not in self._derived:
                per_model = self._ditch_retentions(ds)
                self._derived[key] = (per_model[0][0], per_model[0][1], np.array([r for r, _, _ in per_model]),
                                      np.array([b for _, _, b in per_model]))
            # retention by mass bin and slope model, as a shift from the overall reference retention (the parameter)
            stages.append(_Stage("ditch", key, param=f"retention:{key}",
                                 factor=self._derived[key][3] - self._derived[key][0]))
        for c in comps:
            if c.kind in ("fence", "attenuator"):
                stages.append(self._barrier_stage(c))
        for c in comps:
            if c.kind == "shed":
                stages.append(self._barrier_stage(c))
        for c in comps:
            if c.kind == "closure":
                stages.append(_Stage("closure", c.name, param=f"closure_share:{c.name}"))
        for c in comps:
            if c.kind == "realignment":
                if c.road_x_m is None:
                    factor = np.zeros(len(self._models))
                else:
                    ctx = self._need_context(c, "road_x_m")
                    prof = ctx.scenario.profile
                    if not prof.x[0] < c.road_x_m < prof.x[-1]:
                        raise MitigationError(f"{self.source}: option {c.name!r}: road_x_m = {c.road_x_m:g} m is "
                                              f"outside the profile ({prof.x[0]:g}, {prof.x[-1]:g}) m")
                    factor = []
                    for m in self._models:
                        ref = m["result"] if m["result"] is not None else self._reference_run
                        road_x = ref.scenario.collectors[ref.scenario.collector_index(ctx.road_collector)].x
                        now = runout_beyond(ref, road_x).sum()
                        factor.append(min(float(runout_beyond(ref, c.road_x_m).sum() / now), 1.0) if now else 0.0)
                    factor = np.array(factor)
                stages.append(_Stage("exposure", c.name, factor=factor))
        return stages

    # ---- parameters -----------------------------------------------------------------------
    def central_parameters(self) -> dict:
        """Every input the engine varies, at its central value (names used by tornado and break-even)."""
        self._effects
        hz, ex, co, ec = self.hazard, self.exposure, self.consequences, self.economics
        p = {"rate_factor": 1.0, "value_of_statistical_life": co.value_of_statistical_life,
             "vulnerability_factor": 1.0, "vehicles_per_day": ex.vehicles_per_day,
             "discount_rate": ec.discount_rate}
        if self.uncertainty.fractal_dimension:
            p["fractal_dimension"] = float(np.mean(self.uncertainty.fractal_dimension))
        if isinstance(hz.mass, GutenbergRichterFit):
            p["b"] = float(hz.mass.b)
            p["rate_sampling_factor"] = 1.0
            if hz.mass.m_max is not None:
                p["m_max_kg"] = float(hz.mass.m_max)
        for o in self.options:
            if o.kind == "combined":
                continue
            p[f"capital_cost:{o.name}"] = o.capital_cost
            p[f"annual_maintenance:{o.name}"] = o.annual_maintenance
            if o.rate_reduction is not None:
                p[f"rate_reduction:{o.name}"] = o.rate_reduction
            elif o.kind == "scaling":
                p[f"scaling_effectiveness:{o.name}"] = o.scaling_effect()[3]
            if o.retention is not None:
                p[f"retention:{o.name}"] = o.retention
            if o.kind == "closure":
                p[f"closure_share:{o.name}"] = o.share_while_closed
            if o.kind in BARRIER_KINDS:
                p[f"repair_days:{o.name}"] = self._repair_days(o)
        for key, (ret, _, _, _) in self._derived.items():
            p[f"retention:{key}"] = ret
        p["material_draw"] = 0.0           # index of the slope model (0: the reference simulation)
        return p

    def _repair_days(self, o):
        return DEFAULT_REPAIR_DAYS[o.kind] if o.repair_days is None else o.repair_days

    def parameter_ranges(self) -> dict:
        """name -> (low, high, how): the range each uncertain input is sampled over (and the tornado uses)."""
        from scipy import stats
        u = self.uncertainty
        c = self.central_parameters()
        out = {}
        hz = self.hazard
        if "b" in c and u.sample_power_law:
            n = hz.mass.n_tail
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
        for o in self.options:
            for fld, rng_name in (("capital_cost", "capital_cost_range"), ("annual_maintenance",
                                                                            "annual_maintenance_range"),
                                  ("retention", "retention_range"), ("rate_reduction", "rate_reduction_range")):
                rng = getattr(o, rng_name)
                if rng is not None and f"{fld}:{o.name}" in c:
                    out[f"{fld}:{o.name}"] = (*rng, "uniform, stated" + (" (typed effectiveness: assumption)"
                                                                         if fld in ("retention", "rate_reduction")
                                                                         else ""))
        for o in self.options:
            if o.kind == "scaling" and o.rate_reduction is None:
                e0, (a, b), h, _, (lo, hi) = o.scaling_effect()
                if hi > lo:
                    out[f"scaling_effectiveness:{o.name}"] = (
                        lo, hi, f"uniform, ASSUMED (removes {a:.0%}-{b:.0%} of the targeted releases when new, "
                        f"halving every {h:g} years; mean over the cycle)")
        if self.context is not None:
            for path, rng in sorted(self._material_ranges().items()):
                out[f"material:{path}"] = rng
        if u.sample_retention:
            for key, (_, (a, b), _, _) in self._derived.items():
                d = stats.beta(a, b)
                out[f"retention:{key}"] = (float(d.ppf(0.05)), float(d.ppf(0.95)),
                                           "Beta (Monte Carlo error of the derived retention)")
        return out

    def sample_parameters(self, n: int | None = None, seed=None) -> dict:
        """Joint samples of every uncertain input (arrays of length n), the rest at central values."""
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
                g = rng.gamma(self.hazard.mass.n_tail, size=n) / self.hazard.mass.n_tail
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

    # ---- the loss engine ---------------------------------------------------------------------
    def _fragment_matrix(self, fractal_dimension) -> np.ndarray:
        """(S, J, J): expected fragments in mass bin k of one event in mass bin j, by fractal fragmentation
        (Perfect 1997, :func:`riskrf.hazard.design_block.fractal_fragments`) of the bin's middle mass for each sampled
        D.  With fragmentation the mass grid reaches down to the finest generation of its lightest event, so
        every fragment keeps its own mass (fragments' masses add up to the event's, within the bins' widths)."""
        from ..hazard.design_block import fractal_fragments
        edges, mid, _ = self._grid
        n_gen = self.uncertainty.fragmentation_iterations
        D = np.atleast_1d(np.asarray(fractal_dimension, dtype=float))
        Du, which = np.unique(D, return_inverse=True)     # each distinct D once (a scan holds D at one value)
        tables = [fractal_fragments(1.0, float(d), n_gen) for d in Du]      # per unit volume of the event
        share = tables[0]["volume_m3"].to_numpy()                            # fragment / event volume (D-free)
        counts = np.array([t["count"].to_numpy() for t in tables])[which.ravel()]     # (S, G)
        k = np.clip(np.searchsorted(edges, mid[:, None] * share[None, :], side="right") - 1, 0, mid.size - 1)
        out = np.zeros((D.size, mid.size, mid.size))
        rows = np.arange(mid.size)
        for g in range(share.size):                   # one generation at a time: (row, bin) pairs are distinct
            out[:, rows, k[:, g]] += counts[:, g][:, None]
        return out

    @staticmethod
    def _events_at_road(frag, x, v_d, v_s):
        """Fragments reaching the road -> the events they came from: (events per year by event mass bin,
        vulnerability given the event meets a vehicle, moving and striking), each (S, J).

        ``frag`` = (events per year by mass bin, fragment matrix F (S, J, J), fragments per year by mass bin).  A
        share tau_k = x_k / fragments_k of bin k's fragments reaches the road under the option; an event's
        reaching fragments are taken as Poisson, so the event reaches the road with probability
        1 - exp(-sum_k F_jk tau_k).  A vehicle meets an event's debris once (the exposure is per event, as for an
        intact block); it is fatal unless every reaching fragment spares it: 1 - exp(-sum_k F_jk tau_k v_k),
        given the event reaches the road, divided by that probability."""
        lam_events, F, blocks = frag
        with np.errstate(invalid="ignore", divide="ignore"):
            tau = np.where(blocks > 0, np.clip(x / blocks, 0.0, 1.0), 0.0)
        reach = -np.expm1(-np.einsum("sjk,sk->sj", F, tau))
        out = []
        for v in (v_d, v_s):
            lethal = -np.expm1(-np.einsum("sjk,sk->sj", F, tau * v))
            with np.errstate(invalid="ignore", divide="ignore"):
                out.append(np.where(reach > 0, np.clip(lethal / reach, 0.0, 1.0), 0.0))
        return lam_events * reach, out[0], out[1]

    @staticmethod
    def _released_share(frag, event_scale) -> np.ndarray:
        """(S, J): share of each fragment mass bin still released when a source measure scales the events by
        ``event_scale`` (S, J) (by the event's mass bin)."""
        lam_events, F, blocks = frag
        released = np.einsum("sj,sjk->sk", lam_events * event_scale, F)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(blocks > 0, released / blocks, 0.0)

    def _evaluate(self, P: dict, *, per_bin: bool = False) -> dict:
        """The one loss engine: every option for parameter arrays ``P`` (length S); arrays (S, K)."""
        effects = self._effects
        edges, mid, small_pmf = self._grid
        S = len(next(iter(P.values())))
        hz, ex, co, ec = self.hazard, self.exposure, self.consequences, self.economics
        d = P["material_draw"].astype(int) if "material_draw" in P else np.zeros(S, dtype=int)
        reach_m, share_m = self._model_arrays
        # P(road | barrier line) per sample and mass bin: the slope model's share times the reference run's profile
        # by block mass (heavier blocks run further; :attr:`_road_profile`)
        road_share = np.minimum(share_m[d][:, None] * self._road_profile[None, :], 1.0)   # (S, J)
        rate = hz.rate_per_year * P["rate_factor"] * P.get("rate_sampling_factor", 1.0)
        pmf = self._mass_pmf(P.get("b"), P.get("m_max_kg")) if "b" in P else self._mass_pmf()
        lam = rate[:, None] * pmf + (self.small_falls_per_year * P["rate_factor"])[:, None] * small_pmf[None, :]
        frag = None
        if "fractal_dimension" in P:                    # events break up: their fragments are the blocks that travel
            F = self._fragment_matrix(P["fractal_dimension"])
            frag = (lam, F, np.einsum("sj,sjk->sk", lam, F))
            lam = frag[2]
        arrivals = lam * reach_m[d][:, None]                                       # (S, J) at the barrier line
        if self._by_mass is not None:                   # mass-coupled: heavier blocks reach the line more often
            arrivals = arrivals * self._by_mass[2][None, :]
        # Bunce et al. (1997) per lane: a fall lands in one lane and only that lane's vehicles can be hit
        lanes = ex.lane_list()
        traffic = np.asarray(P["vehicles_per_day"], dtype=float) / ex.vehicles_per_day
        p_st = np.broadcast_to(lane_hit_probability(lanes, ex.vehicle_length_m, traffic), (S,))
        p_strike = ex.share_stopping_on_road * np.broadcast_to(lane_strike_probability(
            lanes, ex.hours_rock_on_road, ex.p_cannot_stop, traffic), (S,))
        vf = P["vulnerability_factor"][:, None]
        v_d = np.minimum(vulnerability_by_mass(mid, co.vulnerability_moving_vehicle)[None, :] * vf, 1.0)
        v_s = np.minimum(vulnerability_by_mass(mid, co.vulnerability_striking_rock)[None, :] * vf, 1.0)
        k_occ, p_occ = occupancy_distribution(ex.occupants_per_vehicle, ex.occupants_distribution)
        occ = float(np.dot(k_occ, p_occ))
        p_ts = commuter_passage_probability(ex.commuter_trips_per_day, ex.vehicle_length_m, ex.speed_kmh)
        p_cs = ex.share_stopping_on_road * commuter_strike_probability(ex.commuter_trips_per_day,
                                                                       ex.hours_rock_on_road, ex.p_cannot_stop)
        r = P["discount_rate"]
        pvf = np.broadcast_to(pv_factor(r, ec.horizon_years), (S,))
        per_fall_cost = np.broadcast_to(closure_cost_per_fall(co, P["vehicles_per_day"]), (S,))
        names = [o.name for o in self.options]
        K = len(names)
        res = {k: np.zeros((S, K)) for k in ("capital", "pv_renewals", "pv_maintenance", "pv_expected_loss",
                                              "total", "road", "hits", "strikes", "deaths", "eal", "ir",
                                              "repairs", "replacements", "retention", "effectiveness",
                                              "user_share")}
        road_bins = np.zeros((S, K, mid.size)) if per_bin else None
        vd_all, vs_all = (np.zeros((S, K, mid.size)), np.zeros((S, K, mid.size))) if per_bin else (None, None)
        base_road = (arrivals * road_share).sum(axis=1) if frag is None else \
            self._events_at_road(frag, arrivals * road_share, v_d, v_s)[0].sum(axis=1)
        for k, opt in enumerate(self.options):
            stages, comps = effects[opt.name]
            ev_scale, g_prev = 1.0, None if frag is None else np.ones_like(lam)   # source measures on events
            x = arrivals.copy()
            stopped_by_structures = np.zeros(S)
            before_structures = None
            maint = np.zeros(S)
            capital = np.zeros(S)
            renew = np.zeros(S)
            repairs = np.zeros(S)
            replacements = np.zeros(S)
            repair_money = np.zeros(S)
            for c in comps:
                kc = P[f"capital_cost:{c.name}"]
                capital += kc
                maint += P[f"annual_maintenance:{c.name}"]
                if c.life_years:
                    renew += kc * renewal_factor(c.life_years, ec.horizon_years, r)
            on_road = False
            users = np.ones(S)          # share of falls meeting open road (a closure protects users only)
            for st in stages:
                if st.after_road and not on_road:
                    x = x * road_share
                    on_road = True
                if st.kind == "closure":
                    users = users * (1.0 - P[st.param])
                    continue
                if st.kind == "release":
                    if st.multiplier is not None:
                        m = st.multiplier[None, :]
                    elif st.param.startswith("scaling_effectiveness:"):
                        m = 1.0 - np.clip(P[st.param], 0.0, 1.0)[:, None] * st.factor[None, :]
                    else:
                        m = (1.0 - P[st.param])[:, None]
                    if frag is None:
                        x = x * m
                    else:           # a source measure removes events (by the event's mass), hence their fragments
                        ev_scale = ev_scale * m
                        g = self._released_share(frag, ev_scale)
                        with np.errstate(invalid="ignore", divide="ignore"):
                            x = np.where(g_prev > 0, x * g / g_prev, 0.0)
                        g_prev = g
                    continue
                if before_structures is None:
                    before_structures = x.sum(axis=1) if on_road else (x * road_share).sum(axis=1)
                if st.kind == "ditch":
                    ret = P[st.param][:, None] + (st.factor[d] if isinstance(st.factor, np.ndarray) else 0.0)
                    x = x * (1.0 - np.clip(ret, 0.0, 1.0))
                elif st.kind == "barrier":
                    c = self.option(st.option)
                    reach = x * st.coverage
                    lam_d = (reach * st.destroy[d]).sum(axis=1)
                    down = out_of_service_share(lam_d, P[f"repair_days:{c.name}"])
                    held = (reach * st.held_sel[d]).sum(axis=1) * (1.0 - down)
                    destroyed = lam_d * (1.0 - down)
                    repairs += held
                    replacements += destroyed
                    repair_money += held * c.repair_cost_per_impact + destroyed * (
                        P[f"capital_cost:{c.name}"] if c.replacement_cost is None else c.replacement_cost)
                    working = st.passing[d] if st.param is None else (1.0 - P[st.param])[:, None]
                    passing = down[:, None] + (1.0 - down[:, None]) * working
                    x = x * (1.0 - st.coverage) + reach * passing
                elif st.kind == "exposure":
                    x = x * st.factor[d][:, None]
            if not on_road:
                x = x * road_share
            vd_k, vs_k = v_d, v_s
            if frag is not None:        # from fragments reaching the road to the events they came from
                x_blocks = x
                x, vd_k, vs_k = self._events_at_road((frag[0] * ev_scale, frag[1], frag[2] * g_prev), x, v_d, v_s)
            road = x.sum(axis=1)
            if before_structures is not None and any(s.kind in ("ditch", "barrier") for s in stages):
                passed = road if frag is None else x_blocks.sum(axis=1)     # share of the blocks stopped
                with np.errstate(invalid="ignore", divide="ignore"):
                    stopped_by_structures = np.where(before_structures > 0, 1.0 - passed / before_structures, 0.0)
                    if any(s.kind == "exposure" for s in stages):
                        stopped_by_structures = np.full(S, np.nan)
            else:
                stopped_by_structures = np.full(S, np.nan)
            hits = x * (p_st * users)[:, None]
            strikes = x * (p_strike * users)[:, None]
            deaths = occ * ((hits * vd_k).sum(axis=1) + (strikes * vs_k).sum(axis=1))
            eal = deaths * P["value_of_statistical_life"] + (hits.sum(axis=1) + strikes.sum(axis=1)) \
                * co.vehicle_damage + road * per_fall_cost
            ir = (x * (p_ts * vd_k + p_cs * vs_k)).sum(axis=1) * users
            pv_m = pvf * (maint + repair_money)
            pv_l = pvf * eal
            for key, val in (("capital", capital), ("pv_renewals", renew), ("pv_maintenance", pv_m),
                             ("pv_expected_loss", pv_l), ("total", capital + renew + pv_m + pv_l), ("road", road),
                             ("hits", hits.sum(axis=1)), ("strikes", strikes.sum(axis=1)), ("deaths", deaths),
                             ("eal", eal), ("ir", ir), ("repairs", repairs), ("replacements", replacements),
                             ("retention", stopped_by_structures)):
                res[key][:, k] = val
            with np.errstate(invalid="ignore", divide="ignore"):
                res["effectiveness"][:, k] = np.where(base_road > 0, 1.0 - road / base_road, 0.0)
            res["user_share"][:, k] = users
            if per_bin:
                road_bins[:, k, :] = x
                vd_all[:, k, :], vs_all[:, k, :] = vd_k, vs_k
        res["names"] = names
        if per_bin:
            res["road_bins"] = road_bins
            res["p_st"], res["p_strike"], res["v_d"], res["v_s"] = p_st, p_strike, vd_all, vs_all   # (S, K, J)
        return res

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
        """Central-value results of one option."""
        opt = self.option(option if isinstance(option, str) else option.name)
        r = self._central_result
        k = r["names"].index(opt.name)
        ret = float(r["retention"][0, k])
        return OptionResult(opt, float(r["road"][0, k]), float(r["repairs"][0, k]), float(r["replacements"][0, k]),
                            float(r["hits"][0, k]), float(r["strikes"][0, k]), float(r["deaths"][0, k]),
                            float(r["eal"][0, k]), float(r["ir"][0, k]), None if np.isnan(ret) else ret,
                            float(r["effectiveness"][0, k]))

    # ---- uncertainty ----------------------------------------------------------------------------
    @cached_property
    def uncertain(self) -> dict:
        """Joint samples: total cost per sample and option (S, K) and the derived statistics per option."""
        P = self.sample_parameters()
        r = self._evaluate(P, per_bin=True)
        total = r["total"]
        best = np.argmin(total, axis=1)
        K = total.shape[1]
        p_best = np.bincount(best, minlength=K) / total.shape[0]
        regret = (total - total.min(axis=1, keepdims=True)).mean(axis=0)
        ir_ok = r["ir"] <= self.criteria.individual_risk_per_year
        fn_ok = self._fn_tolerable(r)
        return {"names": r["names"], "total": total, "mean": total.mean(axis=0),
                "probability_meets_criteria": (ir_ok & fn_ok).mean(axis=0),
                "p05": np.percentile(total, 5, axis=0), "p95": np.percentile(total, 95, axis=0),
                "probability_best": p_best, "expected_regret": regret,
                "probability_meets_individual_risk": ir_ok.mean(axis=0),
                "evpi": max(float(total.mean(axis=0).min() - total.min(axis=1).mean()), 0.0),
                "samples": total.shape[0]}

    def _fn_tolerable(self, r) -> np.ndarray:
        """Per sample and option: is the F-N curve outside the selected criteria's unacceptable region (N up to
        the occupancy of one vehicle here)?  The same F(N) as :meth:`fn_curve`, for every joint sample at once;
        always True for a criteria set without F-N lines."""
        from .road_risk import share_with_at_least
        cs = self.criteria.criteria_set
        if cs.fn_unacceptable is None:
            return np.ones(r["total"].shape, dtype=bool)
        kk, pk = occupancy_distribution(self.exposure.occupants_per_vehicle, self.exposure.occupants_distribution)
        Ns = np.arange(1, int(kk.max()) + 1)
        a_d, a_s = share_with_at_least(r["v_d"], kk, pk), share_with_at_least(r["v_s"], kk, pk)   # (S, K, J, N)
        x = r["road_bins"] * r["user_share"][:, :, None]               # (S, K, J) falls meeting open road
        F = np.einsum("skj,skjn->skn", x * r["p_st"][:, None, None], a_d) \
            + np.einsum("skj,skjn->skn", x * r["p_strike"][:, None, None], a_s)
        return cs.fn_exceedance(F, Ns) <= 1.0

    # ---- societal risk -------------------------------------------------------------------------
    def fn_curve(self, option: str) -> pd.DataFrame:
        """F-N curve of an option: direct hits and strikes on fallen rocks, every block size, occupants as a
        distribution, N = 1 ... largest occupancy."""
        opt = self.option(option)
        r = self._central_result
        k = r["names"].index(opt.name)
        x = r["road_bins"][0, k] * r["user_share"][0, k]             # falls meeting open road
        freq = np.concatenate([x * r["p_st"][0], x * r["p_strike"][0]])
        vul = np.concatenate([r["v_d"][0, k], r["v_s"][0, k]])
        kk, pk = occupancy_distribution(self.exposure.occupants_per_vehicle, self.exposure.occupants_distribution)
        return occupant_fn(freq, vul, kk, pk)

    # ---- ranking ---------------------------------------------------------------------------
    def ranking(self) -> pd.DataFrame:
        """Options ranked by expected total cost (mean over the joint samples), with the central-value
        breakdown, 5-95 % of the total, probability of being cheapest, expected regret and road-user risk."""
        r = self._central_result
        u = self.uncertain
        rows = []
        for k, opt in enumerate(self.options):
            fn = self.fn_curve(opt.name)
            ret = r["retention"][0, k]
            rows.append({
                "option": opt.name, "kind": opt.kind,
                "capital": r["capital"][0, k], "pv_renewals": r["pv_renewals"][0, k],
                "pv_maintenance": r["pv_maintenance"][0, k], "pv_expected_loss": r["pv_expected_loss"][0, k],
                "cost_at_central_values": r["total"][0, k],
                "expected_total_cost": u["mean"][k], "cost_p05": u["p05"][k], "cost_p95": u["p95"][k],
                "probability_best": u["probability_best"][k], "expected_regret": u["expected_regret"][k],
                "road_falls_per_year": r["road"][0, k], "retention": None if np.isnan(ret) else float(ret),
                "effectiveness": r["effectiveness"][0, k],
                "effect_basis": self._basis(opt),
                "repairs_per_year": r["repairs"][0, k], "replacements_per_year": r["replacements"][0, k],
                "deaths_per_year": r["deaths"][0, k], "individual_risk": r["ir"][0, k],
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
        self._alarp(df)
        df = df.sort_values("expected_total_cost", kind="stable").reset_index(drop=True)
        df["rank"] = np.arange(1, len(df) + 1)
        return df

    def _basis(self, opt: Option) -> str:
        comps = [self.option(n) for n in opt.options] if opt.kind == "combined" else [opt]
        typed = [c.name for c in comps if c.typed]
        if typed:
            return "ASSUMPTION: typed effectiveness (" + ", ".join(typed) + ")"
        if opt.kind == "none":
            return "-"
        if all(c.kind == "realignment" and c.road_x_m is None for c in comps):
            return "geometry: the road leaves the slope"
        if all(c.kind == "closure" for c in comps):
            return "computed: closure rule on the rate model and rainfall record"
        if any(c.kind == "drape" for c in comps):
            return ("derived by re-simulation of the draped surface, whose material is ASSUMED "
                    "(riskrf.risk.geometry_measures.DRAPE_MATERIAL)")
        scaled = [c for c in comps if c.kind == "scaling"]
        if scaled:
            e0, _, h, mean, _ = scaled[0].scaling_effect()
            return (f"derived zone and mass range, ASSUMED effectiveness ({scaled[0].name}: {e0:.0%} when new, "
                    f"halving every {h:g} yr, {mean:.0%} on average)"
                    + ("; others derived (simulation and site geometry)" if len(comps) > 1 else ""))
        return "derived (simulation and site geometry)"

    def _design_check(self, opt: Option) -> str:
        """The verdict of an option's design checks (``design_checks``, e.g. a fence's 100-year energy against its
        MEL): "-" when it has none to pass, "not checked" for a barrier without one."""
        comps = [self.option(n) for n in opt.options] if opt.kind == "combined" else [opt]
        verdicts = [f"{c.name}: {self.design_checks[c.name]}" if opt.kind == "combined" else self.design_checks[c.name]
                    for c in comps if c.name in self.design_checks]
        if verdicts:
            return "; ".join(verdicts)
        return "not checked" if any(c.kind in ("fence", "attenuator") for c in comps) else "-"

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

    def resolution(self, ranking: pd.DataFrame | None = None) -> dict:
        """Can the joint samples tell the two cheapest options apart?

        Paired over the joint samples: the difference of their total costs, its Monte Carlo standard error
        sd / sqrt(S), and the standard error of P(best) of the cheapest, sqrt(p (1 - p) / S).  They are
        "distinguishable" when the mean difference exceeds twice its standard error and P(best) is known within
        +-0.03 (two standard errors).  The slope re-simulations (``material_draws``) add an error these samples do
        not show; more draws and samples (``[uncertainty]``) narrow both."""
        t = self.ranking() if ranking is None else ranking
        u = self.uncertain
        names = u["names"]
        a, b = t["option"].iloc[0], t["option"].iloc[1]
        d = u["total"][:, names.index(b)] - u["total"][:, names.index(a)]
        S = d.size
        se = float(d.std(ddof=1) / np.sqrt(S)) if S > 1 else np.inf
        p = float(u["probability_best"][names.index(a)])
        se_p = float(np.sqrt(p * (1 - p) / S))
        ok = bool(abs(d.mean()) > 2 * se and 2 * se_p <= 0.03)
        draws = self.uncertainty.material_draws if any(k.startswith("material:") for k in self.parameter_ranges()) \
            else 0
        text = (f"{a} and {b} {'are' if ok else 'are NOT'} distinguishable at the stated effort ({S:,} joint samples"
                + (f", {draws} slope re-simulations" if draws else "") + f"): {b} costs "
                f"{money(d.mean(), self.currency, sig=3)} more in expectation (+- {money(2 * se, sig=2)}, two "
                f"standard errors); P({a} cheapest) = {p:.2f} +- {2 * se_p:.2f}")
        if not ok:
            text += "; more samples and re-simulations, or better information, are needed to separate them"
        return {"first": a, "second": b, "difference": float(d.mean()), "difference_se": se,
                "probability_best": p, "probability_best_se": se_p, "distinguishable": ok, "text": text + "."}

    def best(self) -> str:
        """Name of the first option of :meth:`ranking` (the lowest expected total cost over the joint samples)."""
        return self.ranking()["option"].iloc[0]

    def recommendation(self, ranking: pd.DataFrame | None = None) -> dict:
        """The cheapest option meeting the tolerability criteria, else the one reducing risk most per unit cost,
        with the reasoning in plain words."""
        t = self.ranking() if ranking is None else ranking
        cur = self.currency
        lim = self.criteria.individual_risk_per_year
        ok = t[t["meets_criteria"]]
        cheapest = t.iloc[0]
        if len(ok):
            rec = ok.iloc[0]
            why = (f"{rec['option']} is the cheapest option that meets the tolerability criteria (individual risk "
                   f"{probability(rec['individual_risk'])}/yr against {probability(lim)}/yr; societal risk {rec['fn_zone']} on the "
                   f"{self.criteria.fn_diagram} F-N diagram). Its expected total cost is "
                   f"{money(rec['expected_total_cost'], cur, sig=3)} (5-95 %: {money(rec['cost_p05'], sig=3)} to "
                   f"{money(rec['cost_p95'], cur, sig=3)}); it meets them in "
                   f"{rec['probability_meets_criteria']:.0%} of the "
                   "joint samples of the uncertain inputs.")
            if rec["option"] != cheapest["option"]:
                intolerable = t[(t["expected_total_cost"] < rec["expected_total_cost"])]
                why += (f" Cheaper options leave the risk intolerable: {cheapest['option']} costs least "
                        f"({money(cheapest['expected_total_cost'], cur, sig=3)}, the cheapest in "
                        f"{cheapest['probability_best']:.0%} of the joint samples) but leaves individual risk "
                        f"{probability(cheapest['individual_risk'])}/yr and societal risk {cheapest['fn_zone']}"
                        + (f"; so do {', '.join(intolerable['option'].iloc[1:])}" if len(intolerable) > 1 else "")
                        + f". Meeting the criteria costs "
                        f"{money(rec['expected_total_cost'] - cheapest['expected_total_cost'], cur, sig=3)} more in "
                        "expectation.")
            else:
                most = t.loc[t["probability_best"].idxmax()]
                why += " It also has the lowest expected total cost of all options" + (
                    f", though it is the cheapest in only {rec['probability_best']:.0%} of the joint samples "
                    f"({most['option']}: {most['probability_best']:.0%})." if most["option"] != rec["option"]
                    else f", and is the cheapest in {rec['probability_best']:.0%} of the joint samples.")
            basis = "cheapest tolerable option"
            if "alarp" in rec and str(rec["alarp"]).startswith("not ALARP"):
                why += f" ALARP test: {rec['alarp']}."
        else:
            crit = self.criteria.describe()
            safest = t.sort_values(["individual_risk", "deaths_per_year"], kind="stable").iloc[0]
            ir_factor = safest["individual_risk"] / lim if lim > 0 else np.inf
            fn_factor = float(safest.get("fn_ratio_to_limit", 0.0))
            factor = max(ir_factor, fn_factor, 1.0)
            need = (f"NO OPTION IS TOLERABLE under {crit}. What would be needed: the safest option, "
                    f"{safest['option']}, leaves individual risk {probability(safest['individual_risk'])}/yr "
                    f"(limit {probability(lim)}/yr)"
                    + (f" and an F-N curve up to {fn_factor:.3g} times the unacceptable line" if fn_factor > 1 else "")
                    + f"; its risk would have to fall by a factor of {factor:.3g} (a further measure removing "
                    f"{1 - 1 / factor:.1%} of the falls that still reach the road, or fewer people exposed). ")
            cand = t[t["kind"] != "none"].dropna(subset=["deaths_avoided_per_million"])
            cand = cand[cand["deaths_avoided_per_million"] > 0]
            if len(cand) == 0:
                rec, basis = cheapest, "no option is tolerable; lowest expected total cost (no option reduces the risk)"
                why = need + f"No option reduces the risk; {rec['option']} costs least."
            else:
                rec = cand.sort_values("deaths_avoided_per_million", ascending=False).iloc[0]
                basis = "no option is tolerable; largest risk reduction per unit cost"
                why = need + (f"Among the options given, {rec['option']} reduces the risk most per unit cost: "
                              f"{rec['deaths_avoided_per_million']:.3g} statistical lives saved over "
                              f"{self.economics.horizon_years:g} years per million {cur} spent; residual individual "
                              f"risk {probability(rec['individual_risk'])}/yr. It is not tolerable either.")
        if "NOT ADEQUATE" in str(rec.get("design_check", "")):
            why += f" Warning: it fails its design checks ({rec['design_check']})."
        if "ASSUMED" in str(rec["effect_basis"]):
            why += f" Note: its effect is partly assumed ({rec['effect_basis']})."
        elif "ASSUMPTION" in str(rec["effect_basis"]):
            why += f" Note: its effectiveness is typed, not derived ({rec['effect_basis']})."
        res = self.resolution(t)
        why += " " + res["text"][0].upper() + res["text"][1:]
        return {"option": str(rec["option"]), "basis": basis, "reason": why, "resolution": res,
                "expected_total_cost": float(rec["expected_total_cost"]),
                "probability_best": float(rec["probability_best"])}

    # ---- sensitivity ---------------------------------------------------------------------------
    def sensitivity_parameters(self) -> list:
        """Every input that can change the order: all engine parameters with an effect."""
        return list(self.central_parameters())

    def _tornado_range(self, name, value):
        ranges = self.parameter_ranges()
        if name in ranges:
            return ranges[name][0], ranges[name][1], ranges[name][2]
        if name.startswith(("retention:", "rate_reduction:", "scaling_effectiveness:")):
            return max(value - 0.2, 0.0), min(value + 0.2, 1.0), "+-0.2 (no range stated)"
        if name == "discount_rate":
            return value * 0.5, min(value * 2, 0.2), "x0.5 / x2 (no range stated)"
        if name == "fractal_dimension":
            return max(value - 0.25, 0.05), min(value + 0.25, 2.95), "+-0.25 (no range stated)"
        return value * 0.5, value * 2.0, "x0.5 / x2 (no range stated)"

    def tornado(self) -> pd.DataFrame:
        """Lowest expected total cost (central values) as each input moves over its stated range (or x0.5/x2),
        with the best option at each end, whether the best or the whole order changes; inputs that change the
        best first, then those that change the order, each by swing.  Material parameters are re-simulated at
        both ends of their ranges."""
        c = self.central_parameters()
        base_r = self._central_result
        base = float(base_r["total"][0].min())
        names = base_r["names"]
        rows = []
        items = [(p, v) for p, v in c.items() if p != "material_draw"]
        labels = [m["label"] for m in self._models]
        for name, (lo, hi, how) in self.parameter_ranges().items():
            if name.startswith("material:"):
                path = name.split(":", 1)[1]
                items.append((name, (labels.index(f"{path} low"), labels.index(f"{path} high"), lo, hi, how)))
        for p, v in items:
            if p.startswith("material:"):
                i_lo, i_hi, lo, hi, how = v
                t = self._central({"material_draw": [i_lo, i_hi]})["total"]
            else:
                lo, hi, how = self._tornado_range(p, v)
                if lo == hi:
                    continue                     # e.g. a zero cost: nothing to vary
                t = self._central({p: [lo, hi]})["total"]
            order = list(np.argsort(base_r["total"][0], kind="stable"))
            rows.append({"parameter": p, "low": lo, "high": hi, "range": how,
                         "changes_order": any(list(np.argsort(row, kind="stable")) != order for row in t),
                         "cost_at_low": t[0].min(), "cost_at_high": t[1].min(),
                         "best_at_low": names[int(np.argmin(t[0]))], "best_at_high": names[int(np.argmin(t[1]))],
                         "base": base})
        df = pd.DataFrame(rows)
        best = names[int(np.argmin(base_r["total"][0]))]
        df["changes_best"] = (df["best_at_low"] != best) | (df["best_at_high"] != best)
        df["swing"] = (df["cost_at_high"] - df["cost_at_low"]).abs()
        return df.sort_values(["changes_best", "changes_order", "swing"], ascending=[False, False, False]
                              ).reset_index(drop=True)

    def _bracket(self, name, value):
        if name.startswith(("retention:", "rate_reduction:", "scaling_effectiveness:")):
            return 0.0, 1.0, False
        if name == "b":
            return 0.2, 3.0, False
        if name == "discount_rate":
            return 0.0, 0.3, False
        if name == "vulnerability_factor":
            return 1e-3, 1e3, True
        if name == "fractal_dimension":
            return 1e-6, 3.0 - 1e-9, False
        return max(value, 1.0) * 1e-3 if value > 0 else 0.0, max(value, 1.0) * 1e3, True

    def break_even(self, parameter: str, *, option_a: str | None = None, option_b: str | None = None):
        """Value of ``parameter`` (others central) at which options a and b (default: the two cheapest at
        central values) cost the same; None if they do not tie within the searched range."""
        r = self._central_result
        names = r["names"]
        order = np.argsort(r["total"][0], kind="stable")
        a = option_a or names[order[0]]
        b = option_b or names[order[1]]
        ia, ib = names.index(a), names.index(b)
        c = self.central_parameters()
        if parameter not in c:
            raise MitigationError(f"unknown sensitivity parameter {parameter!r}; parameters are {sorted(c)}")
        lo, hi, log = self._bracket(parameter, c[parameter])
        grid = np.geomspace(max(lo, 1e-12), hi, 161) if log else np.linspace(lo, hi, 161)
        try:
            t = self._central({parameter: grid})["total"]
        except ValueError:
            return None
        d = t[:, ia] - t[:, ib]
        cross = np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0]
        if cross.size == 0:
            return None
        # the crossing nearest the current value
        j = cross[np.argmin(np.abs(grid[cross] - c[parameter]))]
        from scipy.optimize import brentq

        def diff(x):
            tt = self._central({parameter: [x]})["total"][0]
            return tt[ia] - tt[ib]
        x = float(brentq(diff, grid[j], grid[j + 1], xtol=1e-12 * max(abs(grid[j + 1]), 1.0)))
        return x / c[parameter] if c[parameter] else np.nan, x

    def break_even_table(self) -> pd.DataFrame:
        """For every input: the value at which the second-cheapest option would tie with the cheapest, and
        whether that value lies inside the stated range."""
        r = self._central_result
        order = np.argsort(r["total"][0], kind="stable")
        a, b = r["names"][order[0]], r["names"][order[1]]
        ranges = self.parameter_ranges()
        rows = []
        for p, v in self.central_parameters().items():
            if p == "material_draw":
                continue                 # material parameters: below, from their re-simulated low and high models
            be = self.break_even(p, option_a=a, option_b=b)
            lo, hi = (ranges[p][0], ranges[p][1]) if p in ranges else (np.nan, np.nan)
            inside = bool(be is not None and p in ranges and lo <= be[1] <= hi)
            rows.append({"parameter": p, "current": v, "break_even": be[1] if be else np.nan,
                         "factor": be[0] if be else np.nan, "range_low": lo, "range_high": hi,
                         "within_stated_range": inside,
                         "note": f"{b!r} ties with {a!r}" if be else "no tie within the searched range"})
        rows += self._material_break_even(a, b, ranges)
        return pd.DataFrame(rows)

    def _material_break_even(self, a: str, b: str, ranges: dict) -> list:
        """Break-even rows of the uncertain material parameters.  Each is re-simulated only at the low and high
        ends of its range (the slope models of the tornado), so the tie of options a and b is found by linear
        interpolation of their cost difference between the low, base (reference) and high models; the tie
        nearest the current value, or none within [low, high]."""
        materials = [p for p in ranges if p.startswith("material:")]
        if not materials or self.context is None:
            return []
        from .measures import material_value
        names = self._central_result["names"]
        ia, ib = names.index(a), names.index(b)
        labels = [m["label"] for m in self._models]
        rows = []
        for p in materials:
            path = p.split(":", 1)[1]
            lo, hi, _ = ranges[p]
            current = float(material_value(self.context.scenario, path))
            draws = [labels.index(f"{path} low"), 0, labels.index(f"{path} high")]
            t = self._central({"material_draw": draws})["total"]
            x, d = np.array([lo, current, hi], dtype=float), t[:, ia] - t[:, ib]
            keep = np.argsort(x, kind="stable")
            x, d = x[keep], d[keep]
            ties = [float(x[j]) for j in range(3) if d[j] == 0]
            ties += [float(x[j] + (x[j + 1] - x[j]) * d[j] / (d[j] - d[j + 1])) for j in range(2)
                     if d[j] * d[j + 1] < 0]
            tie = min(ties, key=lambda v: abs(v - current)) if ties else None
            how = "linear interpolation of the cost difference between the re-simulated low, base and high models"
            rows.append({"parameter": p, "current": current, "break_even": np.nan if tie is None else tie,
                         "factor": np.nan if tie is None or not current else tie / current,
                         "range_low": lo, "range_high": hi, "within_stated_range": tie is not None,
                         "note": (f"{b!r} ties with {a!r} ({how})" if tie is not None
                                  else f"no tie within [{lo:g}, {hi:g}] ({how})")})
        return rows

    def value_of_information(self, factors=(0.5, 1.0, 2.0), weights=(0.25, 0.5, 0.25)) -> dict:
        """Expected value of perfect information about the rate of falls (``factors`` x the estimate with
        ``weights``), and about every sampled input at once (from the joint samples)."""
        f = np.asarray(factors, dtype=float)
        w = np.asarray(weights, dtype=float)
        if f.shape != w.shape or np.any(f <= 0) or np.any(w < 0) or abs(w.sum() - 1) > 1e-9:
            raise MitigationError(f"value_of_information: factors {f.tolist()} must be > 0 and weights {w.tolist()} "
                                  "non-negative, as many, summing to 1")
        r = self._central({"rate_factor": f})
        t = r["total"]
        names = r["names"]
        expected = w @ t
        now = int(np.argmin(expected))
        informed = float(w @ t.min(axis=1))
        return {"evpi": float(expected[now] - informed), "best_now": names[now],
                "expected_cost_now": float(expected[now]), "expected_cost_informed": informed,
                "best_by_rate": {f"x{x:g}": names[int(np.argmin(row))] for x, row in zip(f, t)},
                "factors": f.tolist(), "weights": w.tolist(),
                "evpi_all_sampled_inputs": self.uncertain["evpi"]}

    # ---- decision tree -------------------------------------------------------------------------
    def to_tree(self):
        """The decision tree of this study at central values (costs in present value), from the same engine; its
        root says so (the ranking's expected total costs are means over the joint samples and may rank otherwise).

        Under each option a chance node gives the outcome of one fall reaching the road;
        branch costs are that outcome's mean cost (over the sizes reaching the road) times
        the discounted expected number of such falls, so the rollback equals the central
        cost of the ranking.
        """
        from .decision_tree import DecisionTree
        r = self._central_result
        ec, ex, co = self.economics, self.exposure, self.consequences
        pvf = pv_factor(ec.discount_rate, ec.horizon_years)
        k_occ, p_occ = occupancy_distribution(ex.occupants_per_vehicle, ex.occupants_distribution)
        occ = float(np.dot(k_occ, p_occ))
        p_st, p_strike = float(r["p_st"][0]), float(r["p_strike"][0])
        per_fall = float(closure_cost_per_fall(co, ex.vehicles_per_day))
        branches = []
        for k, opt in enumerate(self.options):
            x = r["road_bins"][0, k]
            road = x.sum()
            n_pv = pvf * road
            vd = float(np.dot(x, r["v_d"][0, k]) / road) if road > 0 else 0.0
            vs = float(np.dot(x, r["v_s"][0, k]) / road) if road > 0 else 0.0
            u = float(r["user_share"][0, k])          # a closure: share of falls meeting open road
            outcomes = [
                {"name": "vehicle hit", "probability": p_st * u,
                 "cost": n_pv * (per_fall + co.vehicle_damage + occ * vd * co.value_of_statistical_life)},
                {"name": "vehicle strikes rock on road", "probability": p_strike * u,
                 "cost": n_pv * (per_fall + co.vehicle_damage + occ * vs * co.value_of_statistical_life)},
                {"name": "closure and clean-up only", "probability": 1 - (p_st + p_strike) * u,
                 "cost": n_pv * per_fall}]
            branches.append({"name": opt.name, "cost": float(r["capital"][0, k] + r["pv_renewals"][0, k]
                                                             + r["pv_maintenance"][0, k]),
                             "child": {"type": "chance", "name": "each fall reaching the road",
                                       "branches": outcomes}})
        return DecisionTree.from_dict({"type": "decision", "objective": "min", "branches": branches,
                                       "name": "mitigation at central values of the uncertain inputs"},
                                      source=self.source)

    def options_table(self) -> pd.DataFrame:
        """What each option is and assumes, and its effect as used."""
        r = self._central_result
        rows = []
        for k, o in enumerate(self.options):
            ret = r["retention"][0, k]
            rows.append({"option": o.name, "kind": o.kind, "what it is and assumes": o.describe(self.currency),
                         "retention": None if np.isnan(ret) else float(ret),
                         "effectiveness": float(r["effectiveness"][0, k]), "effect_basis": self._basis(o)})
        return pd.DataFrame(rows)


def _quantile_map(x, ref, var):
    """Values ``x`` moved from the law of sample ``ref`` to that of sample ``var`` (quantile mapping):
    F_var^-1(F_ref(x)), both empirical with plotting positions (i + 1/2) / n and linear between them; beyond
    ``ref``'s extremes scaled by the ratio of the extremes.  Values of ``x`` equal to a value held several times
    in ``ref`` (rolling blocks at h = 0) are spread evenly, in their order, over that value's probability range,
    so that their share is kept.  Identity when ``var`` equals ``ref``; ``2 ref`` maps x to 2 x."""
    x = np.asarray(x, dtype=float)
    r, w = np.sort(np.asarray(ref, dtype=float)), np.sort(np.asarray(var, dtype=float))
    u = np.interp(x, r, (np.arange(r.size) + 0.5) / r.size)
    first, last = np.searchsorted(r, x, side="left"), np.searchsorted(r, x, side="right")
    tied = np.flatnonzero(last - first > 1)
    if tied.size:
        order = tied[np.argsort(x[tied], kind="stable")]
        _, start, count = np.unique(x[order], return_index=True, return_counts=True)
        k = np.arange(order.size) - np.repeat(start, count)              # position among the equal values of x
        m = np.repeat(count, count)
        u[order] = (first[order] + (k + 0.5) / m * (last[order] - first[order])) / r.size
    out = np.interp(u, (np.arange(w.size) + 0.5) / w.size, w)
    hi, lo = x > r[-1], x < r[0]
    out[hi] = x[hi] * (w[-1] / r[-1] if r[-1] > 0 else 1.0)
    out[lo] = x[lo] * (w[0] / r[0] if r[0] > 0 else 1.0)
    return out


def study_inputs(data: dict, source: str) -> dict:
    """Keyword arguments of :class:`MitigationStudy` from a parsed mitigation (or site) table."""
    options, exposure, consequences, economics, used, uncertainty, criteria = parse_mitigation(data, source)
    return {"options": options, "exposure": exposure, "consequences": consequences, "economics": economics,
            "defaults_used": used, "uncertainty": uncertainty, "criteria": criteria}


def check_mitigation_file(path):
    """Read and check a mitigation TOML file (a site file works too) before any work: every table and option
    against its declaration and rules, and a closure rule's [rates] table.  Returns (study inputs, the parsed
    TOML, the checked [rates] or None when no closure rule needs it)."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"mitigation file not found: {path}")
    with open(path, "rb") as fh:
        try:
            raw = tomllib.load(fh)
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:   # a binary file: named, not a bare codec error
            raise MitigationError(f"{path}: not valid TOML: {exc}") from exc
    data = {k: v for k, v in raw.items() if k not in ("site", "inventory", "hazard", "design_block", "rates",
                                                      "design", "report")}
    inputs = study_inputs(data, str(path))         # a site file works too
    rates = None
    if any(o.kind == "closure" and o.has_closure_rule for o in inputs["options"]):
        # closure rules: share and hours from the file's [rates] model (riskrf.site_rates)
        from .site_rates import check_closure_options, check_rates
        inv = dict(raw.get("inventory", {})) if isinstance(raw.get("inventory"), dict) else {}
        rates = check_rates(raw.get("rates"), inv, path, error=MitigationError)
        check_closure_options(inputs["options"], rates, path, error=MitigationError)
    return inputs, raw, rates


def load_mitigation(path, hazard: EnergyHazard, *, road_share: float = 1.0, **kw) -> MitigationStudy:
    """Read a mitigation TOML file (a site file works too) and combine it with an energy hazard.

    Keyword arguments (``context``, ``reference``, ``small_fall_masses_kg``, ``small_falls_per_year``)
    pass to :class:`MitigationStudy`.
    """
    path = Path(path)
    inputs, raw, rates = check_mitigation_file(path)
    if rates is not None:
        from .site_rates import evaluate_rates, resolve_closures
        inv = dict(raw.get("inventory", {})) if isinstance(raw.get("inventory"), dict) else {}
        inputs["options"] = resolve_closures(inputs["options"], evaluate_rates(rates, path.parent, inv,
                                                                               inputs["options"]))
    return MitigationStudy(hazard=hazard, road_share=road_share, source=str(path), **inputs, **kw)
