"""Mitigation options as transformations of the site: one small class per option kind.

Each option of a study (a :class:`riskrf.risk.mitigation_inputs.Option` read from the ``[[options]]`` tables) is
wrapped by the class of its kind (:func:`effect_of`), which says what it does to the falls and what it costs
(CLIMADA's measures: a measure changes the hazard, the exposure or the vulnerability; one engine,
:mod:`riskrf.risk.loss_engine`, computes the losses):

* ``none`` (:class:`DoNothing`): the site as it is;
* ``scaling`` (:class:`Scaling`, scaling and bolting): removes the release of blocks between ``min_mass_kg`` and
  ``max_mass_kg`` from the source zone ``zone_x_m`` (the share of the release line it covers follows from the
  scenario's seeder), with an ASSUMED effectiveness decaying over its life;
* ``ditch`` (:class:`CatchDitch`): a catchment dug into the profile (``x_m``, ``width_m``, ``depth_m``); its
  retention is derived by re-simulating the scenario with the new profile; ``bench``, ``bund``, ``drape``
  (:class:`Bench`, :class:`Bund`, :class:`Drape`) change the slope likewise
  (:mod:`riskrf.risk.geometry_measures`);
* ``fence`` / ``attenuator`` (:class:`Barrier`): a barrier line (``capacity_kj`` = MEL, ``height_m``) at the
  barrier collector or at its own ``x_m``; falls pass over (the block's underside, simulated centre height minus
  the radius of a block of that mass, above the fence: the simulator's own barrier rule,
  ``simulation.kernel.barrier_outcome``) or through (energy above MEL, block by block);
* ``shed`` (:class:`Shed`): covers ``covered_length_m`` of the exposed road with a capacity ``capacity_kj``;
* ``realignment`` (:class:`Realignment`): moves the road to ``road_x_m`` on the profile (share of falls still
  reaching it from the simulated run-out), or away from the slope altogether;
* ``closure`` (:class:`Closure`): closes the road while a rainfall or warning rule holds; falls still reach the
  road but meet no road user;
* ``combined`` (:class:`Combined`): several of the above in series, each acting on the falls the previous ones let
  through, costs added: no double counting.

A typed ``retention`` (ditch, slope measures, barriers) or ``rate_reduction`` (scaling) replaces the derived effect;
it is then an assumption and says so in every output.

The protocol of a kind: :meth:`OptionEffect.parameters` (its costs and effect parameters, named as in the tornado),
:meth:`OptionEffect.stages` (its typed stages for the engine, derived from the slope models of
:class:`riskrf.risk.slope_models.SlopeModels`), :meth:`OptionEffect.describe` and the effect basis
(derived / ASSUMED / typed) of :func:`effect_basis`.
"""
from __future__ import annotations

import numpy as np

from ..core.format import money
from ..core.validation import RiskrfError
from .geometry_measures import SlopeMeasure
from .loss_engine import (
    BarrierStage,
    ClosureStage,
    ContainmentStage,
    ExposureStage,
    OptionChain,
    ReleaseStage,
    RetentionStage,
)
from .measures import Ditch, MeasureError, runout_beyond, seeder_share

OPTION_KINDS = ("none", "scaling", "ditch", "fence", "attenuator", "shed", "realignment", "closure", "combined",
                "bench", "bund", "drape")
#: Options that change the slope or hang on it (bench and bund re-simulated like a ditch; a drape: the falls
#: released under it, see :class:`Drape`).
SLOPE_KINDS = ("bench", "bund", "drape")
BARRIER_KINDS = ("fence", "attenuator", "shed")
#: Days a destroyed structure stays out of service (ASSUMPTION; override with ``repair_days``).
DEFAULT_REPAIR_DAYS = {"fence": 30.0, "attenuator": 30.0, "shed": 180.0}
#: Scaling and bolting by zone and mass: share of the targeted releases removed when the work is new, its range,
#: and the cycle over which the effect is averaged without a life_years.  ASSUMPTIONS (no published effectiveness
#: of scaling was found): labelled "assumed" in every output; override with effectiveness, effectiveness_range and
#: effectiveness_half_life_years.
SCALING_EFFECTIVENESS = 0.8
SCALING_EFFECTIVENESS_RANGE = (0.6, 0.95)
SCALING_DEFAULT_CYCLE_YEARS = 10.0
#: Drape: share of the blocks released under the mesh that it keeps on the face, and its range.  ASSUMPTIONS (no
#: published containment efficiency was found; blocks bulge or tear the mesh, or leave at its open bottom):
#: labelled "ASSUMED" in every output; override with containment and containment_range.
DRAPE_CONTAINMENT = 0.85
DRAPE_CONTAINMENT_RANGE = (0.7, 0.95)
#: Drape: the largest block it contains without a stated max_mass_kg, as a sphere diameter [m] (ASSUMED: the upper
#: end of the 0.6-1.0 m blocks typical of simple drapery, Giacchetti & Grimod, Maccaferri).
DRAPE_MAX_BLOCK_DIAMETER_M = 1.0

# the order in which the elements of an option act on the falls, in series
RELEASE, TYPED_RETENTION, GEOMETRY, BARRIER, SHED, CLOSURE, EXPOSURE = range(7)


class MitigationError(RiskrfError, ValueError):
    """A mitigation file or option is invalid; the message names the option and field."""


def _typed_retention(o, what: str) -> str:
    return f"{what}; ASSUMED to retain {o.retention:.0%} of falls (typed)"


class OptionEffect:
    """The behaviour of one option kind; wraps the option record ``option``.

    ``order``: where its stages act in the series of a combined option (releases, typed retentions, the
    re-simulated slope geometry, barriers, sheds, closures, realignments).
    """

    order = EXPOSURE
    needs_design_check = False
    #: Fields of an ``[[options]]`` table that only this kind takes (any other kind naming one is an error).
    own_fields = ()
    #: Fields a table of this kind must give, each > 0 (a structure's capacity [kJ] and height [m]).
    required_fields = ()
    #: Geometry fields a table of this kind must give when it has no typed ``retention`` (positions, sizes [m]).
    geometry_fields = ()
    #: Does a table of this kind need ``capital_cost`` (a combined option takes its components' costs)?
    needs_capital_cost = True

    def __init__(self, option):
        self.option = option

    # ---- reading an ``[[options]]`` table (riskrf.risk.mitigation_inputs.parse_option) ------------------------
    @classmethod
    def read_spec(cls, kind: str, spec: dict, vals: dict, at: str) -> None:
        """Check and read the fields of this kind's own rule (before the shared checks of shares and ranges).

        Parameters
        ----------
        kind : str
            The table's ``kind`` (one of :data:`OPTION_KINDS`).
        spec : dict
            The ``[[options]]`` table as read (costs in the study's currency, lengths [m], rainfall [mm]).
        vals : dict
            The values to build the option from; updated in place.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError naming ``at``, the field and its value; nothing to read by default.
        """
        return None

    @classmethod
    def check_effect_spec(cls, kind: str, spec: dict, at: str) -> None:
        """Check that a table of this kind says what the option does, beyond :attr:`required_fields` and
        :attr:`geometry_fields` (e.g. the blocks scaling removes).

        Parameters
        ----------
        kind : str
            The table's ``kind`` (one of :data:`OPTION_KINDS`).
        spec : dict
            The ``[[options]]`` table as read.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError naming ``at`` and the missing fields; nothing more is needed by default.
        """
        return None

    @classmethod
    def finish_spec(cls, kind: str, spec: dict, vals: dict, at: str) -> None:
        """Last check and defaults of a table of this kind (after the shared checks).

        Parameters
        ----------
        kind : str
            The table's ``kind`` (one of :data:`OPTION_KINDS`).
        spec : dict
            The ``[[options]]`` table as read.
        vals : dict
            The values to build the option from; updated in place.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError if the table lists component ``options`` (only a combined option has them).
        """
        if "options" in spec:
            raise MitigationError(f"{at}: options = ... is only for kind = 'combined'")

    # ---- what it is and assumes --------------------------------------------------------------------------
    @property
    def typed(self) -> bool:
        """Does a typed effectiveness (an assumption) replace the derived one?"""
        return self.option.retention is not None or self.option.rate_reduction is not None

    def describe(self, currency: str = "") -> str:
        """What the option does, in words (money in ``currency``).

        Parameters
        ----------
        currency : str, optional
            Currency code printed after money amounts (e.g. ``"CHF"``); empty for none.

        Returns
        -------
        str
            One-line description of the option, assumptions labelled ASSUMED.
        """
        raise NotImplementedError

    @property
    def sole_basis(self) -> str | None:
        """The effect basis when every component of an option is of this kind (else None)."""
        return None

    def assumed_basis(self, n_components: int) -> tuple | None:
        """(priority, text): the effect basis of an option with an assumed part of this kind, lower first.

        Parameters
        ----------
        n_components : int
            Number of components of the option whose basis is wanted.

        Returns
        -------
        tuple or None
            ``(priority, text)``: lower priority wins when several components have an assumed part; None when this kind
            assumes nothing.
        """
        return None

    def check(self, source: str) -> None:
        """Raise a MitigationError if the option cannot enter the engine yet.

        Parameters
        ----------
        source : str
            The file (or other source) the option came from, named in the error message.

        Raises
        ------
        MitigationError
            When the option cannot enter the engine yet.
        """

    def components(self, option_named) -> list:
        """The options acting for this one (itself; a combined option's components), ``option_named`` giving the
        study's option of a name.

        Parameters
        ----------
        option_named : callable
            ``option_named(name)`` returns the study's option record of that name.

        Returns
        -------
        list
            The option records acting for this option.
        """
        return [self.option]

    # ---- costs and effect parameters -----------------------------------------------------------------------
    def parameters(self) -> list:
        """(name, central value) of every input of this option the engine varies: capital cost, annual
        maintenance, typed effects, and the kind's own (scaling effectiveness, closure share, repair days).

        Returns
        -------
        list of tuple
            ``(name, central value)`` pairs; costs in the study's currency, effects as shares [-], repair times [day].
        """
        o = self.option
        p = [(f"capital_cost:{o.name}", o.capital_cost), (f"annual_maintenance:{o.name}", o.annual_maintenance)]
        if o.rate_reduction is not None:
            p.append((f"rate_reduction:{o.name}", o.rate_reduction))
        p += self._release_parameters()
        if o.retention is not None:
            p.append((f"retention:{o.name}", o.retention))
        return p + self._own_parameters()

    def _release_parameters(self) -> list:
        return []

    def _own_parameters(self) -> list:
        return []

    def stated_ranges(self, central: dict) -> dict:
        """name -> (low, high, how) of the option's stated ranges (costs and typed effects).

        Parameters
        ----------
        central : dict
            ``name -> central value`` of the parameters the engine varies; only ranges of names in it are returned.

        Returns
        -------
        dict
            ``name -> (low, high, how)``: the stated bounds (costs in the study's currency, effects as shares [-]) and
            the sampling, typed effectiveness labelled as an assumption.
        """
        o = self.option
        out = {}
        for fld in ("capital_cost", "annual_maintenance", "retention", "rate_reduction"):
            rng = getattr(o, f"{fld}_range")
            if rng is not None and f"{fld}:{o.name}" in central:
                out[f"{fld}:{o.name}"] = (*rng, "uniform, stated" + (" (typed effectiveness: assumption)"
                                                                     if fld in ("retention", "rate_reduction")
                                                                     else ""))
        return out

    def assumed_ranges(self) -> dict:
        """name -> (low, high, how) of the option's assumed (not stated) ranges.

        Returns
        -------
        dict
            ``name -> (low, high, how)``: bounds of each assumed range (same units as the parameter) and how it is
            sampled.
        """
        return {}

    # ---- effect on the falls -------------------------------------------------------------------------------
    def stages(self, site, space, index: int) -> list:
        """The option's typed stages (:mod:`riskrf.risk.loss_engine`), derived with the slope models ``site``
        (:class:`riskrf.risk.slope_models.SlopeModels`); effect parameters get their columns from ``space``;
        ``index``: the option's position in the study.

        Parameters
        ----------
        site : riskrf.risk.slope_models.SlopeModels
            The site's slope models (simulated runs, mass grid, exposed road).
        space : object
            The engine's parameter space; ``space.column(name)`` gives the sampled values of an effect parameter.
        index : int
            The option's position in the study.

        Returns
        -------
        list
            The option's stages (:mod:`riskrf.risk.loss_engine` stage objects), in the order they act.
        """
        return []

    def geometry_measure(self):
        """The profile or surface change to re-simulate (a derived ditch, bench, bund or drape), else None."""
        return None


class DoNothing(OptionEffect):
    """``none``: the site as it is."""

    def describe(self, currency=""):
        return "the site as it is"

    @property
    def sole_basis(self):
        return "-"


class Scaling(OptionEffect):
    """``scaling``: scaling and bolting removes releases (of its zone and mass range, or a typed share)."""

    order = RELEASE
    own_fields = ("effectiveness", "effectiveness_range", "effectiveness_half_life_years")

    @classmethod
    def check_effect_spec(cls, kind, spec, at):
        """Check that scaling names the blocks it removes or a typed ``rate_reduction``.

        Parameters
        ----------
        kind : str
            The table's ``kind`` (``"scaling"``).
        spec : dict
            The ``[[options]]`` table as read (masses [kg], zone [m]).
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError when neither is given.
        """
        if spec.get("rate_reduction") is None and not any(
                spec.get(k) is not None for k in ("min_mass_kg", "max_mass_kg", "zone_x_m")):
            raise MitigationError(f"{at}: scaling needs the blocks it removes (min_mass_kg, max_mass_kg "
                                  "and/or zone_x_m) or a typed rate_reduction (an assumption)")

    def effect(self) -> tuple:
        """Scaling and bolting by zone and mass: (initial effectiveness, its range, half-life [yr], mean over a
        renewal cycle, mean at the range's ends).  ASSUMED defaults: 0.8 of the targeted releases removed when new
        (range 0.6-0.95), halving every ``life_years`` (10 years without one): loosening, new joints opening and
        missed blocks make scaling neither complete nor lasting.  Mean over a cycle of length L of e0 2^(-t/h):
        e0 h (1 - 2^(-L/h)) / (L ln 2).

        Returns
        -------
        tuple
            ``(e0, (low, high), half_life, mean, (mean_low, mean_high))``: initial effectiveness [-], its range [-],
            half-life [yr], mean effectiveness over a renewal cycle [-] and the mean at the range's ends [-].
        """
        o = self.option
        e0 = SCALING_EFFECTIVENESS if o.effectiveness is None else o.effectiveness
        rng = o.effectiveness_range or ((SCALING_EFFECTIVENESS_RANGE if o.effectiveness is None
                                         else (o.effectiveness, o.effectiveness)))
        life = o.life_years or SCALING_DEFAULT_CYCLE_YEARS
        h = o.effectiveness_half_life_years or life
        k = h * -np.expm1(-np.log(2.0) * life / h) / (life * np.log(2.0))
        return e0, tuple(rng), h, e0 * k, (rng[0] * k, rng[1] * k)

    def describe(self, currency=""):
        o = self.option
        if o.rate_reduction is not None:
            return f"scaling and bolting; ASSUMED to prevent {o.rate_reduction:.0%} of falls (typed)"
        size = (f"{o.min_mass_kg or 0:,.0f}-{o.max_mass_kg:,.0f} kg" if o.max_mass_kg
                else f"above {o.min_mass_kg:,.0f} kg" if o.min_mass_kg else "of every size")
        zone = f" from x = {o.zone_x_m[0]:g}-{o.zone_x_m[1]:g} m" if o.zone_x_m else ""
        e0, rng, h, mean, _ = self.effect()
        return (f"scaling and bolting: removes {e0:.0%} (ASSUMED, {rng[0]:.0%}-{rng[1]:.0%}) of the release of "
                f"blocks {size}{zone} when new, halving every {h:g} years (ASSUMED): {mean:.0%} on average")

    def assumed_basis(self, n_components):
        """(priority, text): the effect basis of an option with an assumed part of this kind.

        Parameters
        ----------
        n_components : int
            Number of components of the option whose basis is wanted.

        Returns
        -------
        tuple or None
            ``(priority, text)``: lower priority wins when several components have an assumed part; None when this kind
            assumes nothing.
        """
        e0, _, h, mean, _ = self.effect()
        return 1, (f"derived zone and mass range, ASSUMED effectiveness ({self.option.name}: {e0:.0%} when new, "
                   f"halving every {h:g} yr, {mean:.0%} on average)"
                   + ("; others derived (simulation and site geometry)" if n_components > 1 else ""))

    def _release_parameters(self):
        if self.option.rate_reduction is not None:
            return []
        return [(f"scaling_effectiveness:{self.option.name}", self.effect()[3])]

    def assumed_ranges(self):
        o = self.option
        if o.rate_reduction is not None:
            return {}
        e0, (a, b), h, _, (lo, hi) = self.effect()
        if not hi > lo:
            return {}
        return {f"scaling_effectiveness:{o.name}": (
            lo, hi, f"uniform, ASSUMED (removes {a:.0%}-{b:.0%} of the targeted releases when new, "
            f"halving every {h:g} years; mean over the cycle)")}

    def stages(self, site, space, index):
        o = self.option
        if o.rate_reduction is not None:
            return [ReleaseStage(o.name, space.column(f"rate_reduction:{o.name}"))]
        share = 1.0
        if o.zone_x_m is not None:
            ctx = site.need_context(o, "zone_x_m")
            try:
                share = seeder_share(ctx.scenario, o.zone_x_m, f"{site.source}: option {o.name!r}")
            except MeasureError as exc:
                raise MitigationError(str(exc)) from exc
        mid = site.grid.mid
        lo, hi = o.min_mass_kg or 0.0, o.max_mass_kg or np.inf
        inside = (mid >= lo) & (mid <= hi)
        # the targeted releases (derived: zone and mass range) times the ASSUMED mean effectiveness
        return [ReleaseStage(o.name, space.column(f"scaling_effectiveness:{o.name}"),
                             target=share * inside.astype(float))]


class _SlopeGeometry(OptionEffect):
    """A change of the slope (ditch, bench, bund, drape): a typed retention, or re-simulated with the changed
    profile or surface (every such component of an option at once; see :func:`option_chain`)."""

    @property
    def order(self):
        return TYPED_RETENTION if self.option.retention is not None else GEOMETRY

    def stages(self, site, space, index):
        if self.option.retention is None:
            return []               # derived: simulated with the option's other geometry changes
        return [RetentionStage(self.option.name, space.column(f"retention:{self.option.name}"))]

    def geometry_measure(self):
        if self.option.retention is not None:
            return None
        o = self.option
        return SlopeMeasure(o.kind, o.name, o.x_m, o.width_m, o.height_m, o.zone_x_m, o.inner_slope_hv,
                            o.outer_slope_hv, o.material)


class CatchDitch(_SlopeGeometry):
    """``ditch``: a catchment ditch dug into the profile."""

    geometry_fields = ("x_m", "width_m", "depth_m")

    def describe(self, currency=""):
        o = self.option
        if o.retention is not None:
            return _typed_retention(o, "catchment ditch")
        return (f"catchment ditch {o.width_m:g} m wide and {o.depth_m:g} m deep from x = {o.x_m:g} m; "
                "retention derived by simulation")

    def geometry_measure(self):
        """The ditch to re-simulate, else None (typed retention).

        Returns
        -------
        riskrf.risk.measures.Ditch or riskrf.risk.geometry_measures.SlopeMeasure or None
            The geometry change to re-simulate; None when a typed retention replaces it.
        """
        if self.option.retention is not None:
            return None
        o = self.option
        return Ditch(o.x_m, o.width_m, o.depth_m, o.inner_slope_hv or 0.25,
                     1.0 if o.outer_slope_hv is None else o.outer_slope_hv, o.material, o.name)


class Bench(_SlopeGeometry):
    """``bench``: a catch bench cut into the slope."""

    geometry_fields = ("x_m", "width_m")

    def describe(self, currency=""):
        o = self.option
        if o.retention is not None:
            return _typed_retention(o, "bench")
        return f"catch bench {o.width_m:g} m wide cut into the slope from x = {o.x_m:g} m; retention derived by " \
               "simulation"

    @property
    def sole_basis(self):
        return ("derived: the slope re-simulated with the bench cut into it (common random numbers, as for a "
                "ditch)")


class Bund(_SlopeGeometry):
    """``bund``: an embankment on the ground."""

    geometry_fields = ("x_m", "width_m", "height_m")

    def describe(self, currency=""):
        o = self.option
        if o.retention is not None:
            return _typed_retention(o, "bund")
        return (f"bund {o.height_m:g} m high on the ground from x = {o.x_m:g} m over {o.width_m:g} m; "
                "retention derived by simulation")

    @property
    def sole_basis(self):
        return ("derived: the slope re-simulated with the bund built on it (common random numbers, as for a "
                "ditch)")


class Drape(OptionEffect):
    """``drape``: a mesh hung on the rock face over ``zone_x_m``.

    Its effect is derived where the simulation can derive it and assumed where it cannot (Badger & Duffy 2012):

    * derived: the share of the falls reaching the road that are released under the mesh (release point in
      ``zone_x_m``, by block mass and slope model, :meth:`riskrf.risk.slope_models.SlopeModels.drape_share`), with
      its Monte Carlo Beta law; falls from above or beside the mesh are not credited (an unsecured or secured
      drapery addresses the rock fall that originates from the covered area; a hybrid drapery or attenuator, kind
      ``attenuator``, intercepts falls from upslope);
    * derived, with an ASSUMED default: blocks heavier than ``max_mass_kg`` are not contained; without it, blocks
      above a 1.0 m sphere (:data:`DRAPE_MAX_BLOCK_DIAMETER_M`, the upper end of the 0.6-1.0 m typical of simple
      drapery, Giacchetti & Grimod; at the scenario's rock density) are not credited;
    * ASSUMED: the containment efficiency ``containment`` (default :data:`DRAPE_CONTAINMENT`, range
      :data:`DRAPE_CONTAINMENT_RANGE`), the share of the blocks released under the mesh that it keeps on the face
      and delivers to the toe at low speed; the rest escape (they bulge or tear the mesh, or leave at its open
      bottom) and are taken as falling as without it.

    Retained share of the falls reaching the road = containment x share released under the mesh; never 100 %
    without an ASSUMED containment of 1 stated in the option and labelled in every output.  A typed ``retention``
    replaces all of this (an ASSUMPTION).

    References
    ----------
    Badger, T. C. & Duffy, J. D. (2012).  Drapery systems.  In Turner & Schuster (eds), *Rockfall:
    Characterization and Control*, chapter 16, TRB.
    Giacchetti, G. & Grimod, A. Rockfall mitigation using simple drapery system: design approach (Maccaferri).
    """

    geometry_fields = ("zone_x_m",)
    own_fields = ("containment", "containment_range")

    #: A drape acts on the face, before the slope's geometry changes and the structures below it.
    order = TYPED_RETENTION

    @classmethod
    def finish_spec(cls, kind, spec, vals, at):
        """Last check of a drape's table: its containment lies in its range.

        Parameters
        ----------
        kind : str
            The table's ``kind`` (``"drape"``).
        spec : dict
            The ``[[options]]`` table as read.
        vals : dict
            The values to build the option from.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError when ``containment`` lies outside ``containment_range``, or a typed
            ``retention`` is given with a containment (one replaces the other).
        """
        super().finish_spec(kind, spec, vals, at)
        rng, c = vals.get("containment_range"), spec.get("containment")
        if rng is not None and c is not None and not rng[0] <= c <= rng[1]:
            raise MitigationError(f"{at}: containment = {c!r} lies outside containment_range = {list(rng)}")
        if spec.get("retention") is not None and (c is not None or rng is not None):
            raise MitigationError(f"{at}: a typed retention replaces the drape's derived effect: give retention "
                                  "or containment, not both")

    def containment(self) -> tuple:
        """(containment efficiency [-], its (low, high) range [-], is it riskrf's ASSUMED default?).

        Returns
        -------
        tuple
            ``(c, (low, high), default)``.
        """
        o = self.option
        if o.containment is None:
            return DRAPE_CONTAINMENT, o.containment_range or DRAPE_CONTAINMENT_RANGE, True
        return o.containment, o.containment_range or (o.containment, o.containment), False

    def max_mass_kg(self, scenario) -> tuple:
        """(largest block the mesh contains [kg], how it was set).

        Parameters
        ----------
        scenario : simulation.scenario.Scenario or None
            The slope scenario (its seeder's rock density [kg/m3] sets the default from
            :data:`DRAPE_MAX_BLOCK_DIAMETER_M`).

        Returns
        -------
        tuple
            ``(mass [kg], text)``.
        """
        o = self.option
        if o.max_mass_kg is not None:
            return float(o.max_mass_kg), f"blocks above max_mass_kg = {o.max_mass_kg:,.0f} kg not contained"
        rho = scenario.seeder.density_kg_m3 if scenario is not None else 2650.0
        m = rho * np.pi * DRAPE_MAX_BLOCK_DIAMETER_M ** 3 / 6.0
        return m, (f"blocks above {m:,.0f} kg (a {DRAPE_MAX_BLOCK_DIAMETER_M:g} m sphere; ASSUMED: no max_mass_kg "
                   "given) not contained")

    @property
    def key(self) -> str:
        """Name of the derived share under the mesh (its effect parameter is ``retention:<key>``)."""
        return f"{self.option.name}: share under the mesh"

    def describe(self, currency=""):
        o = self.option
        if o.retention is not None:
            return _typed_retention(o, "drape")
        c, (lo, hi), default = self.containment()
        return (f"drape over the face at x = {o.zone_x_m[0]:g}-{o.zone_x_m[1]:g} m: keeps on the face "
                f"{c:.0%} ({'ASSUMED' if default else 'stated, an ASSUMPTION'}, {lo:.0%}-{hi:.0%}) of the blocks "
                "released under it (which falls start there: derived by simulation); falls from above or beside "
                "the mesh not credited")

    def assumed_basis(self, n_components):
        """(priority, text): the effect basis of an option with a drape.

        Parameters
        ----------
        n_components : int
            Number of components of the option whose basis is wanted.

        Returns
        -------
        tuple or None
            ``(priority, text)``: lower priority wins when several components have an assumed part; None when this kind
            assumes nothing.
        """
        if self.option.retention is not None:
            return None
        c, (lo, hi), default = self.containment()
        how = "ASSUMED containment" if default else "stated containment (an ASSUMPTION, not derived)"
        mass = (f"blocks above max_mass_kg = {self.option.max_mass_kg:,.0f} kg not contained"
                if self.option.max_mass_kg is not None else
                f"blocks above a {DRAPE_MAX_BLOCK_DIAMETER_M:g} m sphere not contained (ASSUMED)")
        return 0, (f"derived share of road falls released under the mesh ({self.option.name}: "
                   f"x = {self.option.zone_x_m[0]:g}-{self.option.zone_x_m[1]:g} m; falls from above not credited; "
                   f"{mass}) x {how} {c:.0%} ({lo:.0%}-{hi:.0%})"
                   + ("; others derived (simulation and site geometry)" if n_components > 1 else ""))

    def _own_parameters(self):
        if self.option.retention is not None:
            return []
        return [(f"containment:{self.option.name}", self.containment()[0])]

    def assumed_ranges(self):
        if self.option.retention is not None:
            return {}
        c, (lo, hi), default = self.containment()
        if not hi > lo:
            return {}
        return {f"containment:{self.option.name}": (
            lo, hi, "uniform, " + ("ASSUMED (riskrf's default containment of a drape: no published efficiency "
                                   "found)" if default else "stated (containment_range: an assumption)"))}

    def check_zone(self, scenario, where: str) -> float:
        """Check the draped zone against ``scenario`` (:func:`riskrf.risk.geometry_measures.check_drape_zone`).

        Parameters
        ----------
        scenario : simulation.scenario.Scenario
            The slope scenario.
        where : str
            The start of every error message (file and option).

        Returns
        -------
        float
            Share of the release line under the mesh [-].

        Raises
        ------
        MitigationError
            Naming ``where`` and ``zone_x_m`` when the zone leaves the profile, is not on a face or has no release.
        """
        from .geometry_measures import check_drape_zone
        try:
            return check_drape_zone(scenario, self.option.zone_x_m, where)
        except MeasureError as exc:
            raise MitigationError(str(exc)) from exc

    def stages(self, site, space, index):
        o = self.option
        if o.retention is not None:
            return [RetentionStage(o.name, space.column(f"retention:{o.name}"))]
        ctx = site.need_context(o, "zone_x_m")
        where = f"{site.source}: option {o.name!r}"
        cap, _ = self.max_mass_kg(ctx.scenario)
        s0, _, _, by_mass = site.drape_share(self.key, lambda sc: self.check_zone(sc, where), o.zone_x_m, cap)
        return [ContainmentStage(o.name, space.column(f"containment:{o.name}"), space.column(f"retention:{self.key}"),
                                 shift=by_mass - s0)]


class _Structure(OptionEffect):
    """A structure with damage states: out of service ``repair_days`` after a destructive impact."""

    @classmethod
    def finish_spec(cls, kind, spec, vals, at):
        """Last check of the table, and the ASSUMED default ``repair_days`` of its kind (:data:`DEFAULT_REPAIR_DAYS`).

        Parameters
        ----------
        kind : str
            The table's ``kind`` (one of :data:`BARRIER_KINDS`).
        spec : dict
            The ``[[options]]`` table as read.
        vals : dict
            The values to build the option from; ``repair_days`` [day] set in place when not given.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError as :meth:`OptionEffect.finish_spec` does.
        """
        super().finish_spec(kind, spec, vals, at)
        if vals.get("repair_days") is None:
            vals["repair_days"] = DEFAULT_REPAIR_DAYS[kind]

    def _own_parameters(self):
        o = self.option
        return [(f"repair_days:{o.name}", DEFAULT_REPAIR_DAYS[o.kind] if o.repair_days is None else o.repair_days)]

    def _stage(self, site, space, index, *, shed: bool, coverage: float) -> BarrierStage:
        o = self.option
        passing, held_sel, destroy = site.barrier_damage(o, shed=shed)
        return BarrierStage(o.name, index, passing, held_sel, destroy, coverage=coverage, after_road=shed,
                            param=space.column(f"retention:{o.name}") if o.retention is not None else None,
                            repair_cost_per_impact=o.repair_cost_per_impact, replacement_cost=o.replacement_cost)


class Barrier(_Structure):
    """``fence`` / ``attenuator``: a barrier line of capacity ``capacity_kj`` (MEL) and height ``height_m``."""

    order = BARRIER
    needs_design_check = True
    required_fields = ("capacity_kj", "height_m")

    def describe(self, currency=""):
        o = self.option
        return (f"{o.kind} of {o.capacity_kj:,.0f} kJ (MEL), {o.height_m:g} m high"
                + (f" at x = {o.x_m:g} m" if o.x_m is not None else " at the barrier line")
                + (f"; ASSUMED to retain {o.retention:.0%} (typed)" if o.retention is not None
                   else "; passing falls from simulated heights and energies")
                + f"; out of service {o.repair_days:g} days after an impact above MEL (assumption)")

    def stages(self, site, space, index):
        return [self._stage(site, space, index, shed=False, coverage=1.0)]


class Shed(_Structure):
    """``shed``: a rock shed over ``covered_length_m`` of the exposed road, capacity ``capacity_kj``."""

    order = SHED
    required_fields = ("capacity_kj",)

    def describe(self, currency=""):
        o = self.option
        return (f"rock shed of {o.capacity_kj:,.0f} kJ over "
                + (f"{o.covered_length_m:g} m of road" if o.covered_length_m else "the exposed road")
                + f"; out of service {o.repair_days:g} days after an impact above capacity (assumption)")

    def stages(self, site, space, index):
        o = self.option
        coverage = min(o.covered_length_m / site.exposed_length_m, 1.0) if o.covered_length_m else 1.0
        return [self._stage(site, space, index, shed=True, coverage=coverage)]


class Realignment(OptionEffect):
    """``realignment``: the road moved to ``road_x_m`` on the profile, or away from the slope."""

    order = EXPOSURE

    def describe(self, currency=""):
        o = self.option
        return (f"road moved to x = {o.road_x_m:g} m" if o.road_x_m is not None
                else "road moved away from the slope (no exposure)")

    @property
    def sole_basis(self):
        return "geometry: the road leaves the slope" if self.option.road_x_m is None else None

    def stages(self, site, space, index):
        o = self.option
        if o.road_x_m is None:
            return [ExposureStage(o.name, np.zeros(len(site.models)))]
        ctx = site.need_context(o, "road_x_m")
        prof = ctx.scenario.profile
        if not prof.x[0] < o.road_x_m < prof.x[-1]:
            raise MitigationError(f"{site.source}: option {o.name!r}: road_x_m = {o.road_x_m:g} m is "
                                  f"outside the profile ({prof.x[0]:g}, {prof.x[-1]:g}) m")
        factor = []
        for m in site.models:
            ref = m.result if m.result is not None else site.reference_run
            road_x = ref.scenario.collectors[ref.scenario.collector_index(ctx.road_collector)].x
            now = runout_beyond(ref, road_x).sum()
            factor.append(min(float(runout_beyond(ref, o.road_x_m).sum() / now), 1.0) if now else 0.0)
        return [ExposureStage(o.name, np.array(factor))]


class Closure(OptionEffect):
    """``closure``: the road closed under a rainfall or warning rule (or a typed share of falls while closed)."""

    order = CLOSURE
    #: A closure rule (computed from the site's rate model) ...
    rule_fields = ("threshold_mm", "window_days", "warning_levels")
    #: ... or a typed share of falls while closed and hours closed per year (an assumption).
    typed_fields = ("share_while_closed", "closure_hours_per_year")
    own_fields = typed_fields + rule_fields + ("cost_per_closure_hour",)

    @classmethod
    def read_spec(cls, kind, spec, vals, at):
        """Check and read a closure's rule (rainfall or warning) or its typed share and hours; the cost of the
        hours closed is added to ``annual_maintenance``.

        Parameters
        ----------
        kind : str
            The table's ``kind`` (``"closure"``).
        spec : dict
            The ``[[options]]`` table as read (rainfall [mm], window [day], hours [h/yr], cost per hour).
        vals : dict
            The values to build the option from; ``warning_levels``, ``window_days`` and ``annual_maintenance``
            set in place.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError naming ``at``, the field and its value.
        """
        if spec.get("warning_levels") is not None:
            lv = spec["warning_levels"]
            if not (isinstance(lv, list) and lv and all(isinstance(x, str) and x.strip() for x in lv)):
                raise MitigationError(f"{at}: warning_levels = {lv!r} must be a list of warning levels, "
                                      "e.g. [\"Red\", \"Black\"]")
            vals["warning_levels"] = tuple(x.strip().capitalize() for x in lv)
        rule = [k for k in cls.rule_fields if spec.get(k) is not None]
        typed = [k for k in cls.typed_fields if spec.get(k) is not None]
        if rule and typed:
            raise MitigationError(f"{at}: give a closure rule ({', '.join(rule)}; its share and hours are "
                                  f"computed from the site's rate model) or typed {', '.join(typed)} (an assumption), "
                                  "not both")
        if rule:
            if spec.get("threshold_mm") is not None and spec.get("warning_levels") is not None:
                raise MitigationError(f"{at}: give threshold_mm (a rainfall rule) or warning_levels (a "
                                      "warning rule), not both")
            if spec.get("window_days") is not None and spec.get("threshold_mm") is None:
                raise MitigationError(f"{at}: window_days = {spec['window_days']!r} belongs to a rainfall "
                                      "rule: give threshold_mm too")
            if spec.get("threshold_mm") is not None and not spec["threshold_mm"] > 0:
                raise MitigationError(f"{at}: threshold_mm = {spec['threshold_mm']!r} must be a rainfall "
                                      "> 0 mm")
            wd = spec.get("window_days")
            if wd is not None and (isinstance(wd, bool) or int(wd) != wd or wd < 1):
                raise MitigationError(f"{at}: window_days = {wd!r} must be a whole number of days >= 1")
            if spec.get("threshold_mm") is not None and wd is None:
                vals["window_days"] = 1.0
        else:
            for key in cls.typed_fields:
                if spec.get(key) is None:
                    raise MitigationError(
                        f"{at}: a closure needs a rule (threshold_mm [+ window_days], or warning_levels; "
                        "computed from the site's [rates] model) or typed share_while_closed and "
                        "closure_hours_per_year (an assumption; riskrf.risk.closure.closure_rule gives both: "
                        f"ClosureRule.option_spec); {key} is missing")
            if spec["closure_hours_per_year"] > 8766:
                raise MitigationError(f"{at}: closure_hours_per_year = "
                                      f"{spec['closure_hours_per_year']!r} exceeds the hours of a year (8766)")
            vals["annual_maintenance"] = float(spec.get("annual_maintenance", 0.0)) + \
                float(spec["closure_hours_per_year"]) * float(spec.get("cost_per_closure_hour", 0.0))

    @property
    def typed(self):
        return super().typed or not self.option.has_closure_rule

    def describe(self, currency=""):
        o = self.option
        if o.share_while_closed is None:
            return f"{o.rule_text()}; share and hours not yet computed (needs the site's rate model, [rates])"
        how = "computed from the rate model" if o.has_closure_rule else "ASSUMED (typed)"
        cur = f" {currency}" if currency else ""
        return ((f"{o.closure_rule}: " if o.closure_rule else "")
                + f"road closed {o.closure_hours_per_year:,.1f} h per year ({how}) at "
                f"{o.cost_per_closure_hour:,.0f}{cur} per hour "
                f"({money(o.closure_hours_per_year * o.cost_per_closure_hour, sig=3)}{cur} per year, in the "
                f"annual maintenance); {o.share_while_closed:.1%} of falls occur while closed "
                f"({how}); protects road users, falls still reach the road")

    @property
    def sole_basis(self):
        return "computed: closure rule on the rate model and rainfall record"

    def check(self, source):
        o = self.option
        if o.share_while_closed is None:
            raise MitigationError(
                f"{source}: option {o.name!r}: its closure rule ({o.rule_text()}) has not been evaluated: "
                "the share of falls while closed and the closure hours are computed from a daily rate model "
                "(a site file's [rates] table, riskrf assess; or riskrf.risk.site_rates.resolve_closures)")

    def _own_parameters(self):
        return [(f"closure_share:{self.option.name}", self.option.share_while_closed)]

    def stages(self, site, space, index):
        return [ClosureStage(self.option.name, space.column(f"closure_share:{self.option.name}"))]


class Combined(OptionEffect):
    """``combined``: its components in series; costs and effects are theirs."""

    needs_capital_cost = False

    @classmethod
    def finish_spec(cls, kind, spec, vals, at):
        """Check and read the components ``options`` (two or more option names) and nothing else.

        Parameters
        ----------
        kind : str
            The table's ``kind`` (``"combined"``).
        spec : dict
            The ``[[options]]`` table as read.
        vals : dict
            The values to build the option from; ``options`` set in place to a tuple of names.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError when the components are missing or other fields are given.
        """
        comps = spec.get("options")
        if not isinstance(comps, list) or len(comps) < 2 or not all(isinstance(c, str) for c in comps):
            raise MitigationError(f"{at}: a combined option needs options = [\"name\", \"name\", ...] "
                                  "(two or more)")
        extra = {k for k in spec if k not in ("name", "kind", "options", "description")}
        if extra:
            raise MitigationError(f"{at}: a combined option takes its costs and effects from its "
                                  f"components; remove {sorted(extra)}")
        vals["options"] = tuple(comps)

    def describe(self, currency=""):
        return "combination of " + " + ".join(self.option.options)

    def components(self, option_named):
        """The options acting for this one: a combined option's components.

        Parameters
        ----------
        option_named : callable
            ``option_named(name)`` returns the study's option record of that name.

        Returns
        -------
        list
            The option records acting for this option.
        """
        return [option_named(n) for n in self.option.options]

    def parameters(self):
        """No parameters of its own: a combined option's costs and effects are its components'.

        Returns
        -------
        list of tuple
            ``(name, central value)`` pairs; costs in the study's currency, effects as shares [-], repair times [day].
        """
        return []


#: Kinds with fields no other kind takes (their classes' ``own_fields``), in the order a table is checked for them.
OWN_FIELD_KINDS = ("closure", "scaling", "drape")

#: The class of each option kind.
KIND_CLASSES = {"none": DoNothing, "scaling": Scaling, "ditch": CatchDitch, "fence": Barrier, "attenuator": Barrier,
                "shed": Shed, "realignment": Realignment, "closure": Closure, "combined": Combined, "bench": Bench,
                "bund": Bund, "drape": Drape}


def effect_of(option) -> OptionEffect:
    """The behaviour of ``option`` (its kind's class, wrapping it).

    Parameters
    ----------
    option : riskrf.risk.mitigation_inputs.Option
        The option record (its ``kind`` one of :data:`OPTION_KINDS`).

    Returns
    -------
    OptionEffect
        The instance of the kind's class (:data:`KIND_CLASSES`) wrapping ``option``.
    """
    return KIND_CLASSES[option.kind](option)


def scaling_effect(option) -> tuple:
    """:meth:`Scaling.effect` of a scaling option.

    Parameters
    ----------
    option : riskrf.risk.mitigation_inputs.Option
        A ``scaling`` option record.

    Returns
    -------
    tuple
        As :meth:`Scaling.effect`: initial effectiveness [-], its range [-], half-life [yr], cycle mean [-] and the
        cycle means at the range's ends [-].
    """
    return Scaling(option).effect()


def effect_basis(option, components) -> str:
    """How the effect of ``option`` (made of ``components``) is known: typed (an ASSUMPTION), computed, derived,
    or derived with an ASSUMED part, in words.

    Parameters
    ----------
    option : riskrf.risk.mitigation_inputs.Option
        The option whose effect basis is wanted.
    components : list of riskrf.risk.mitigation_inputs.Option
        The options acting for it (itself, or a combined option's components).

    Returns
    -------
    str
        The basis in words; a typed effectiveness starts with ``"ASSUMPTION"``.
    """
    effects = [effect_of(c) for c in components]
    typed = [e.option.name for e in effects if e.typed]
    if typed:
        return "ASSUMPTION: typed effectiveness (" + ", ".join(typed) + ")"
    sole = {e.sole_basis for e in effects}
    if len(sole) == 1 and None not in sole:
        return sole.pop()
    assumed = [b for b in (e.assumed_basis(len(components)) for e in effects) if b is not None]
    if len(assumed) == 1:
        return assumed[0][1]
    if assumed:                 # every assumed part named, lowest priority first; the derived rest once
        tail = "; others derived (simulation and site geometry)"
        texts = [t.removesuffix(tail) for _, t in sorted(assumed, key=lambda b: b[0])]
        return "; ".join(texts) + (tail if len(components) > len(assumed) else "")
    return "derived (simulation and site geometry)"


def option_chain(option, components, site, space, index_of: dict) -> OptionChain:
    """The engine's view of ``option``: the stages of its ``components`` in series (releases, typed retentions, the
    slope geometry changes re-simulated together, barriers, sheds, closures, realignments) and their costs.
    ``index_of``: option name -> position in the study.

    Parameters
    ----------
    option : riskrf.risk.mitigation_inputs.Option
        The option.
    components : list of riskrf.risk.mitigation_inputs.Option
        The options acting for it, in any order (sorted here by the order in which they act).
    site : riskrf.risk.slope_models.SlopeModels
        The site's slope models.
    space : object
        The engine's parameter space; ``space.column(name)`` gives the sampled values of an effect parameter.
    index_of : dict
        Option name -> position in the study.

    Returns
    -------
    riskrf.risk.loss_engine.OptionChain
        The option's name, its stages in series and ``(option index, life [yr])`` of each component.
    """
    effects = [effect_of(c) for c in components]
    stages = []
    for order in range(EXPOSURE + 1):
        for e in effects:
            if e.order == order:
                stages += e.stages(site, space, index_of[e.option.name])
        if order == GEOMETRY:
            geo = [e for e in effects if e.order == GEOMETRY]
            if geo:
                site.need_context(geo[0].option, "x_m")
                key = "+".join(e.option.name for e in geo)
                ret0, _, _, by_mass = site.geometry_retention(key, [e.geometry_measure() for e in geo])
                # retention by mass bin and slope model, as a shift from the overall reference retention (the
                # parameter)
                stages.append(RetentionStage(key, space.column(f"retention:{key}"), shift=by_mass - ret0))
    return OptionChain(option.name, tuple(stages), tuple((index_of[c.name], c.life_years) for c in components))
