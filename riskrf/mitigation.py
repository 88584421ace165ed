"""Mitigation options ranked by expected total cost (Wyllie 2014, 8.5.5; Wyllie, McCammon & Brumund 1980).

    expected total cost = capital + PV(renewals) + PV(maintenance + repairs) + PV(expected losses)

Each option leaves a residual hazard, the falls that still reach the road each
year, built from the energy hazard at the barrier line:

* ``none`` (do nothing): every arriving fall;
* ``scaling`` (scaling and bolting): the rate of falls cut by ``rate_reduction``;
* ``ditch``: retains a share ``retention`` of arriving falls, or every fall up to ``max_mass_kg``;
* ``fence`` / ``attenuator`` (``capacity_kj``, ``height_m``): falls passing over
  (bounce height above the fence) or through (energy above the capacity), from the
  simulated heights and velocities paired block by block; impacts it holds above
  its service energy (MEL/3) cost a repair each;
* ``shed`` (``capacity_kj``): falls with energy above its capacity;
* ``realignment``: removes the exposure.

Losses per fall reaching the road: a moving vehicle at the impact point (Bunce et
al. 1997, P(S:T)), a vehicle striking a rock left on the road, occupants killed
with the given vulnerabilities at the value of a statistical life, vehicle
damage, and closure and clean-up costs.  All inputs come from a TOML file
documented in the README ("Mitigation files").
"""
from __future__ import annotations

import difflib
import tomllib
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np
import pandas as pd

from .annual_hazard import EnergyHazard
from .barriers import service_energy_level
from .impact_energy import mass_model
from .road_risk import (
    individual_risk,
    pv_factor,
    pv_of_renewals,
    spatial_temporal_probability,
    stationary_rock_strike_probability,
    vehicle_occupant_fn,
)
from .units import mass_for_energy_kg

OPTION_KINDS = ("none", "scaling", "ditch", "fence", "attenuator", "shed", "realignment")


class MitigationError(ValueError):
    """A mitigation file or option is invalid; the message names the option and field."""


@dataclass(frozen=True)
class Exposure:
    """Traffic on the exposed road section."""

    vehicles_per_day: float = 4000.0
    vehicle_length_m: float = 5.0
    speed_kmh: float = 80.0
    occupants_per_vehicle: float = 1.5
    commuter_trips_per_day: float = 2.0
    hours_rock_on_road: float = 0.5
    p_cannot_stop: float = 0.002
    share_stopping_on_road: float = 0.3


@dataclass(frozen=True)
class Consequences:
    """Costs of consequences (in ``currency``) and vulnerabilities (probability of death)."""

    value_of_statistical_life: float = 5.0e6
    vulnerability_moving_vehicle: float = 0.5
    vulnerability_striking_rock: float = 0.1
    vehicle_damage: float = 25000.0
    closure_days_per_fall: float = 0.5
    closure_cost_per_day: float = 20000.0
    cleanup_cost_per_fall: float = 3000.0
    currency: str = "CHF"


@dataclass(frozen=True)
class Economics:
    discount_rate: float = 0.03
    horizon_years: float = 50.0


@dataclass(frozen=True)
class Option:
    name: str
    kind: str
    capital_cost: float
    annual_maintenance: float = 0.0
    life_years: float | None = None
    repair_cost_per_impact: float = 0.0
    rate_reduction: float | None = None
    retention: float | None = None
    max_mass_kg: float | None = None
    capacity_kj: float | None = None
    height_m: float | None = None
    description: str = ""


@dataclass(frozen=True)
class OptionResult:
    option: Option
    road_falls_per_year: float
    held_impacts_above_sel_per_year: float
    vehicle_hits_per_year: float
    rock_strikes_per_year: float
    deaths_per_year: float
    expected_annual_loss: float
    individual_risk: float


@dataclass(frozen=True)
class MitigationStudy:
    """A hazard at the barrier line, the road exposure, consequences, economics and options."""

    hazard: EnergyHazard
    options: tuple
    exposure: Exposure = Exposure()
    consequences: Consequences = Consequences()
    economics: Economics = Economics()
    road_share: float = 1.0            # P(reaches the road | reaches the barrier line)
    source: str = "<dict>"
    defaults_used: tuple = field(default_factory=tuple)

    # ---- residual hazard ---------------------------------------------------------------
    def _paired_samples(self):
        v = self.hazard.velocity
        v = np.asarray(getattr(v, "velocity_ms", v), dtype=float)
        h = self.hazard.heights_m
        if h is None or len(h) != len(v):
            raise MitigationError(f"{self.source}: fences and attenuators need simulated velocities paired with "
                                  "bounce heights (build the hazard with EnergyHazard.from_simulation)")
        return v, np.asarray(h, dtype=float)

    def evaluate(self, option: Option) -> OptionResult:
        hz = self.hazard
        arrivals = hz.arrival_rate            # falls per year at the barrier line
        mm = mass_model(hz.mass)
        held_above_sel = 0.0
        kind = option.kind
        if kind == "none":
            passing = 1.0
        elif kind == "scaling":
            passing = 1.0 - option.rate_reduction
        elif kind == "ditch":
            passing = (1.0 - option.retention) if option.retention is not None \
                else float(mm.sf(option.max_mass_kg))
        elif kind in ("fence", "attenuator"):
            v, h = self._paired_samples()
            over = h > option.height_m
            through = mm.sf(mass_for_energy_kg(option.capacity_kj, v))
            passing = float(np.mean(np.where(over, 1.0, through)))
            above_sel = mm.sf(mass_for_energy_kg(service_energy_level(option.capacity_kj), v))
            held_above_sel = arrivals * float(np.mean(np.where(over, 0.0, above_sel - through)))
        elif kind == "shed":
            passing = float(hz.exceedance_probability(option.capacity_kj))
        else:   # realignment
            passing = 0.0
        road = arrivals * passing * self.road_share
        ex, co = self.exposure, self.consequences
        p_st = spatial_temporal_probability(ex.vehicles_per_day, ex.vehicle_length_m, ex.speed_kmh)
        hits = road * p_st
        strikes = road * ex.share_stopping_on_road * stationary_rock_strike_probability(
            ex.vehicles_per_day, ex.hours_rock_on_road, ex.p_cannot_stop)
        deaths = ex.occupants_per_vehicle * (hits * co.vulnerability_moving_vehicle
                                             + strikes * co.vulnerability_striking_rock)
        eal = (deaths * co.value_of_statistical_life + (hits + strikes) * co.vehicle_damage
               + road * (co.closure_days_per_fall * co.closure_cost_per_day + co.cleanup_cost_per_fall))
        ir = individual_risk(road, ex.commuter_trips_per_day, ex.vehicle_length_m, ex.speed_kmh,
                             co.vulnerability_moving_vehicle)
        return OptionResult(option, road, held_above_sel, hits, strikes, deaths, eal, ir)

    # ---- ranking ---------------------------------------------------------------------
    def ranking(self) -> pd.DataFrame:
        """The ranking table: costs, expected losses, residual hazard, risk, benefit-cost ratio, rank."""
        ec = self.economics
        pvf = pv_factor(ec.discount_rate, ec.horizon_years)
        rows = []
        for opt in self.options:
            r = self.evaluate(opt)
            renew = pv_of_renewals(opt.capital_cost, opt.life_years, ec.horizon_years, ec.discount_rate) \
                if opt.life_years else 0.0
            pv_maint = pvf * (opt.annual_maintenance + r.held_impacts_above_sel_per_year * opt.repair_cost_per_impact)
            pv_loss = pvf * r.expected_annual_loss
            rows.append({"option": opt.name, "kind": opt.kind, "capital": opt.capital_cost + renew,
                         "pv_maintenance": pv_maint, "pv_expected_loss": pv_loss,
                         "expected_total_cost": opt.capital_cost + renew + pv_maint + pv_loss,
                         "road_falls_per_year": r.road_falls_per_year, "deaths_per_year": r.deaths_per_year,
                         "individual_risk": r.individual_risk})
        df = pd.DataFrame(rows)
        base = df[df["kind"] == "none"]
        if len(base):
            b = base.iloc[0]
            spend = df["capital"] + df["pv_maintenance"] - (b["capital"] + b["pv_maintenance"])
            saved = b["pv_expected_loss"] - df["pv_expected_loss"]
            with np.errstate(divide="ignore", invalid="ignore"):
                df["benefit_cost_ratio"] = np.where(spend > 0, saved / spend, np.nan)
        df = df.sort_values("expected_total_cost").reset_index(drop=True)
        df["rank"] = np.arange(1, len(df) + 1)
        return df

    def best(self) -> str:
        return self.ranking()["option"].iloc[0]

    # ---- sensitivity -------------------------------------------------------------------
    def _scaled(self, parameter: str, factor: float) -> "MitigationStudy":
        """A copy with one input multiplied by ``factor`` (parameters of tornado() and break_even())."""
        if parameter == "fall_rate":
            return replace(self, hazard=replace(self.hazard, rate_per_year=self.hazard.rate_per_year * factor))
        if parameter in {f.name for f in fields(Exposure)}:
            return replace(self, exposure=replace(self.exposure, **{parameter: getattr(self.exposure, parameter)
                                                                     * factor}))
        if parameter in {f.name for f in fields(Consequences)} - {"currency"}:
            return replace(self, consequences=replace(self.consequences,
                                                      **{parameter: getattr(self.consequences, parameter) * factor}))
        if parameter in ("discount_rate", "horizon_years"):
            return replace(self, economics=replace(self.economics,
                                                   **{parameter: getattr(self.economics, parameter) * factor}))
        if parameter.startswith("capital_cost:"):
            name = parameter.split(":", 1)[1]
            opts = tuple(replace(o, capital_cost=o.capital_cost * factor) if o.name == name else o
                         for o in self.options)
            return replace(self, options=opts)
        raise MitigationError(f"unknown sensitivity parameter {parameter!r}")

    def sensitivity_parameters(self) -> list:
        return ["fall_rate", "value_of_statistical_life", "vehicles_per_day", "vulnerability_moving_vehicle",
                "discount_rate"] + [f"capital_cost:{o.name}" for o in self.options if o.capital_cost > 0]

    def tornado(self, low: float = 0.5, high: float = 2.0) -> pd.DataFrame:
        """Swing of the lowest expected total cost as each input is multiplied by ``low`` and ``high``."""
        base = self.ranking()["expected_total_cost"].iloc[0]
        rows = []
        for p in self.sensitivity_parameters():
            lo_rank, hi_rank = self._scaled(p, low).ranking(), self._scaled(p, high).ranking()
            rows.append({"parameter": p, "factor_low": low, "factor_high": high,
                         "cost_at_low": lo_rank["expected_total_cost"].iloc[0],
                         "cost_at_high": hi_rank["expected_total_cost"].iloc[0],
                         "best_at_low": lo_rank["option"].iloc[0], "best_at_high": hi_rank["option"].iloc[0],
                         "base": base})
        df = pd.DataFrame(rows)
        df["swing"] = (df["cost_at_high"] - df["cost_at_low"]).abs()
        return df.sort_values("swing", ascending=False).reset_index(drop=True)

    def break_even(self, parameter: str, *, option_a: str | None = None, option_b: str | None = None,
                   factor_range=(1e-3, 1e3)):
        """Multiplier of ``parameter`` at which the best and second options (or a and b) cost the same.

        Returns (factor, value) or None if they do not cross within ``factor_range``.
        """
        if option_a is None or option_b is None:
            rank = self.ranking()["option"]
            option_a, option_b = option_a or rank.iloc[0], option_b or rank.iloc[1]
        a, b = option_a, option_b

        def diff(log_f):
            try:
                t = self._scaled(parameter, float(np.exp(log_f))).ranking().set_index("option")
            except ValueError:          # e.g. traffic so dense that P(S:T) >= 1: outside the model
                return np.nan
            return t["expected_total_cost"][a] - t["expected_total_cost"][b]
        lo, hi = np.log(factor_range[0]), np.log(factor_range[1])
        grid = np.linspace(lo, hi, 61)
        vals = [diff(g) for g in grid]
        for g0, g1, v0, v1 in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
            if np.isfinite(v0) and np.isfinite(v1) and np.sign(v0) != np.sign(v1):
                from scipy.optimize import brentq
                f = float(np.exp(brentq(diff, g0, g1, xtol=1e-10)))
                return f, self._parameter_value(parameter) * f
        return None

    def _parameter_value(self, parameter: str) -> float:
        if parameter == "fall_rate":
            return self.hazard.rate_per_year
        for obj in (self.exposure, self.consequences, self.economics):
            if hasattr(obj, parameter):
                return float(getattr(obj, parameter))
        name = parameter.split(":", 1)[1]
        return next(o.capital_cost for o in self.options if o.name == name)

    def break_even_table(self) -> pd.DataFrame:
        """For every sensitivity parameter: the value at which the second option would tie with the best."""
        rank = self.ranking()
        a, b = rank["option"].iloc[0], rank["option"].iloc[1]
        rows = []
        for p in self.sensitivity_parameters():
            be = self.break_even(p, option_a=a, option_b=b)
            rows.append({"parameter": p, "current": self._parameter_value(p),
                         "break_even": be[1] if be else np.nan, "factor": be[0] if be else np.nan,
                         "note": f"{b!r} ties with {a!r}" if be else "no tie within x0.001-x1000"})
        return pd.DataFrame(rows)

    def value_of_information(self, factors=(0.5, 1.0, 2.0), weights=(0.25, 0.5, 0.25)) -> dict:
        """Expected value of perfect information about the rate of falls.

        The rate is uncertain by more than its Poisson error (the share of the source
        above the road, completeness, changes with time); ``factors`` and ``weights``
        give a discrete distribution of the true rate relative to the estimate
        (default: half, as estimated, double with probabilities 1/4, 1/2, 1/4).  EVPI =
        cost of the best option chosen now minus the expected cost of choosing after
        learning the rate: the most a monitoring programme that settles it is worth.
        """
        f = np.asarray(factors, dtype=float)
        w = np.asarray(weights, dtype=float)
        if f.shape != w.shape or np.any(f <= 0) or np.any(w < 0) or abs(w.sum() - 1) > 1e-9:
            raise MitigationError(f"value_of_information: factors {f.tolist()} must be > 0 and weights {w.tolist()} "
                                  "non-negative, as many, summing to 1")
        tables = [self._scaled("fall_rate", x).ranking().set_index("option")["expected_total_cost"] for x in f]
        expected = sum(wi * t for wi, t in zip(w, tables))
        now = expected.idxmin()
        informed = float(sum(wi * t.min() for wi, t in zip(w, tables)))
        return {"evpi": float(expected[now] - informed), "best_now": now,
                "expected_cost_now": float(expected[now]), "expected_cost_informed": informed,
                "best_by_rate": {f"x{x:g}": t.idxmin() for x, t in zip(f, tables)},
                "factors": f.tolist(), "weights": w.tolist()}

    # ---- societal risk and tree --------------------------------------------------------
    def fn_curve(self, option: str) -> pd.DataFrame:
        opt = next((o for o in self.options if o.name == option), None)
        if opt is None:
            raise MitigationError(f"no option named {option!r}; options are {[o.name for o in self.options]}")
        r = self.evaluate(opt)
        return vehicle_occupant_fn(r.vehicle_hits_per_year, self.exposure.occupants_per_vehicle,
                                   self.consequences.vulnerability_moving_vehicle)

    def to_tree(self):
        """The decision tree of this study (costs in present value), for rollback, diagrams and EVPI.

        Under each option, a chance node gives the outcome of one fall reaching the
        road; branch costs are that outcome's cost times the discounted expected
        number of such falls over the horizon, so the rollback equals the ranking.
        """
        from .decision_tree import DecisionTree
        ec, ex, co = self.economics, self.exposure, self.consequences
        pvf = pv_factor(ec.discount_rate, ec.horizon_years)
        p_st = spatial_temporal_probability(ex.vehicles_per_day, ex.vehicle_length_m, ex.speed_kmh)
        p_strike = ex.share_stopping_on_road * stationary_rock_strike_probability(
            ex.vehicles_per_day, ex.hours_rock_on_road, ex.p_cannot_stop)
        per_fall = co.closure_days_per_fall * co.closure_cost_per_day + co.cleanup_cost_per_fall
        ranking = self.ranking().set_index("option")
        branches = []
        for opt in self.options:
            r = self.evaluate(opt)
            n_pv = pvf * r.road_falls_per_year
            row = ranking.loc[opt.name]
            outcomes = [
                {"name": "vehicle hit", "probability": p_st,
                 "cost": n_pv * (per_fall + co.vehicle_damage + ex.occupants_per_vehicle
                                 * co.vulnerability_moving_vehicle * co.value_of_statistical_life)},
                {"name": "vehicle strikes rock on road", "probability": p_strike,
                 "cost": n_pv * (per_fall + co.vehicle_damage + ex.occupants_per_vehicle
                                 * co.vulnerability_striking_rock * co.value_of_statistical_life)},
                {"name": "closure and clean-up only", "probability": 1 - p_st - p_strike, "cost": n_pv * per_fall}]
            branches.append({"name": opt.name, "cost": float(row["capital"] + row["pv_maintenance"]),
                             "child": {"type": "chance", "name": "each fall reaching the road",
                                       "branches": outcomes}})
        return DecisionTree.from_dict({"type": "decision", "name": "mitigation", "objective": "min",
                                       "branches": branches}, source=self.source)

    @property
    def currency(self) -> str:
        return self.consequences.currency


def _table(data: dict, cls, where: str, source: str, used: list):
    names = {f.name for f in fields(cls)}
    unknown = set(data) - names
    if unknown:
        key = sorted(unknown)[0]
        close = difflib.get_close_matches(key, names, n=1)
        raise MitigationError(f"{source}: unknown field {where}.{key}" + (f"; did you mean {close[0]!r}?" if close
                                                                         else f"; allowed: {sorted(names)}"))
    for f in fields(cls):
        if f.name not in data:
            used.append(f"{where}.{f.name} = {getattr(cls(), f.name)!r} (default)")
        elif f.name != "currency":
            v = data[f.name]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v < 0:
                raise MitigationError(f"{source}: {where}.{f.name} = {v!r} must be a number >= 0")
    return cls(**data)


def parse_option(spec: dict, i: int, source: str) -> Option:
    where = f"options[{i}]"
    if not isinstance(spec, dict):
        raise MitigationError(f"{source}: {where} must be a table")
    name = spec.get("name")
    if not name:
        raise MitigationError(f"{source}: {where} needs a name")
    where = f"option {name!r}"
    allowed = {f.name for f in fields(Option)}
    unknown = set(spec) - allowed
    if unknown:
        key = sorted(unknown)[0]
        close = difflib.get_close_matches(key, allowed, n=1)
        raise MitigationError(f"{source}: {where}: unknown field {key!r}" + (f"; did you mean {close[0]!r}?"
                                                                            if close else ""))
    kind = spec.get("kind")
    if kind not in OPTION_KINDS:
        raise MitigationError(f"{source}: {where}: kind = {kind!r} is not one of {', '.join(OPTION_KINDS)}")
    if "capital_cost" not in spec:
        raise MitigationError(f"{source}: {where}: missing field 'capital_cost' (use 0 for none)")
    for key in ("capital_cost", "annual_maintenance", "life_years", "repair_cost_per_impact", "rate_reduction",
                "retention", "max_mass_kg", "capacity_kj", "height_m"):
        v = spec.get(key)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v < 0):
            raise MitigationError(f"{source}: {where}: {key} = {v!r} must be a number >= 0")
    need = {"scaling": ("rate_reduction",), "fence": ("capacity_kj", "height_m"),
            "attenuator": ("capacity_kj", "height_m"), "shed": ("capacity_kj",)}.get(kind, ())
    for key in need:
        if spec.get(key) is None:
            raise MitigationError(f"{source}: {where}: a {kind} needs {key}")
    for key in ("rate_reduction", "retention"):
        if spec.get(key) is not None and spec[key] > 1:
            raise MitigationError(f"{source}: {where}: {key} = {spec[key]!r} is a share and must lie in [0, 1]")
    if kind == "ditch" and (spec.get("retention") is None) == (spec.get("max_mass_kg") is None):
        raise MitigationError(f"{source}: {where}: a ditch needs exactly one of retention or max_mass_kg")
    if spec.get("life_years") == 0:
        raise MitigationError(f"{source}: {where}: life_years must be > 0")
    return Option(**{k: (float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v)
                     for k, v in spec.items()})


def parse_mitigation(data: dict, source: str = "<dict>") -> tuple:
    """Validate a mitigation table: returns (options, exposure, consequences, economics, defaults_used)."""
    allowed = {"options", "traffic", "consequences", "economics"}
    for key in data:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1)
            raise MitigationError(f"{source}: unknown table [{key}]" + (f"; did you mean [{close[0]}]?" if close
                                                                       else f"; allowed: {sorted(allowed)}"))
    used: list = []
    exposure = _table(data.get("traffic", {}), Exposure, "traffic", source, used)
    consequences = _table(data.get("consequences", {}), Consequences, "consequences", source, used)
    economics = _table(data.get("economics", {}), Economics, "economics", source, used)
    if economics.discount_rate >= 1:
        raise MitigationError(f"{source}: economics.discount_rate = {economics.discount_rate!r} must be a rate "
                              "below 1 (e.g. 0.03)")
    specs = data.get("options", [])
    if not isinstance(specs, list) or len(specs) < 2:
        raise MitigationError(f"{source}: [[options]] needs at least two options to compare")
    options = tuple(parse_option(s, i, source) for i, s in enumerate(specs))
    names = [o.name for o in options]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise MitigationError(f"{source}: duplicate option name(s) {sorted(dup)}")
    return options, exposure, consequences, economics, tuple(used)


def load_mitigation(path, hazard: EnergyHazard, *, road_share: float = 1.0) -> MitigationStudy:
    """Read a mitigation TOML file and combine it with an energy hazard."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"mitigation file not found: {path}")
    with open(path, "rb") as fh:
        try:
            data = tomllib.load(fh)
        except tomllib.TOMLDecodeError as exc:
            raise MitigationError(f"{path}: not valid TOML: {exc}") from exc
    data = {k: v for k, v in data.items() if k not in ("site", "inventory", "hazard")}   # a site file works too
    options, exposure, consequences, economics, used = parse_mitigation(data, str(path))
    return MitigationStudy(hazard=hazard, options=options, exposure=exposure, consequences=consequences,
                           economics=economics, road_share=road_share, source=str(path), defaults_used=used)
