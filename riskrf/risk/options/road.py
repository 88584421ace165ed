"""Options that stop falls at the road or keep its users from them.

Structures with damage states, out of service ``repair_days`` after a destructive impact: ``fence`` /
``attenuator`` (:class:`Barrier`, a barrier line of capacity MEL and height) and ``shed`` (:class:`Shed`, over a
length of the exposed road); ``realignment`` (:class:`Realignment`, the road moved on the profile or away from the
slope); ``closure`` (:class:`Closure`, the road closed under a rainfall or warning rule, or a typed share).
"""
from __future__ import annotations

import numpy as np

from ...core.format import money
from ..loss_engine import BarrierStage, ClosureStage, ExposureStage
from ..measures import runout_beyond
from .base import BARRIER, CLOSURE, DEFAULT_REPAIR_DAYS, EXPOSURE, MitigationError, OptionEffect, SHED


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
