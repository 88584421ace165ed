"""Inputs of a mitigation study: options, traffic, consequences, economics, criteria, uncertainty, the
parser of the TOML tables that hold them and the reader of the file (every field is checked before anything is
computed; errors name the file, the option and the field).  See :mod:`riskrf.risk.mitigation` for what the options do.
"""
from __future__ import annotations

import difflib
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np
import pandas as pd

from .measures import Ditch, MeasureError
from ..core.format import sig
from .road_users import DEFAULT_VULNERABILITY
from .tolerability import CRITERIA_SETS, CriteriaSet, user_criteria
from .road_risk import occupancy_distribution
from .loss_engine import MASS_BINS, closure_cost_per_fall  # noqa: F401  (public names of this module)
from .options.base import (  # noqa: F401  (public names of this module)
    BARRIER_KINDS,
    DEFAULT_REPAIR_DAYS,
    OPTION_KINDS,
    SLOPE_KINDS,
    MitigationError,
)
from .options.chain import (  # noqa: F401  (public names of this module)
    KIND_CLASSES,
    OWN_FIELD_KINDS,
    effect_of,
    scaling_effect,
)
from .options.slope import (  # noqa: F401  (public names of this module)
    SCALING_DEFAULT_CYCLE_YEARS,
    SCALING_EFFECTIVENESS,
    SCALING_EFFECTIVENESS_RANGE,
)


@dataclass(frozen=True)
class Exposure:
    """Traffic on the exposed road section: ``vehicles_per_day`` two-way over ``lanes`` lanes (half each way),
    split ``directional_split`` : 1 - split between the directions; a fall lands in one lane (``lane_fall_shares``,
    nearest the slope first; default: evenly), so only that lane's vehicles can be hit (Bunce et al. 1997 per
    lane, :mod:`riskrf.risk.road_users`)."""

    vehicles_per_day: float = 4000.0
    vehicle_length_m: float = 5.0
    speed_kmh: float = 80.0
    occupants_per_vehicle: float = 1.5
    commuter_trips_per_day: float = 2.0
    hours_rock_on_road: float = 0.5
    p_cannot_stop: float = 0.002
    share_stopping_on_road: float = 0.3
    exposed_length_m: float = 100.0
    occupants_distribution: dict | None = None
    lanes: int = 2
    directional_split: float = 0.5
    lane_fall_shares: tuple | None = None

    def lane_list(self) -> tuple:
        """The lanes (:class:`riskrf.risk.road_users.Lane`) carrying this traffic.

        Returns
        -------
        tuple of riskrf.risk.road_users.Lane
            The lanes, nearest the slope first (traffic [vehicles/day], speed [km/h]).
        """
        from .road_users import lanes_from_traffic
        return lanes_from_traffic(self.vehicles_per_day, self.speed_kmh, int(self.lanes), self.directional_split,
                                  self.lane_fall_shares)


@dataclass(frozen=True)
class Consequences:
    """Costs of consequences (in ``currency``) and vulnerabilities (probability of death).

    A vulnerability is a number or pairs (mass_kg, probability) interpolated in log mass.
    """

    value_of_statistical_life: float = 5.0e6
    vulnerability_moving_vehicle: object = DEFAULT_VULNERABILITY.direct
    vulnerability_striking_rock: object = DEFAULT_VULNERABILITY.strike
    vehicle_damage: float = 25000.0
    closure_days_per_fall: float = 0.5
    closure_cost_per_day: float = 20000.0
    detour_hours: float = 0.0
    value_of_time_per_hour: float = 0.0
    cleanup_cost_per_fall: float = 3000.0
    currency: str = "CHF"


@dataclass(frozen=True)
class Economics:
    """Discounting of the study: ``discount_rate`` (a fraction per year, default 0.03) over ``horizon_years``
    [yr] (default 50); present values use the uniform-series factor (1 - (1 + r)^-n) / r (Wyllie 2014, 8.5.5).
    """
    discount_rate: float = 0.03
    horizon_years: float = 50.0


@dataclass(frozen=True)
class Criteria:
    """Tolerability, selected in the site file's ``[criteria]``: ``set`` one of
    :data:`riskrf.risk.tolerability.CRITERIA_SETS` ("hong-kong-geo-1998", the default; "ags-2007"; "uk-hse-r2p2";
    "swiss-planat") or "user"; ``slope`` "existing" or "new".  ``individual_risk_per_year`` [1/yr] overrides the
    set's limit (and is required for "user", with optional ``fn_c``, ``fn_k``, ``fn_acceptable_c`` and
    ``marginal_cost_per_life``).  ``disproportion_factor``: the ALARP test calls a further measure reasonably
    practicable while its cost per statistical life saved is at most this factor times the marginal cost of the
    set (or, without one, the value of a statistical life).  After construction ``individual_risk_per_year`` holds
    the limit in force and ``fn_diagram`` the set's name."""

    set: str = "hong-kong-geo-1998"
    slope: str = "existing"
    individual_risk_per_year: float | None = None
    fn_diagram: str = ""
    fn_c: float | None = None
    fn_k: float = 1.0
    fn_acceptable_c: float | None = None
    marginal_cost_per_life: float | None = None
    disproportion_factor: float = 1.0

    def __post_init__(self):
        if self.set != "user" and self.set not in CRITERIA_SETS:
            raise MitigationError(f"criteria.set = {self.set!r} is not one of {sorted(CRITERIA_SETS) + ['user']}")
        if self.slope not in ("existing", "new"):
            raise MitigationError(f"criteria.slope = {self.slope!r} must be 'existing' or 'new'")
        if self.set == "user" and self.individual_risk_per_year is None:
            raise MitigationError("criteria.set = 'user' needs individual_risk_per_year (and optionally fn_c, fn_k, "
                                  "fn_acceptable_c, marginal_cost_per_life)")
        cs = self.criteria_set
        if self.individual_risk_per_year is None:
            object.__setattr__(self, "individual_risk_per_year", cs.individual_limit(self.slope))
        if not self.fn_diagram:
            object.__setattr__(self, "fn_diagram", cs.name)

    @property
    def criteria_set(self) -> CriteriaSet:
        """The selected :class:`~riskrf.risk.tolerability.CriteriaSet` (a user set built from these fields)."""
        if self.set == "user":
            return user_criteria(self.individual_risk_per_year, self.fn_c, self.fn_k, self.fn_acceptable_c,
                                 self.marginal_cost_per_life)
        cs = CRITERIA_SETS[self.set]
        if self.marginal_cost_per_life is not None:
            from dataclasses import replace
            cs = replace(cs, marginal_cost_per_life=self.marginal_cost_per_life)
        return cs

    def describe(self) -> str:
        """The criteria in force in one sentence.

        Returns
        -------
        str
            The sentence, individual risk limit in [1/yr].
        """
        cs = self.criteria_set
        return cs.describe(self.slope).replace(f"{cs.individual_limit(self.slope):.0e}/yr",
                                               f"{self.individual_risk_per_year:.0e}/yr")


@dataclass(frozen=True)
class Uncertainty:
    """Epistemic inputs sampled jointly (uniform within the stated ranges; m_max log-uniform).

    ``rate_factor``: the rate of falls relative to the estimate (e.g. the share of the source above the
    road); ``vulnerability_factor`` multiplies both vulnerability curves.  The power law's b and rate are
    sampled from their posteriors given the record of n falls (b x Gamma(n)/n, the Jeffreys-prior posterior of b;
    rate x Gamma(n)/n, prior 1/rate) and derived retentions from their
    Monte Carlo law (Beta) unless switched off.  ``materials`` gives ranges of slope material parameters
    ("talus.ground_friction_angle_deg" = [20, 30]); the scenario is re-simulated for ``material_draws``
    joint draws (and once at each end of each range, for the tornado) and every sample uses one of the
    draws: reach probability, velocities and heights at the barrier, the road share and every derived
    retention change with it.  The draws are a Latin hypercube over the ranges (a scrambled Sobol' net when
    ``material_draws`` is a power of 2 and there are several parameters); each simulates ``draw_blocks`` blocks
    (default: the option re-simulations' blocks).  ``calibration`` (the ``bootstrap.csv`` of ``riskrf calibrate``: one row
    of re-fitted parameters per replicate) gives the material draws instead: rows drawn jointly, so the
    correlation the calibration found is kept; the tornado uses its 5 % and 95 % quantiles.
    ``fractal_dimension`` (low, high): each event volume breaks up into the expected fragments of fractal
    fragmentation (Perfect 1997; :func:`riskrf.hazard.design_block.fractal_fragments`, ``fragmentation_iterations``
    generations) with D sampled uniformly in the range (central value its midpoint), and the loss engine counts
    the fragments as the blocks that travel and reach the road; without it every event volume is one intact
    block.
    """

    samples: int = 1000
    seed: int = 1
    rate_factor: tuple = (1.0, 1.0)
    m_max_kg: tuple | None = None
    value_of_statistical_life: tuple | None = None
    vulnerability_factor: tuple = DEFAULT_VULNERABILITY.factor_range
    vehicles_per_day: tuple | None = None
    discount_rate: tuple | None = None
    sample_power_law: bool = True
    sample_retention: bool = True
    materials: dict = field(default_factory=dict)    # {"material.field": (low, high)} of the slope scenario
    material_draws: int = 8
    #: blocks per joint material re-simulation (None: the option re-simulations' blocks, ``[hazard] option_blocks``)
    draw_blocks: int | None = None
    calibration: object = field(default=None, repr=False)   # DataFrame: joint draws of a calibration's bootstrap
    calibration_source: str = ""
    fractal_dimension: tuple | None = None   # (low, high): event volumes break up by fractal fragmentation
    fragmentation_iterations: int = 3         # generations of that fragmentation (Perfect 1997)
    #: repeated trajectory ensembles for the error budget (0: off, the outputs say the ensembles' error is not
    #: included; else at least 2) and the share of the blocks each uses (riskrf.risk.error_budget)
    ensemble_replicates: int = 4
    ensemble_effort: float = 0.25
    #: adaptive effort (riskrf.risk.error_budget.adapt_effort): joint samples and material re-simulations are
    #: doubled until the ranking is resolved, every option's expected cost is known within +-precision_target
    #: (2 SE, a share of the cost), or the budget is used
    precision_target: float = 0.05
    max_samples: int = 4000
    max_material_draws: int = 32


@dataclass(frozen=True)
class Option:
    """One mitigation option of a study, as read from the ``[[mitigation.options]]`` tables (README "Mitigation
    options").  ``kind`` is one of OPTION_KINDS.  Money in the study's currency: ``capital_cost``,
    ``annual_maintenance`` (per year), ``repair_cost_per_impact``, ``replacement_cost``; ``life_years`` [yr],
    ``repair_days`` [days] of closure per repair.  Geometry in metres (``x_m``, ``width_m``, ``depth_m``,
    ``height_m``, ``zone_x_m``, ``covered_length_m``, ``road_x_m``), fence capacity ``capacity_kj`` [kJ],
    scaling range ``min_mass_kg``/``max_mass_kg`` [kg].  Typed effects (``retention``, ``rate_reduction``,
    closure ``share_while_closed`` and ``closure_hours_per_year``) are ASSUMPTIONS and labelled as such; the
    ``*_range`` fields are (low, high) for the uncertainty study.
    """
    name: str
    kind: str
    capital_cost: float = 0.0
    annual_maintenance: float = 0.0
    life_years: float | None = None
    repair_cost_per_impact: float = 0.0
    replacement_cost: float | None = None
    repair_days: float | None = None
    rate_reduction: float | None = None
    retention: float | None = None
    x_m: float | None = None
    width_m: float | None = None
    depth_m: float | None = None
    inner_slope_hv: float | None = None
    outer_slope_hv: float | None = None
    material: str | None = None
    capacity_kj: float | None = None
    height_m: float | None = None
    kit: str | None = None                         # fence/attenuator: a kit of riskrf/data/barrier_kits.csv
    min_mass_kg: float | None = None
    max_mass_kg: float | None = None
    zone_x_m: tuple | None = None
    covered_length_m: float | None = None
    road_x_m: float | None = None
    options: tuple = ()
    capital_cost_range: tuple | None = None
    annual_maintenance_range: tuple | None = None
    retention_range: tuple | None = None
    rate_reduction_range: tuple | None = None
    share_while_closed: float | None = None       # closure: share of falls while the road is closed
    closure_hours_per_year: float | None = None   # closure: hours closed per year
    cost_per_closure_hour: float = 0.0            # closure: cost of one hour of closure
    threshold_mm: float | None = None             # closure rule: rainfall over window_days that closes the road
    window_days: float | None = None              # closure rule: rainfall window [days] (default 1)
    warning_levels: tuple | None = None           # closure rule: close under these rainstorm warning levels
    closure_rule: str = ""                        # the rule in words and its source, once computed (site_rates)
    description: str = ""
    effectiveness: float | None = None            # scaling: share of the targeted releases removed when new
    effectiveness_range: tuple | None = None      # scaling: (low, high) of that share
    effectiveness_half_life_years: float | None = None   # scaling: years for the effect to halve
    containment: float | None = None              # drape: share of the falls released under it kept on the face
    containment_range: tuple | None = None        # drape: (low, high) of that share

    def scaling_effect(self) -> tuple:
        """Scaling and bolting by zone and mass: (initial effectiveness, its range, half-life [yr], mean over a
        renewal cycle, mean at the range's ends); see :meth:`riskrf.risk.options.slope.Scaling.effect`.

        Returns
        -------
        tuple
            Initial effectiveness [-], its range [-], half-life [yr], mean over a cycle [-] and the means at the range's
            ends [-].
        """
        return scaling_effect(self)

    @property
    def has_closure_rule(self) -> bool:
        """A closure given as a rule, whose share and hours are computed from the site's rate model."""
        return self.threshold_mm is not None or self.warning_levels is not None

    @property
    def typed(self) -> bool:
        """Does a typed effectiveness (an assumption) replace the derived one?"""
        return effect_of(self).typed

    def describe(self, currency: str = "") -> str:
        """What the option is and assumes, in words (money in ``currency``); each kind's text is its class's in
        :mod:`riskrf.risk.options`.

        Parameters
        ----------
        currency : str, optional
            Currency code printed after money amounts (e.g. ``"CHF"``); empty for none.

        Returns
        -------
        str
            The description, assumptions labelled ASSUMED.
        """
        return (self.description + ": " if self.description else "") + effect_of(self).describe(currency)

    def rule_text(self) -> str:
        """A closure rule in words (rainfall or warning rule).

        Returns
        -------
        str
            The rule (rainfall [mm] over a window [day], or warning levels); empty for a closure without a rule.
        """
        if self.threshold_mm is not None:
            w = int(self.window_days or 1)
            return f"close while the {w}-day rainfall reaches {self.threshold_mm:g} mm (whole day)"
        if self.warning_levels is not None:
            return f"close while a {' or '.join(self.warning_levels)} rainstorm warning is in force"
        return ""


# ---- parsing -------------------------------------------------------------------------------------
NUMBER_FIELDS = ("capital_cost", "annual_maintenance", "life_years", "repair_cost_per_impact", "replacement_cost",
                 "repair_days", "rate_reduction", "retention", "x_m", "width_m", "depth_m", "inner_slope_hv",
                 "outer_slope_hv", "capacity_kj", "height_m", "min_mass_kg", "max_mass_kg", "covered_length_m",
                 "road_x_m", "share_while_closed", "closure_hours_per_year", "cost_per_closure_hour",
                 "threshold_mm", "window_days", "effectiveness", "effectiveness_half_life_years", "containment")
RANGE_FIELDS = ("capital_cost_range", "annual_maintenance_range", "retention_range", "rate_reduction_range",
                "zone_x_m", "effectiveness_range", "containment_range")


def _range(v, where: str, *, share: bool = False):
    if not (isinstance(v, (list, tuple)) and len(v) == 2 and all(isinstance(x, (int, float))
                                                                 and not isinstance(x, bool) for x in v)):
        raise MitigationError(f"{where} = {v!r} must be [low, high]")
    lo, hi = float(v[0]), float(v[1])
    if not (np.isfinite(lo) and np.isfinite(hi)) or lo < 0:
        raise MitigationError(f"{where} = {v!r}: values must be finite numbers >= 0")
    if lo > hi:
        raise MitigationError(f"{where} = {v!r}: low {lo:g} is greater than high {hi:g}")
    if share and hi > 1:
        raise MitigationError(f"{where} = {v!r} is a share and must lie in [0, 1]")
    return lo, hi


def _table(data: dict, cls, where: str, source: str, used: list, special=()):
    names = {f.name for f in fields(cls)}
    if not isinstance(data, dict):
        raise MitigationError(f"{source}: [{where}] must be a table")
    unknown = set(data) - names
    if unknown:
        key = sorted(unknown)[0]
        close = difflib.get_close_matches(key, names, n=1)
        raise MitigationError(f"{source}: unknown field {where}.{key}" + (f"; did you mean {close[0]!r}?" if close
                                                                         else f"; allowed: {sorted(names)}"))
    for f in fields(cls):
        if f.name not in data:
            used.append(f"{where}.{f.name} = {getattr(cls(), f.name)!r} (default)")
        elif f.name in special:
            continue
        elif f.name != "currency" and f.type not in ("bool",):
            v = data[f.name]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v < 0:
                raise MitigationError(f"{source}: {where}.{f.name} = {v!r} must be a number >= 0")
    return data


def _vulnerability(v, where):
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        if not 0 <= v <= 1:
            raise MitigationError(f"{where} = {v!r} must be a probability in [0, 1]")
        return float(v)
    try:
        arr = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        arr = np.empty((0,))
    if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1 or np.any(arr[:, 0] <= 0) \
            or np.any((arr[:, 1] < 0) | (arr[:, 1] > 1)) or np.any(np.diff(arr[:, 0]) <= 0):
        raise MitigationError(f"{where} = {v!r} must be a probability or [[mass_kg, probability], ...] with "
                              "increasing masses > 0 and probabilities in [0, 1]")
    return tuple(map(tuple, arr.tolist()))


def _with_kit(spec: dict, kind: str, at: str) -> dict:
    """``spec`` with the MEL [kJ] and nominal height [m] of the kit it names (``kit = "..."``, a kit of
    :func:`riskrf.hazard.barrier_kits.known_kits`) where it gives none; a MitigationError naming ``at`` and the
    field when the kit is unknown (the known kits listed), the kind is not a barrier, or a stated capacity or
    height contradicts the kit."""
    from ..hazard.barrier_kits import get_kit
    if kind not in ("fence", "attenuator"):
        raise MitigationError(f"{at}: kit = {spec['kit']!r} is only for kind = 'fence' or 'attenuator'")
    try:
        kit = get_kit(spec["kit"], f"{at}: kit")
    except ValueError as exc:
        raise MitigationError(str(exc)) from exc
    out = dict(spec)
    for key, value, unit in (("capacity_kj", kit.mel_kj, "kJ (its MEL)"), ("height_m", kit.nominal_height_m,
                                                                             "m (its nominal height)")):
        given = out.get(key)
        if given is None:
            out[key] = value
        elif isinstance(given, (int, float)) and not isinstance(given, bool) and abs(float(given) - value) > 1e-9:
            raise MitigationError(f"{at}: {key} = {given!r} contradicts kit {kit.name!r}: {value:g} {unit}; leave "
                                  f"{key} out to take the kit's")
    return out


def parse_option(spec: dict, i: int, source: str) -> Option:
    """Check and read option ``i`` of a study (a dict from TOML) read from ``source``; an :class:`Option`.

    Every field is checked before any work (kind, costs >= 0, geometry, ranges low <= high); a
    MitigationError names the source, the option and the field with its value.

    Parameters
    ----------
    spec : dict
        One ``[[options]]`` table (costs in the study's currency, lengths [m], masses [kg], energies [kJ]).
    i : int
        Its position in the study (named in errors).
    source : str
        The file it was read from.

    Returns
    -------
    Option
        The checked option.

    Raises
    ------
    MitigationError
        Naming the source, option and field with its value.
    """
    where = f"options[{i}]"
    if not isinstance(spec, dict):
        raise MitigationError(f"{source}: {where} must be a table")
    name = spec.get("name")
    if not name:
        raise MitigationError(f"{source}: {where} needs a name")
    where = f"option {name!r}"
    allowed = {f.name for f in fields(Option)} - {"closure_rule"}     # closure_rule: filled when computed
    unknown = set(spec) - allowed
    if unknown:
        key = sorted(unknown)[0]
        close = difflib.get_close_matches(key, allowed, n=1)
        raise MitigationError(f"{source}: {where}: unknown field {key!r}" + (f"; did you mean {close[0]!r}?"
                                                                            if close else ""))
    kind = spec.get("kind")
    if kind not in OPTION_KINDS:
        raise MitigationError(f"{source}: {where}: kind = {kind!r} is not one of {', '.join(OPTION_KINDS)}")
    kind_class = KIND_CLASSES[kind]
    if spec.get("kit") is not None:
        spec = _with_kit(spec, kind, f"{source}: {where}")
    if "capital_cost" not in spec and kind_class.needs_capital_cost:
        raise MitigationError(f"{source}: {where}: missing field 'capital_cost' (use 0 for none)")
    for key in NUMBER_FIELDS:
        v = spec.get(key)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v < 0):
            raise MitigationError(f"{source}: {where}: {key} = {v!r} must be a number >= 0")
    vals = {k: (float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v) for k, v in spec.items()}
    for key in RANGE_FIELDS:
        if key in spec:
            vals[key] = _range(spec[key], f"{source}: {where}: {key}",
                               share=key in ("retention_range", "rate_reduction_range", "effectiveness_range",
                                            "containment_range"))
    at = f"{source}: {where}"
    kind_class.read_spec(kind, spec, vals, at)
    for owner in OWN_FIELD_KINDS:       # fields of one kind's own, named by another kind
        own = KIND_CLASSES[owner].own_fields
        if KIND_CLASSES[owner] is not kind_class and any(spec.get(k) is not None for k in own):
            raise MitigationError(f"{at}: {', '.join(own[:-1])} and {own[-1]} are only for kind = {owner!r}")
    if spec.get("effectiveness_half_life_years") is not None and not spec["effectiveness_half_life_years"] > 0:
        raise MitigationError(f"{source}: {where}: effectiveness_half_life_years = "
                              f"{spec['effectiveness_half_life_years']!r} must be > 0 years")
    for key in ("rate_reduction", "retention", "share_while_closed", "effectiveness", "containment"):
        if spec.get(key) is not None and spec[key] > 1:
            raise MitigationError(f"{source}: {where}: {key} = {spec[key]!r} is a share and must lie in [0, 1]")
    for key in kind_class.required_fields:
        if spec.get(key) is None:
            raise MitigationError(f"{at}: a {kind} needs {key}")
        if spec[key] <= 0:      # a 0 kJ or 0 m barrier stops nothing: a typing mistake, never a design
            unit = "kJ" if key == "capacity_kj" else "m"
            raise MitigationError(f"{source}: options[{i}].{key} = {spec[key]!r} must be > 0 {unit} "
                                  f"({where}, a {kind})")
    if spec.get("retention") is None:
        for key in kind_class.geometry_fields:
            if spec.get(key) is None:
                raise MitigationError(f"{at}: a {kind} needs {key} (its geometry; its retention is "
                                      "derived by simulation) or a typed retention (an assumption)")
    kind_class.check_effect_spec(kind, spec, at)
    if spec.get("min_mass_kg") is not None and spec.get("max_mass_kg") is not None \
            and spec["min_mass_kg"] > spec["max_mass_kg"]:
        raise MitigationError(f"{source}: {where}: min_mass_kg = {spec['min_mass_kg']!r} is greater than "
                              f"max_mass_kg = {spec['max_mass_kg']!r}")
    if spec.get("retention_range") is not None and spec.get("retention") is None:
        raise MitigationError(f"{source}: {where}: retention_range needs a typed retention (a derived retention "
                              "carries its own Monte Carlo uncertainty)")
    if spec.get("rate_reduction_range") is not None and spec.get("rate_reduction") is None:
        raise MitigationError(f"{source}: {where}: rate_reduction_range needs a typed rate_reduction")
    for fld in ("capital_cost", "annual_maintenance", "retention", "rate_reduction"):
        rng = vals.get(f"{fld}_range")
        if rng is not None and spec.get(fld) is not None and not rng[0] <= spec[fld] <= rng[1]:
            raise MitigationError(f"{source}: {where}: {fld} = {spec[fld]!r} lies outside {fld}_range = "
                                  f"{list(rng)}")
    if spec.get("life_years") == 0:
        raise MitigationError(f"{source}: {where}: life_years must be > 0")
    kind_class.finish_spec(kind, spec, vals, at)
    return Option(**vals)


def _check_combinations(options, source):
    names = [o.name for o in options]
    for o in options:
        if o.kind != "combined":
            continue
        for c in o.options:
            if c not in names:
                close = difflib.get_close_matches(c, names, n=1)
                raise MitigationError(f"{source}: option {o.name!r}: options names unknown option {c!r}"
                                      + (f"; did you mean {close[0]!r}?" if close else f"; options are {names}"))
            comp = options[names.index(c)]
            if comp.kind in ("combined", "none"):
                raise MitigationError(f"{source}: option {o.name!r}: component {c!r} is of kind {comp.kind!r}; "
                                      "combine measures only")
        if len(set(o.options)) != len(o.options):
            raise MitigationError(f"{source}: option {o.name!r}: options lists a component twice")
        ditches = [options[names.index(c)] for c in o.options if options[names.index(c)].kind == "ditch"
                   and options[names.index(c)].retention is None]
        try:
            from .measures import check_ditches_disjoint
            check_ditches_disjoint([Ditch(d.x_m, d.width_m, d.depth_m, option=d.name) for d in ditches],
                                   f"{source}: option {o.name!r}")
        except MeasureError as exc:
            raise MitigationError(str(exc)) from exc


def _uncertainty(data: dict, source: str, used: list) -> Uncertainty:
    allowed = ({f.name for f in fields(Uncertainty)} - {"calibration", "calibration_source"}) \
        | {"calibration_bootstrap"}
    if not isinstance(data, dict):
        raise MitigationError(f"{source}: [uncertainty] must be a table")
    for key in data:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1)
            raise MitigationError(f"{source}: unknown field uncertainty.{key}"
                                  + (f"; did you mean {close[0]!r}?" if close else f"; allowed: {sorted(allowed)}"))
    vals = {}
    for key, v in data.items():
        w = f"{source}: uncertainty.{key}"
        if key == "ensemble_replicates":
            if isinstance(v, bool) or not isinstance(v, int) or v < 0 or v == 1:
                raise MitigationError(f"{w} = {v!r} must be 0 (off) or a whole number >= 2 (a variance needs two "
                                      "replicates)")
            vals[key] = v
        elif key == "precision_target":
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < v <= 1:
                raise MitigationError(f"{w} = {v!r} must be a share of the expected cost > 0 and <= 1 (0.05: "
                                      "+-5 % at 2 standard errors)")
            vals[key] = float(v)
        elif key in ("max_samples", "max_material_draws"):
            if isinstance(v, bool) or not isinstance(v, int) or v < 2:
                raise MitigationError(f"{w} = {v!r} must be a whole number >= 2 (a standard error needs at least "
                                      "two)")
            vals[key] = v
        elif key == "ensemble_effort":
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < v <= 1:
                raise MitigationError(f"{w} = {v!r} must be a share of the blocks > 0 and <= 1")
            vals[key] = float(v)
        elif key in ("samples", "seed", "material_draws", "fragmentation_iterations", "draw_blocks"):
            if isinstance(v, bool) or not isinstance(v, int) or v < (0 if key == "seed" else 1):
                raise MitigationError(f"{w} = {v!r} must be a whole number {'>= 0' if key == 'seed' else '>= 1'}")
            if key == "fragmentation_iterations" and v > 12:
                raise MitigationError(f"{w} = {v!r} must be a whole number of generations between 1 and 12")
            vals[key] = v
        elif key == "materials":
            if not isinstance(v, dict):
                raise MitigationError(f"{w} must be a table of \"material.parameter\" = [low, high]")
            mats = {}
            for path, rng in v.items():
                name, _, fld = str(path).partition(".")
                from .measures import MATERIAL_FIELDS
                if not name or fld not in MATERIAL_FIELDS:
                    raise MitigationError(f"{w}: {path!r} must be \"material.parameter\" with parameter one of "
                                          f"{', '.join(MATERIAL_FIELDS)}")
                mats[str(path)] = _range(rng, f"{w}.{path}")
            vals[key] = mats
        elif key == "calibration_bootstrap":
            base = Path(source).parent if Path(source).is_file() else Path(".")
            path = base / str(v)
            if not path.is_file():
                raise MitigationError(f"{w} = {v!r}: file not found ({path.resolve()}); give the bootstrap.csv "
                                      "written by riskrf calibrate or the posterior.csv of riskrf calibrate-pooled")
            df = pd.read_csv(path, comment="#")       # a pooled posterior's first line is a comment
            from .measures import MATERIAL_FIELDS
            if len(df) < 2:
                raise MitigationError(f"{w} = {v!r}: needs at least 2 bootstrap rows; got {len(df)}")
            from simulation.materials import parameter_materials
            for col in df.columns:
                if len(parameter_materials(col)) != 1 or col.split(".", 2)[2] not in MATERIAL_FIELDS:
                    raise MitigationError(f"{w} = {v!r}: column {col!r} is not a material parameter "
                                          "(materials.NAME.FIELD with one material NAME, not a shared 'A+B', and "
                                          f"FIELD one of {', '.join(MATERIAL_FIELDS)})")
                if not np.all(np.isfinite(pd.to_numeric(df[col], errors="coerce"))):
                    raise MitigationError(f"{w} = {v!r}: column {col!r} has values that are not finite numbers")
            vals["calibration"] = df.astype(float)
            vals["calibration_source"] = str(v)
        elif key in ("sample_power_law", "sample_retention"):
            if not isinstance(v, bool):
                raise MitigationError(f"{w} = {v!r} must be true or false")
            vals[key] = v
        else:
            lo, hi = _range(v, w)
            if key in ("rate_factor", "m_max_kg", "vehicles_per_day", "value_of_statistical_life",
                       "vulnerability_factor") and lo <= 0:
                raise MitigationError(f"{w} = {v!r}: low must be > 0")
            if key == "discount_rate" and hi >= 1:
                raise MitigationError(f"{w} = {v!r}: rates lie below 1 (e.g. [0.01, 0.05])")
            if key == "fractal_dimension" and not 0 < lo <= hi < 3:
                raise MitigationError(f"{w} = {v!r}: the fractal dimension lies strictly between 0 and 3 "
                                      "(rock fragmentation typically 2-3)")
            vals[key] = (lo, hi)
    if vals.get("calibration") is not None and vals.get("materials"):
        raise MitigationError(f"{source}: give uncertainty.materials or uncertainty.calibration_bootstrap, not both")
    d = Uncertainty()
    for budget, start in (("max_samples", "samples"), ("max_material_draws", "material_draws")):
        first = vals.get(start, getattr(d, start))
        if budget not in vals:
            vals[budget] = max(getattr(d, budget), first)
        elif vals[budget] < first:
            raise MitigationError(f"{source}: uncertainty.{budget} = {vals[budget]!r} is below uncertainty.{start} "
                                  f"= {first!r}: the budget must allow at least the effort the study starts with")
    for f in fields(Uncertainty):
        if f.name in ("calibration", "calibration_source"):
            continue
        if f.name not in data and f.name not in ("calibration_bootstrap",):
            used.append(f"uncertainty.{f.name} = {vals.get(f.name, getattr(d, f.name))!r} (default)")
    return Uncertainty(**vals)


def parse_mitigation(data: dict, source: str = "<dict>", *, require_options: bool = True) -> tuple:
    """Validate a mitigation table: returns (options, exposure, consequences, economics, defaults_used,
    uncertainty, criteria).  ``require_options=False``: no [[options]] is accepted (a site on 3-D terrain,
    whose traffic and consequences are used without ranking options).

    Parameters
    ----------
    data : dict
        The tables ``[[options]]``, ``[traffic]``, ``[consequences]``, ``[economics]``, ``[uncertainty]`` and
        ``[criteria]`` as read from TOML.
    source : str, optional
        The file they were read from (named in errors).
    require_options : bool, optional
        Require at least two options.

    Returns
    -------
    tuple
        ``(options, exposure, consequences, economics, defaults_used, uncertainty, criteria)``: a tuple of
        :class:`Option`, :class:`Exposure`, :class:`Consequences`, :class:`Economics`, the names of the defaults
        used, :class:`Uncertainty` and :class:`Criteria`.

    Raises
    ------
    MitigationError
        Naming the source, table and field with its value.
    """
    allowed = {"options", "traffic", "consequences", "economics", "uncertainty", "criteria"}
    for key in data:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1)
            raise MitigationError(f"{source}: unknown table [{key}]" + (f"; did you mean [{close[0]}]?" if close
                                                                       else f"; allowed: {sorted(allowed)}"))
    used: list = []
    tr = dict(_table(data.get("traffic", {}), Exposure, "traffic", source, used,
                     special=("occupants_distribution", "lane_fall_shares")))
    if "lanes" in tr and (int(tr["lanes"]) != tr["lanes"] or tr["lanes"] < 1):
        raise MitigationError(f"{source}: traffic.lanes = {tr['lanes']!r} must be a whole number >= 1")
    if tr.get("directional_split", 0.5) > 1:
        raise MitigationError(f"{source}: traffic.directional_split = {tr['directional_split']!r} must lie in [0, 1]")
    if "lane_fall_shares" in tr:
        fs = tr["lane_fall_shares"]
        ok = isinstance(fs, list) and len(fs) == int(tr.get("lanes", 2)) and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and 0 <= x <= 1 for x in fs)
        if not ok or abs(sum(fs) - 1) > 1e-6:
            raise MitigationError(f"{source}: traffic.lane_fall_shares = {fs!r} must list one share in [0, 1] per "
                                  f"lane ({int(tr.get('lanes', 2))}), nearest the slope first, summing to 1")
        tr["lane_fall_shares"] = tuple(float(x) for x in fs)
    if "lanes" in tr:
        tr["lanes"] = int(tr["lanes"])
    if "occupants_distribution" in tr:
        try:
            occupancy_distribution(tr.get("occupants_per_vehicle", 1.5), tr["occupants_distribution"])
        except (ValueError, TypeError) as exc:
            raise MitigationError(f"{source}: traffic.{exc}") from exc
    if tr.get("occupants_per_vehicle", 1.5) < 1:
        raise MitigationError(f"{source}: traffic.occupants_per_vehicle = {tr['occupants_per_vehicle']!r} must be "
                              ">= 1 (the driver)")
    exposure = Exposure(**tr)
    cq = dict(_table(data.get("consequences", {}), Consequences, "consequences", source, used,
                     special=("vulnerability_moving_vehicle", "vulnerability_striking_rock")))
    for key in ("vulnerability_moving_vehicle", "vulnerability_striking_rock"):
        if key in cq:
            cq[key] = _vulnerability(cq[key], f"{source}: consequences.{key}")
    consequences = Consequences(**cq)
    for key in ("vulnerability_moving_vehicle", "vulnerability_striking_rock"):
        if key not in cq:
            curve = ", ".join(f"{sig(p)} at {sig(m)} kg" for m, p in getattr(consequences, key))
            used.append(f"consequences.{key}: probability of death by block mass {curve}, chosen to match the "
                        "Hong Kong CEDD/GEO register (the road-user model's default vulnerability)")
    economics = Economics(**_table(data.get("economics", {}), Economics, "economics", source, used))
    if not economics.horizon_years > 0:
        raise MitigationError(f"{source}: economics.horizon_years = {economics.horizon_years!r} must be > 0 years "
                              "(the period over which costs and losses are counted)")
    if economics.discount_rate >= 1:
        raise MitigationError(f"{source}: economics.discount_rate = {economics.discount_rate!r} must be a rate "
                              "below 1 (e.g. 0.03)")
    crit = dict(_table(data.get("criteria", {}), Criteria, "criteria", source, used,
                       special=("fn_diagram", "set", "slope", "individual_risk_per_year", "fn_c", "fn_acceptable_c",
                                "marginal_cost_per_life")))
    for key in ("individual_risk_per_year", "fn_c", "fn_acceptable_c", "marginal_cost_per_life"):
        v = crit.get(key)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v <= 0):
            raise MitigationError(f"{source}: criteria.{key} = {v!r} must be a number > 0")
    for key in ("set", "slope"):
        if key in crit and not isinstance(crit[key], str):
            raise MitigationError(f"{source}: criteria.{key} = {crit[key]!r} must be a string")
    try:
        criteria = Criteria(**crit)
    except MitigationError as exc:
        raise MitigationError(f"{source}: {exc}") from None
    uncertainty = _uncertainty(data.get("uncertainty", {}), source, used)
    specs = data.get("options", [])
    if not isinstance(specs, list) or (len(specs) < 2 and (require_options or specs)):
        raise MitigationError(f"{source}: [[options]] needs at least two options to compare")
    options = tuple(parse_option(s, i, source) for i, s in enumerate(specs))
    names = [o.name for o in options]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise MitigationError(f"{source}: duplicate option name(s) {sorted(dup)}")
    _check_combinations(options, source)
    from ..core.file_schemas import OPTIONS_SCHEMA
    from ..core.schema import check
    check(data, OPTIONS_SCHEMA, source, error=MitigationError)     # every declared type and range
    return options, exposure, consequences, economics, tuple(used), uncertainty, criteria


def study_inputs(data: dict, source: str, *, require_options: bool = True) -> dict:
    """Keyword arguments of :class:`~riskrf.risk.mitigation.MitigationStudy` from a parsed mitigation (or site) table
    (``require_options=False``: none needed, :func:`parse_mitigation`).

    Parameters
    ----------
    data : dict
        The parsed TOML tables of the mitigation (or site) file.
    source : str
        The file, named in errors.
    require_options : bool, optional
        Whether ``[[option]]`` entries are required (default True).

    Returns
    -------
    dict
        ``options``, ``exposure``, ``consequences``, ``economics``, ``defaults_used``, ``uncertainty`` and
        ``criteria``.
    """
    options, exposure, consequences, economics, used, uncertainty, criteria = parse_mitigation(
        data, source, require_options=require_options)
    return {"options": options, "exposure": exposure, "consequences": consequences, "economics": economics,
            "defaults_used": used, "uncertainty": uncertainty, "criteria": criteria}


def check_mitigation_file(path):
    """Read and check a mitigation TOML file (a site file works too) before any work: every table and option
    against its declaration and rules, and a closure rule's [rates] table.  Returns (study inputs, the parsed
    TOML, the checked [rates] or None when no closure rule needs it).

    Parameters
    ----------
    path : str or pathlib.Path
        The mitigation or site TOML file.

    Returns
    -------
    inputs : dict
        Keyword arguments of :class:`~riskrf.risk.mitigation.MitigationStudy` (:func:`study_inputs`).
    raw : dict
        The parsed TOML.
    rates : SiteRatesTable or None
        The checked ``[rates]`` table (:func:`riskrf.risk.site_rates.check_rates`), or None.

    Raises
    ------
    FileNotFoundError
        When ``path`` does not exist.
    MitigationError
        Invalid TOML, or a table, option or ``[rates]`` entry that does not fit its declaration.
    """
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
        # closure rules: share and hours from the file's [rates] model (riskrf.risk.site_rates)
        from .site_rates import check_closure_options, check_rates, inventory_record
        rates, _ = check_rates(raw.get("rates"), inventory_record(raw.get("inventory")), path,
                               error=MitigationError)
        check_closure_options(inputs["options"], rates, path, error=MitigationError)
    return inputs, raw, rates
