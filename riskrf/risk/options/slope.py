"""Options that act on the slope: they remove releases, change the profile or surface, or hold blocks on the face.

``scaling`` (:class:`Scaling`: the targeted releases times an ASSUMED effectiveness decaying over its life,
:data:`SCALING_EFFECTIVENESS`), ``ditch``, ``bench`` and ``bund`` (:class:`CatchDitch`, :class:`Bench`,
:class:`Bund`: re-simulated with the changed profile, or a typed retention) and ``drape`` (:class:`Drape`: the
derived share released under the mesh times an ASSUMED containment, :data:`DRAPE_CONTAINMENT`).
"""
from __future__ import annotations

import numpy as np

from ..geometry_measures import SlopeMeasure
from ..loss_engine import ContainmentStage, ReleaseStage, RetentionStage
from ..measures import Ditch, MeasureError, seeder_share
from .base import GEOMETRY, MitigationError, OptionEffect, RELEASE, TYPED_RETENTION, _typed_retention


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
        from ..geometry_measures import check_drape_zone
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
