"""The slope models behind the options' derived effects: the reference simulation and its material variants.

A :class:`SlopeModels` holds what the option kinds of :mod:`riskrf.risk.options` need to derive their effects: the
reference model (the hazard's own simulation) and the material-parameter variants (joint draws, and one low and
one high variant per uncertain material for the tornado), each a :class:`SlopeModel` (speeds and bounce heights at
the barrier line and the road, reach probability, P(road | barrier line)); for a mass-coupled hazard the arrivals
by block mass; the fence damage states of every (slope model, mass bin) pair; the retention of ditches,
benches and bunds by re-simulating the changed slope with common random numbers; and, for a drape, the share of
the falls reaching the road that start under the mesh (their simulated release points).  Lengths in m, speeds
in m/s, masses in kg, energies in kJ.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import pandas as pd

from ..core.units import kinetic_energy_kj
from ..core.validation import check_positive
from ..hazard.barriers import damage_state_shares, service_energy_level
from ..hazard.velocity_models import velocity_model
from .loss_engine import MassGrid
from .measures import (
    Ditch,
    MeasureError,
    effective_samples,
    material_value,
    road_crossings,
    scenario_with_ditches,
    scenario_with_materials,
)
from .options.base import MitigationError


@dataclass(frozen=True)
class SlopeModel:
    """One slope model: its ``label`` and material ``values``, (effective speeds [m/s], bounce heights [m]) at the
    barrier line (``barrier``) and at the road (``road``, or None), the probability of reaching the barrier line
    ``reach``, P(road | barrier line) ``road_share``, its scenario and simulation result (None without), and the
    ``seed`` of its simulation (None: the context's, the common random numbers of the reference and the tornado
    variants; a joint material draw has its own, so that the draws are independent ensembles).  The re-simulations
    of a model's changed slopes (ditches, fences elsewhere) use its seed."""

    label: str
    values: dict
    barrier: tuple
    reach: float
    road_share: float
    scenario: object = None
    result: object = None
    road: tuple | None = None
    seed: int | None = None


def quantile_map(x, ref, var):
    """Values ``x`` moved from the law of sample ``ref`` to that of sample ``var`` (quantile mapping):
    F_var^-1(F_ref(x)), both empirical with plotting positions (i + 1/2) / n and linear between them; beyond
    ``ref``'s extremes scaled by the ratio of the extremes.  Values of ``x`` equal to a value held several times
    in ``ref`` (rolling blocks at h = 0) are spread evenly, in their order, over that value's probability range,
    so that their share is kept.  Identity when ``var`` equals ``ref``; ``2 ref`` maps x to 2 x.

    Parameters
    ----------
    x : array_like
        Values to map (units of the samples, e.g. bounce heights [m]).
    ref : array_like
        Sample of the law ``x`` follows.
    var : array_like
        Sample of the target law.

    Returns
    -------
    numpy.ndarray
        Mapped values, shaped as ``x``, in the samples' units.
    """
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


def material_design(p: int, G: int, rng) -> np.ndarray:
    """G points in [0, 1)^p for the joint material draws, one in each of G equal strata of every coordinate (a Latin
    hypercube): with G a power of 2 and p >= 2, a scrambled Sobol' net (Owen 1997; ``scipy.stats.qmc.Sobol``), whose
    pairs of coordinates are stratified too; otherwise strata paired at random (McKay et al. 1979).

    Parameters
    ----------
    p : int
        Number of parameters.
    G : int
        Number of draws.
    rng : numpy.random.Generator
        The stream (consumed differently by the two designs).

    Returns
    -------
    numpy.ndarray
        Shape (G, p) [-].

    References
    ----------
    McKay, M.D., Beckman, R.J. & Conover, W.J. (1979) A comparison of three methods for selecting values of input
    variables in the analysis of output from a computer code. Technometrics 21:239-245.  Owen, A.B. (1997)
    Scrambled net variance for integrals of smooth functions. Annals of Statistics 25:1541-1562.
    """
    if p >= 2 and G >= 2 and G & (G - 1) == 0:
        from scipy.stats import qmc
        return qmc.Sobol(p, scramble=True, rng=rng).random(G)
    return np.column_stack([(rng.permutation(G) + rng.uniform(size=G)) / G for _ in range(p)]).reshape(G, p)


@dataclass(frozen=True, eq=False)
class SlopeModels:
    """The slope models of a study and the effects derived from them (computed on first use and kept).

    ``hazard``: the energy hazard at the barrier line; ``context``
    (:class:`~riskrf.risk.measures.SimulationContext`, or None) the scenario re-simulated for derived effects;
    ``reference`` the simulation behind the hazard; ``grid`` the engine's mass grid; ``road_share``
    P(road | barrier line) of the reference; ``coupled_road_hits`` per block of the mass-coupled run, did it reach
    the road; ``exposed_length_m`` [m] the exposed road (shed coverage); ``source`` names the study in errors.
    """

    hazard: object
    context: object
    reference: object
    uncertainty: object
    grid: MassGrid
    road_share: float
    coupled_road_hits: np.ndarray | None
    exposed_length_m: float
    source: str
    derived: dict = field(default_factory=dict)      # geometry key -> (ret0, Beta law, per model, by mass)
    _variant_classes: dict = field(default_factory=dict)
    _variant_pairs: dict = field(default_factory=dict)

    def need_context(self, opt, fld):
        """The simulation context, or a MitigationError naming the option and the field that needs it.

        Parameters
        ----------
        opt : riskrf.risk.mitigation_inputs.Option
            The option (named in error messages).
        fld : str
            The option's field that needs the scenario.

        Returns
        -------
        riskrf.risk.measures.SimulationContext
            The study's simulation context.

        Raises
        ------
        MitigationError
            When the study has no scenario.
        """
        if self.context is None:
            raise MitigationError(f"{self.source}: option {opt.name!r}: {fld} needs the slope scenario to derive its "
                                  "effect (run with a scenario, or type an effectiveness as an assumption)")
        return self.context

    # ---- the models ----------------------------------------------------------------------------------------
    @cached_property
    def models(self) -> list:
        """[0] the reference (the hazard's own simulation), then the joint material draws, then one low and one
        high variant per uncertain material parameter (tornado).

        Returns
        -------
        list of SlopeModel
            The slope models, the reference first.
        """
        models = [self._reference_model()]
        u = self.uncertainty
        ranges = self.material_ranges()
        if ranges and self.context is not None:
            ctx = self.context
            rng = np.random.default_rng(np.random.SeedSequence([u.seed, 13]))
            names = sorted(ranges)
            if u.calibration is not None:
                rows = u.calibration
                pick = rng.choice(len(rows), size=u.material_draws, replace=len(rows) < u.material_draws)
                draws = [{n: float(rows.iloc[i][f"materials.{n}"]) for n in names} for i in pick]
            else:
                # a Latin hypercube over the stated ranges (each range cut into G strata, one draw in each): the
                # mean over the draws varies less than with independent draws (demo: the sd of doing nothing's
                # expected cost over sampling seeds 22 % -> 9 %); its standard error takes the main effects out
                # (riskrf.risk.error_budget.clustered_se with a design).  With G a power of 2 and several
                # parameters, the hypercube is a scrambled Sobol' net (Owen 1997), whose pairs of parameters are
                # stratified too: the demo's expected cost of doing nothing grows some hundredfold towards high
                # talus restitution AND low friction together, a corner a random pairing of strata samples
                # unevenly (16 draws: sd over sampling seeds 8.7 % as a random hypercube, 5.4 % as a net)
                cols = {n: ranges[n][0] + u01 * (ranges[n][1] - ranges[n][0])
                        for n, u01 in zip(names, material_design(len(names), u.material_draws, rng).T)}
                draws = [{n: float(cols[n][i]) for n in names} for i in range(u.material_draws)]
            central = {n: material_value(ctx.scenario, n) for n in names}
            variants = [(vals, "draw") for vals in draws] + \
                [({**central, n: v}, f"{n} {end}") for n in names for end, v in (("low", ranges[n][0]),
                                                                                 ("high", ranges[n][1]))]
            scenarios = [scenario_with_materials(ctx.scenario, vals, where=f"{self.source}: uncertainty.materials")
                         for vals, _ in variants]
            # each joint draw an independent ensemble (its own seed): the samples' clusters then carry the
            # trajectory noise too (riskrf.risk.error_budget); the tornado's low/high variants keep the context's
            draw_seeds = [int(x) for x in np.random.SeedSequence([int(ctx.seed), int(u.seed), 17]).generate_state(
                len(draws))]
            seeds = draw_seeds + [None] * (len(variants) - len(draws))
            # the joint draws with [uncertainty] draw_blocks each (their spread is mostly between draws, so more
            # draws of fewer blocks buy more precision for the same blocks); the tornado's variants keep the
            # context's blocks and seed (common random numbers with the reference)
            blocks = [u.draw_blocks] * len(draws) + [None] * (len(variants) - len(draws))
            runs = ctx.run_many(scenarios, seeds, blocks)
            for (vals, label), sc, res, seed in zip(variants, scenarios, runs, seeds):
                models.append(self._simulated_model(vals, label, sc, res, seed))
        return models

    def draw_design(self):
        """The joint material draws' coordinates, one row per draw (models 1 ... G), each parameter scaled to
        [0, 1] of its range: the design of the Latin hypercube (None for the rows of a calibration bootstrap,
        which are not stratified, or without material uncertainty).

        Returns
        -------
        numpy.ndarray or None
            Shape (G, p) [-].
        """
        u = self.uncertainty
        ranges = self.material_ranges()
        if not ranges or u.calibration is not None or self.context is None:
            return None
        names = sorted(ranges)
        draws = [m for m in self.models[1:] if m.label == "draw"]
        lo = np.array([ranges[n][0] for n in names])
        span = np.array([ranges[n][1] - ranges[n][0] for n in names])
        span[span == 0] = 1.0
        return (np.array([[m.values[n] for n in names] for m in draws]) - lo) / span

    def material_ranges(self) -> dict:
        """"material.field" -> (low, high, how) of the uncertain slope material parameters.

        Returns
        -------
        dict
            ``"material.field"`` -> (low, high, how): bounds in the field's units (restitution [-], angles [deg],
            roughness [m]) and how they were obtained.
        """
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

    def _reference_model(self) -> SlopeModel:
        v = velocity_model(self.hazard.velocity).speed_samples_ms()
        h = self.hazard.heights_m
        ctx = self.context
        road = None
        if self.reference is not None and ctx is not None and \
                ctx.road_collector in [c.name for c in self.reference.scenario.collectors]:
            road = effective_samples(self.reference, ctx.road_collector)
        return SlopeModel("reference", {}, (v, None if h is None else np.asarray(h, dtype=float)),
                          float(self.hazard.reach_probability), float(self.road_share),
                          None if ctx is None else ctx.scenario, self.reference, road)

    def _simulated_model(self, values: dict, label: str, sc, res, seed=None) -> SlopeModel:
        ctx = self.context
        v, h = effective_samples(res, ctx.barrier_collector)
        reach = max(v.size, 1) / res.n
        road = effective_samples(res, ctx.road_collector)
        share = min(road[0].size / v.size, 1.0) if v.size else 1.0
        return SlopeModel(label, values, (v, h), reach, share, sc, res, road, seed)

    @cached_property
    def arrays(self):
        """Reach probability at the barrier line and P(road | barrier) per slope model.

        Returns
        -------
        reach : numpy.ndarray
            Probability of reaching the barrier line per slope model [-].
        road_share : numpy.ndarray
            P(road | barrier line) per slope model [-].
        """
        ms = self.models
        reach = np.array([m.reach for m in ms])
        if self.by_mass is not None and len(ms) > 1:
            # mass-coupled: a variant's reach relative to the unmodified slope simulated alike (seeder masses),
            # times the hazard's mass-averaged reach (see by_mass)
            res = self.reference_run
            base = effective_samples(res, self.context.barrier_collector)[0].size / res.n
            reach[1:] = reach[1:] * reach[0] / base if base > 0 else reach[1:]
        return reach, np.array([m.road_share for m in ms])

    def table(self) -> pd.DataFrame:
        """The slope models: material values, reach probability and road share of each.

        Returns
        -------
        pandas.DataFrame
            One row per slope model: ``model``, ``label``, material values, ``reach_probability`` [-] and ``road_share``
            [-].
        """
        return pd.DataFrame([{"model": i, "label": m.label, **m.values, "reach_probability": m.reach,
                              "road_share": m.road_share} for i, m in enumerate(self.models)])

    # ---- block size ----------------------------------------------------------------------------------------
    @cached_property
    def radius_m(self) -> np.ndarray:
        """Radius [m] of a block of each mass bin's representative mass: the scenario's block shape and density
        (its seeder) when there is a slope model, else a sphere of 2,650 kg/m3.  A block passes over a fence when
        its underside (centre height - radius) clears the fence top, as in the simulator's barrier.

        Returns
        -------
        numpy.ndarray
            Radius per mass bin (J,) [m].
        """
        mid = self.grid.mid
        seeder = getattr(getattr(self.context, "scenario", None), "seeder", None)
        if seeder is not None:
            return np.asarray(seeder.radius(mid), dtype=float)
        from ..core.units import DEFAULT_DENSITY_KG_M3
        return (3.0 * mid / (4.0 * np.pi * DEFAULT_DENSITY_KG_M3)) ** (1.0 / 3.0)

    @cached_property
    def by_mass(self):
        """For a mass-coupled hazard: per mass bin, its simulated mass class's arriving blocks (effective speeds
        [m/s], bounce heights [m], paired) and P(reach | class) over the hazard's mean reach probability; else None.

        The reference slope model's fence impacts and arrivals then follow block mass (heavier blocks arrive more
        often and faster).  A material variant keeps this mass dependence, changed as its pooled samples changed
        from those of the unmodified slope simulated alike (:attr:`reference_run`: same blocks, seed and seeder
        masses; the hazard's own samples are another mass mixture): speeds by the ratio of the medians, bounce
        heights by quantile mapping (:func:`quantile_map`; a ratio of medians is 0 or unbounded when most blocks
        roll, h = 0), reach by the ratio of the mean reach probabilities (:attr:`arrays`).

        Returns
        -------
        tuple or None
            ``(class_of_bin, samples, profile)``: the mass class of each bin, class -> (speeds [m/s], bounce heights
            [m]) of its arriving blocks, and per bin P(reach | class) over the mean reach [-]; None when the hazard is
            not mass-coupled.
        """
        hz = self.hazard
        if not hz.mass_coupled:
            return None
        vel = hz.velocity
        mid = self.grid.mid
        cls = vel.class_of(mid)
        k = vel.class_of(vel.mass_kg)
        arrived = vel.reached
        samples = {c: (vel.speed_ms[arrived & (k == c)], vel.height_m[arrived & (k == c)]) for c in np.unique(cls)}
        profile = vel.reach_by_class[cls] / max(float(hz.reach_probability), 1e-300)
        return cls, samples, profile

    @cached_property
    def road_profile(self) -> np.ndarray:
        """Per mass bin: P(road | barrier line) of the bin's mass stratum over the study's ``road_share`` (ones
        without a mass-coupled hazard or its road crossings).

        One road share for all block sizes over-counts small falls at the road and under-counts large ones (large
        blocks run further), so each mass stratum has its own share: the blocks of the stratum that crossed the
        barrier line and then the road line, over those that crossed the barrier line.  The strata are the mass
        classes of the hazard's mass-coupled run, continued below its lightest mass by strata of the same width in
        ln m down to the lightest bin (falls below the power law's m_min).  Each stratum pools the blocks of both
        runs of that slope whose masses fall in it (:meth:`road_counts`): the mass-coupled run (spread evenly over
        ln m) and the reference run (the seeder's masses, which crowd the light strata where most falls are).  On
        the demo the lightest stratum holds 70 % of the falls and about 35 road crossings of the mass-coupled run
        alone (a share known to +-17 %, the largest source of the spread of doing nothing's expected cost between
        simulation seeds); pooled, about 130, and the falls below m_min get the share of the reference run's own
        light blocks (about 330 crossings) instead of the lightest class's.  A stratum within the simulated masses
        with fewer than 20 blocks at the barrier line keeps the overall share; below them, strata are collapsed into
        groups of at least 20 / ``road_share`` blocks at the barrier line (20 road crossings expected), and
        without that many the lightest class's share is used (the extrapolation the mass-coupled hazard states).

        References
        ----------
        Cochran, W.G. (1977) Sampling Techniques, 3rd ed. Wiley, sec. 5.12 (post-stratification) and 5A.12
        (collapsed strata).

        Returns
        -------
        numpy.ndarray
            Relative road share per mass bin (J,) [-].

        Raises
        ------
        MitigationError
            When ``coupled_road_hits`` does not match the hazard's mass-coupled run.
        """
        counts = self.road_counts()
        ones = np.ones(self.grid.mid.size)
        if counts is None:
            return ones
        stratum_of_bin, in_range, arrivals, hits = counts
        share = np.ones(arrivals.size)
        enough = in_range & (arrivals >= 20)
        share[enough] = hits[enough] / arrivals[enough] / self.road_share
        # below the simulated masses: strata collapsed (Cochran 1977, 5A.12), from the heaviest down, into groups
        # of at least 20 / road_share blocks at the barrier line (20 road crossings expected at the overall share);
        # a last group short of that joins the heavier one, and with none the lightest class's share is used
        light = np.flatnonzero(~in_range)[::-1]
        need = 20.0 / self.road_share
        groups, group = [], []
        for s in light:
            group.append(s)
            if arrivals[group].sum() >= need:
                groups.append(group)
                group = []
        if group:
            if groups:
                groups[-1] += group
            else:
                share[group] = share[in_range][0] if in_range.any() else 1.0
        for g in groups:
            share[g] = hits[g].sum() / arrivals[g].sum() / self.road_share
        return share[stratum_of_bin]

    def road_counts(self):
        """The mass strata of :attr:`road_profile` and their counts pooled over the mass-coupled and reference runs.

        Returns
        -------
        tuple or None
            ``(stratum_of_bin, in_range, arrivals, road)``: the stratum of each mass bin of the grid (J,), whether
            each stratum lies within the mass-coupled run's masses, and per stratum the blocks at the barrier line
            and those of them that then crossed the road line; None without a mass-coupled hazard, its road
            crossings or a positive ``road_share``.

        Raises
        ------
        MitigationError
            When ``coupled_road_hits`` does not match the hazard's mass-coupled run.
        """
        hits = self.coupled_road_hits
        if self.by_mass is None or hits is None or self.road_share <= 0:
            return None
        vel = self.hazard.velocity
        hits = np.asarray(hits, dtype=bool)
        if hits.size != np.size(vel.mass_kg):
            raise MitigationError(f"{self.source}: coupled_road_hits has {hits.size} blocks; the hazard's mass-coupled "
                                  f"run has {np.size(vel.mass_kg)}")
        edges = np.log(np.asarray(vel.edges_kg, dtype=float))
        width = edges[1] - edges[0]
        below = max(int(np.ceil((edges[0] - np.log(self.grid.edges[0])) / width - 1e-9)), 0)
        n_strata = below + edges.size - 1

        def stratum(mass_kg, clip: bool):
            """Stratum of each mass: those below the simulated masses first, then its classes; outside all of
            them the nearest (``clip``, for the grid's bins) or -1 (a block left out)."""
            m = np.log(np.asarray(mass_kg, dtype=float))
            out = below + np.searchsorted(edges, m, side="right") - 1
            light = m < edges[0]
            out[light] = below - 1 - np.floor((edges[0] - m[light]) / width).astype(int)
            outside = (out < 0) | (out >= n_strata)
            out[outside] = np.clip(out[outside], 0, n_strata - 1) if clip else -1
            out[m == edges[-1]] = n_strata - 1              # the heaviest simulated mass is in the last class
            return out

        at_b = np.asarray(vel.reached, dtype=bool)
        runs = [(np.asarray(vel.mass_kg, dtype=float), at_b, hits & at_b)]
        ref, ctx = self.reference, self.context
        if ref is not None and ctx is not None and "mass" in getattr(ref, "blocks", {}) and \
                ctx.road_collector in [c.name for c in ref.scenario.collectors] and \
                ctx.road_collector != ctx.barrier_collector:
            at = np.zeros(ref.n, dtype=bool)
            at[ref.collector(ctx.barrier_collector, first_only=True)["block"].to_numpy()] = True
            on_road = np.zeros(ref.n, dtype=bool)
            on_road[road_crossings(ref, ctx.road_collector)] = True
            runs.append((np.asarray(ref.blocks["mass"], dtype=float), at, on_road & at))
        arrivals, road = np.zeros(n_strata), np.zeros(n_strata)
        for masses, at, crossed in runs:
            k = stratum(masses, clip=False)
            arrivals += np.bincount(k[at & (k >= 0)], minlength=n_strata)
            road += np.bincount(k[crossed & (k >= 0)], minlength=n_strata)
        in_range = np.arange(n_strata) >= below
        return stratum(self.grid.mid, clip=True), in_range, arrivals, road

    # ---- barriers ------------------------------------------------------------------------------------------
    def barrier_damage(self, opt, *, shed: bool) -> tuple:
        """(passing, held above SEL, destroying) shares, each (models, J), of the falls meeting the fence or
        attenuator ``opt`` (at the barrier line or its own ``x_m``) or, ``shed``, the shed over the road, with
        the damage states of :func:`riskrf.hazard.barriers.damage_state_shares` and E = 1/2 m v^2 [kJ].

        Parameters
        ----------
        opt : riskrf.risk.mitigation_inputs.Option
            The option (named in error messages). Its ``capacity_kj`` [kJ], ``height_m`` [m] and ``x_m`` [m] are used.
        shed : bool
            A shed over the road (falls at the road line, none pass over) instead of a fence or attenuator.

        Returns
        -------
        passing, held, destroying : numpy.ndarray
            Shares of the falls [-], each (slope models, J).

        Raises
        ------
        MitigationError
            When bounce heights paired with speeds are missing.
        """
        mid = self.grid.mid
        cap = opt.capacity_kj
        fence_lines = self.fence_samples_at(opt) if opt.x_m is not None and not shed else None
        out = []
        for m in self.models:
            if shed:
                v, h = m.road if m.road is not None else m.barrier
                over = np.zeros(v.size, dtype=bool)
            else:
                v, h = fence_lines[len(out)] if opt.x_m is not None else m.barrier
                if h is None or len(h) != len(v):
                    raise MitigationError(f"{self.source}: option {opt.name!r}: fences and attenuators need simulated "
                                          "velocities paired with bounce heights (a scenario, or a velocity file with "
                                          "height_m)")
                if opt.x_m is None and self.by_mass is not None:
                    out.append(self._damage_by_mass(m, v, h, opt.height_m, cap))
                    continue
                over = np.asarray(h)[:, None] - self.radius_m[None, :] > opt.height_m
            # energies of every (block, mass bin) pair [kJ]: E = 1/2 m v^2; damage states from riskrf.hazard.barriers
            out.append(damage_state_shares(kinetic_energy_kj(mid[None, :], v[:, None]), over, cap))
        return tuple(np.array([o[i] for o in out]) for i in range(3))

    def _class_samples(self, model: SlopeModel, v, h) -> dict:
        """Per mass class (speeds [m/s], bounce heights [m]) at the barrier line as ``model`` changes them (see
        :attr:`by_mass`); computed once per model, shared by every barrier option."""
        cached = self._variant_classes.get(id(model))
        if cached is not None:
            return cached
        samples = self.by_mass[1]
        if model is not self.models[0]:                     # the reference slope model keeps its own samples
            ref_v, ref_h = self.reference_barrier
            sv = float(np.median(v) / np.median(ref_v)) if len(v) and len(ref_v) else 1.0
            mapped = len(h) and len(ref_h)
            samples = {c: (sv * vc, quantile_map(hc, ref_h, h) if mapped else hc) for c, (vc, hc) in samples.items()}
        self._variant_classes[id(model)] = samples
        return samples

    def _damage_by_mass(self, model: SlopeModel, v, h, height_m: float, cap: float):
        """damage_state_shares per mass bin with the speeds and heights of the bin's own mass class (see by_mass).

        Every class at once: each (block of the class, bin of the class) pair is one element, with the same
        energy E = 1/2 m v^2 [kJ] and the same comparisons as damage_state_shares makes per class; the states
        are counted per bin and divided by the class's number of blocks, which is the mean of the 0/1 flags
        that function takes (sums of ones are exact), so the shares are the same floats."""
        bins, n_bin, e, clearance = self._class_pairs(model, v, h)
        mel = check_positive(cap, "mel_kj")
        sel = service_energy_level(mel)
        over = clearance > height_m
        working = ~over
        through = working & (e > mel)
        held_repair = working & (e > sel) & (e <= mel)
        size, has = self.grid.mid.size, n_bin > 0
        out = []
        for flag in (over | through, held_repair, through):
            count = np.bincount(bins, weights=flag, minlength=size)
            out.append(np.divide(count, n_bin, out=np.zeros(size), where=has))
        return tuple(out)

    def _class_pairs(self, model: SlopeModel, v, h) -> tuple:
        """The (block, bin) pairs of :meth:`_damage_by_mass` for ``model``: per pair its mass bin; per bin the
        number of blocks of its class (0: none, or a bin of a class without samples); per pair the energy
        E = 1/2 m v^2 [kJ] of the bin's mass at the block's speed and the height [m] of the block's underside
        (centre height less the bin's radius).  Once per model (every barrier option shares them)."""
        cached = self._variant_pairs.get(id(model))
        if cached is not None:
            return cached
        cls = self.by_mass[0]
        n_bin = np.zeros(self.grid.mid.size)
        rows, bins, speeds, heights, start = [], [], [], [], 0
        for c, (vc, hc) in self._class_samples(model, v, h).items():
            j = np.flatnonzero(cls == c)
            vc, hc = np.asarray(vc, dtype=float), np.asarray(hc, dtype=float)
            n = vc.size
            rows.append(np.repeat(np.arange(start, start + n), j.size))
            bins.append(np.tile(j, n))
            n_bin[j] = n
            speeds.append(vc)
            heights.append(hc)
            start += n
        cat = (lambda parts, dtype: np.concatenate(parts) if parts else np.zeros(0, dtype=dtype))
        rows, bins, vc, hc = cat(rows, np.intp), cat(bins, np.intp), cat(speeds, float), cat(heights, float)
        pairs = (bins, n_bin, kinetic_energy_kj(self.grid.mid[bins], vc[rows]), hc[rows] - self.radius_m[bins])
        self._variant_pairs[id(model)] = pairs
        return pairs

    def fence_samples_at(self, opt) -> list:
        """Per slope model: (effective speeds [m/s], bounce heights [m]) at the option's own line x_m.

        Parameters
        ----------
        opt : riskrf.risk.mitigation_inputs.Option
            The option (named in error messages). Its ``x_m`` [m] is the line.

        Returns
        -------
        list of tuple
            Per slope model, (effective speeds [m/s], bounce heights [m]).

        Raises
        ------
        MitigationError
            When the study has no scenario or ``x_m`` lies outside the profile.
        """
        import simulation.scenario as sc_mod
        ctx = self.need_context(opt, "x_m")
        prof = ctx.scenario.profile
        if not prof.x[0] < opt.x_m < prof.x[-1]:
            raise MitigationError(f"{self.source}: option {opt.name!r}: x_m = {opt.x_m:g} m is outside the profile "
                                  f"({prof.x[0]:g}, {prof.x[-1]:g}) m")
        col = sc_mod.Collector(f"{opt.name} line", float(opt.x_m))
        runs = ctx.run_many((replace(m.scenario, collectors=m.scenario.collectors + (col,)) for m in self.models),
                            [m.seed for m in self.models], self._model_blocks())
        return [effective_samples(res, col.name) for res in runs]

    # ---- the reference run (common random numbers) ---------------------------------------------------------
    @cached_property
    def reference_run(self):
        """The unmodified scenario with the re-simulation blocks and seed (the common random numbers).

        Returns
        -------
        simulation.SimulationResult
            The reference re-simulation.
        """
        return self.context.run(self.context.scenario)

    @cached_property
    def reference_barrier(self):
        """(effective speeds [m/s], bounce heights [m]) at the barrier line of :attr:`reference_run`.

        Returns
        -------
        speed : numpy.ndarray
            Effective speeds [m/s].
        height : numpy.ndarray
            Bounce heights [m].
        """
        return effective_samples(self.reference_run, self.context.barrier_collector)

    @cached_property
    def reference_road_blocks(self):
        """Blocks of :attr:`reference_run` crossing the road line.

        Returns
        -------
        numpy.ndarray of int
            Sorted block indices.
        """
        return road_crossings(self.reference_run, self.context.road_collector)

    # ---- ditches, benches, bunds, drapes -------------------------------------------------------------------
    def geometry_retention(self, key: str, measures) -> tuple:
        """(overall retention of the reference model, its Beta law, overall retention per slope model, retention
        by mass bin per slope model) of the slope changes ``measures`` simulated together; kept under ``key``.

        Parameters
        ----------
        key : str
            Name under which the result is kept (the options' names joined by ``+``).
        measures : list
            The slope changes (:class:`riskrf.risk.measures.Ditch` or
            :class:`riskrf.risk.geometry_measures.SlopeMeasure`).

        Returns
        -------
        tuple
            (retention of the reference model [-], its Beta law, retention per slope model [-], retention by mass bin
            per slope model [-]).
        """
        if key not in self.derived:
            per_model = self._ditch_retentions(measures)
            self.derived[key] = (per_model[0][0], per_model[0][1], np.array([r for r, _, _ in per_model]),
                                 np.array([b for _, _, b in per_model]))
        return self.derived[key]

    def drape_share(self, key: str, scenario_check, zone_x_m, max_mass_kg=None) -> tuple:
        """(share of the road falls released under a drape in the reference model, its Beta law, that share per
        slope model, by mass bin per slope model) of the draped zone ``zone_x_m``; kept under ``key``.  Derived from
        the release points of the simulated blocks that reach the road (no re-simulation: a drape does not change
        where the blocks it does not hold go).

        Parameters
        ----------
        key : str
            Name under which the result is kept (its effect parameter is ``retention:<key>``).
        scenario_check : callable
            ``scenario_check(scenario)`` raises a MitigationError when the zone does not fit that slope model's
            scenario (:func:`riskrf.risk.geometry_measures.check_drape_zone`).
        zone_x_m : tuple of float
            (x_lo, x_hi) of the draped zone [m].
        max_mass_kg : float, optional
            Largest block the mesh contains [kg]; None: every block.

        Returns
        -------
        tuple
            (share of the reference model [-], its Beta law (a, b), share per slope model [-], share by mass bin per
            slope model [-]).
        """
        from .geometry_measures import drape_release_share
        if key not in self.derived:
            ctx = self.context
            scenario_check(ctx.scenario)
            mid = self.grid.mid
            cap = np.ones(mid.size) if max_mass_kg is None else (mid <= max_mass_kg).astype(float)
            rows = []
            for i, m in enumerate(self.models):
                res = self.reference_run if i == 0 else m.result
                road = self.reference_road_blocks if i == 0 else road_crossings(res, ctx.road_collector)
                share, beta, under = drape_release_share(res, road, zone_x_m, max_mass_kg)
                mass = np.asarray(res.blocks["mass"], dtype=float)[road]
                in_zone = drape_release_share(res, road, zone_x_m)[2]
                if road.size:
                    edges = np.quantile(mass, np.linspace(0, 1, 6))
                    centres, shares = [], []
                    for lo, hi in zip(edges[:-1], edges[1:]):
                        sel = (mass >= lo) & (mass <= hi)
                        if sel.any():
                            centres.append(float(np.median(mass[sel])))
                            shares.append(float(in_zone[sel].mean()))
                    by_mass = np.interp(np.log(mid), np.log(centres), shares) * cap
                else:
                    by_mass = np.zeros(mid.size)
                rows.append((share, beta, by_mass))
            self.derived[key] = (rows[0][0], rows[0][1], np.array([r[0] for r in rows]),
                                 np.array([r[2] for r in rows]))
        return self.derived[key]

    def _ditch_retentions(self, ditches) -> list:
        """:meth:`_ditch_retention` for every slope model (the changed profiles simulated at once): ditches
        (:class:`~riskrf.risk.measures.Ditch`) and benches, bunds and drapes
        (:class:`~riskrf.risk.geometry_measures.SlopeMeasure`)."""
        from .geometry_measures import scenario_with_measures
        ctx = self.context
        try:
            if all(isinstance(d, Ditch) for d in ditches):
                scenarios = [scenario_with_ditches(m.scenario, ditches, where=self.source,
                                                   road_collector=ctx.road_collector) for m in self.models]
            else:
                scenarios = [scenario_with_measures(m.scenario, ditches, where=self.source,
                                                    road_collector=ctx.road_collector) for m in self.models]
        except (MeasureError, ValueError) as exc:
            raise MitigationError(str(exc)) from exc
        return [self._ditch_retention(m, i, res) for i, (m, res) in
                enumerate(zip(self.models, ctx.run_many(scenarios, [m.seed for m in self.models],
                                                        self._model_blocks())))]

    def _model_blocks(self) -> list:
        """Blocks of each slope model's own run (None: the context's), for re-simulating its changed slopes with
        the same blocks and seed (common random numbers); the reference's base is :attr:`reference_run`."""
        return [None] + [None if m.result is None else int(m.result.n) for m in self.models[1:]]

    def _ditch_retention(self, model: SlopeModel, index: int, ditched):
        """Share of the falls that would reach the road that the ditches stop (common random numbers): overall,
        its Monte Carlo Beta law, and by block mass (5 strata of the simulated masses, interpolated in log mass
        onto the mass grid and held constant beyond the simulated range)."""
        ctx = self.context
        base_res = self.reference_run if index == 0 else model.result
        base = self.reference_road_blocks if index == 0 else road_crossings(base_res, ctx.road_collector)
        kept = road_crossings(ditched, ctx.road_collector)
        mid = self.grid.mid
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
