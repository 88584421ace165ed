"""Road users hit by rock falls: Bunce et al. (1997) per lane and direction, vulnerability as a stated model.

Two ways a fall reaching the road kills or injures vehicle occupants, reported separately:

* **direct hit on a moving vehicle**: the block lands in lane i (share ``q_i`` of the falls reaching the
  road) while a vehicle of that lane occupies the impact point.  Bunce, Cruden & Morgenstern (1997, Can.
  Geotech. J. 34: 344-356) give the spatial-temporal probability P(S:T) = N_v L_v / (24 x 1000 x V_v) for
  N_v vehicles a day at V_v km/h of length L_v m.  Their N_v is the traffic that can occupy the impact
  point: the vehicles of the lane the block lands in, not the two-way traffic of the road.  Per lane,

      P(hit) = sum_i q_i N_i L_v / (24 x 1000 x V_i),

  which for n equal lanes sharing N vehicles a day equally is Bunce's two-way value divided by n;
* **a vehicle strikes a rock lying on the road**: the rock stays ``t`` hours in lane i; the first vehicle
  of that lane to arrive meanwhile (probability 1 - exp(-N_i t / 24)) fails to stop with probability ``p``
  (sight distance shorter than stopping distance): P(strike) = sum_i q_i p (1 - exp(-N_i t / 24)).
  ASSUMPTION: once a vehicle has stopped at the rock, the lane is blocked and signalled, so later drivers
  do not meet it unwarned.  (Counting every arriving driver, 1 - exp(-N_i t p / 24), predicts 0.3-0.8
  vehicles striking per fall on Hong Kong's roads against 0.017 vehicles involved per fall recorded.)

Vulnerability, V(D:T): the probability that an occupant of a vehicle involved dies, as a function of the
block's mass (:class:`Vulnerability`); injuries: an occupant who survives is injured with probability
``injury_given_survival``.  The default model (:data:`DEFAULT_VULNERABILITY`) is chosen so that the
predicted deaths and injuries per fall reaching a road match the Hong Kong slope incident register
(CEDD/GEO 1984-2020; :mod:`riskrf.risk.road_validation`, docs/validation/road-risk.md), inside the range
that Finlay et al. (1999) / AGS (2000) give for an occupant of a vehicle "damaged only" (0-0.3) and
reaching the "crushed" range (0.9-1.0) only for falls of 10,000 t.  Literature values beside every
number: :data:`LITERATURE_VULNERABILITY`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..core.units import HOURS_PER_DAY, M_PER_KM

#: Published vulnerability values for occupants of vehicles (probability of death), with where each was read.
#: "evidence": V = read in the source (or a faithful reproduction) in this project; R = recalled, the page was
#: not available here (do not rely on it without the paper).
LITERATURE_VULNERABILITY = pd.DataFrame([
    {"source": "Finlay et al. (1999); AGS (2000)", "situation": "person in vehicle, vehicle damaged only",
     "low": 0.0, "recommended": 0.3, "high": 0.3,
     "where": "table of recommended vulnerability factors, reproduced in 'Design Considerations Based on "
              "Quantitative Risk Assessments for Slopes' p. 47 (online.flipbuilder.com/qjxlt/nkbv)",
     "evidence": "V"},
    {"source": "Finlay et al. (1999); AGS (2000)", "situation": "person in vehicle, vehicle buried or crushed",
     "low": 0.9, "recommended": 1.0, "high": 1.0, "where": "same table, p. 47", "evidence": "V"},
    {"source": "Finlay et al. (1999); AGS (2000)", "situation": "person in open space, struck by a rock fall",
     "low": 0.1, "recommended": 0.5, "high": 0.7, "where": "same table, p. 47", "evidence": "V"},
    {"source": "Hong Kong CEDD/GEO incident register 1984-2020 (rock and soil/rock cuts, road affected)",
     "situation": "deaths per occupant of a vehicle involved (1 death, 12 vehicles involved, ~1.5 occupants)",
     "low": 0.0014, "recommended": 0.056, "high": 0.31,
     "where": "computed here from DEATHNO and CONSEC (riskrf.risk.road_validation); 95 % exact Poisson interval",
     "evidence": "V"},
    {"source": "Bunce, Cruden & Morgenstern (1997)", "situation": "occupant of a vehicle hit (Argillite Cut)",
     "low": np.nan, "recommended": np.nan, "high": np.nan,
     "where": "Can. Geotech. J. 34: 344-356; value not recovered here", "evidence": "R"},
    {"source": "Hungr, Evans & Hazzard (1999)", "situation": "occupant of a vehicle hit (BC highways)",
     "low": np.nan, "recommended": np.nan, "high": np.nan,
     "where": "Can. Geotech. J. 36: 224-238; value not recovered here", "evidence": "R"},
    {"source": "Corominas et al. (2005)", "situation": "vulnerability by damage state (buildings, Andorra)",
     "low": np.nan, "recommended": np.nan, "high": np.nan,
     "where": "Landslides 2: 343-357, abstract (upcommons.upc.edu/handle/2117/13698); vehicle values not given",
     "evidence": "V"},
    {"source": "Ferlisi et al. (2012)", "situation": "occupants of vehicles on the Amalfi coast road SS163",
     "low": np.nan, "recommended": np.nan, "high": np.nan,
     "where": "Nat. Hazards 62: 691-721 (doi 10.1007/s11069-012-0102-z), abstract only; values not recovered",
     "evidence": "V"},
])


@dataclass(frozen=True)
class Lane:
    """One traffic lane: its direction, vehicles a day, speed and the share of the falls reaching the road
    that land in it (``fall_share``; None: the falls spread evenly over the lanes)."""

    direction: str
    vehicles_per_day: float
    speed_kmh: float
    fall_share: float | None = None

    def __post_init__(self):
        for name in ("vehicles_per_day", "speed_kmh"):
            v = getattr(self, name)
            if isinstance(v, bool) or not np.isfinite(v) or v <= 0:
                raise ValueError(f"lane {self.direction!r}: {name} = {v!r} must be a number > 0")
        if self.fall_share is not None and not 0 <= self.fall_share <= 1:
            raise ValueError(f"lane {self.direction!r}: fall_share = {self.fall_share!r} must lie in [0, 1]")


def lanes_from_traffic(vehicles_per_day, speed_kmh: float, lanes: int = 2, directional_split: float = 0.5,
                       fall_shares=None) -> tuple:
    """Lanes of a road carrying ``vehicles_per_day`` (two-way) at ``speed_kmh``: half the lanes each way
    (one lane each way for a two-lane road; an odd lane goes to the direction away from the slope), the
    traffic split ``directional_split`` : 1 - split between the directions and evenly between a direction's
    lanes.  ``fall_shares`` (one per lane, nearest the slope first; default even) say where falls land.

    Parameters
    ----------
    vehicles_per_day : float
        Two-way traffic [vehicles/day], > 0.
    speed_kmh : float
        Speed [km/h].
    lanes : int, optional
        Number of lanes, >= 1.
    directional_split : float, optional
        Share of the traffic towards the slope side [-], in [0, 1].
    fall_shares : sequence of float, optional
        Share of the falls reaching the road landing in each lane [-], nearest the slope first, summing to 1.

    Returns
    -------
    tuple of Lane
        The lanes, nearest the slope first.

    Raises
    ------
    ValueError
        When a number is out of range or ``fall_shares`` has the wrong length.

    Examples
    --------
    >>> [round(l.vehicles_per_day) for l in lanes_from_traffic(6000, 80)]
    [3000, 3000]
    """
    n = int(lanes)
    if n != lanes or n < 1:
        raise ValueError(f"lanes = {lanes!r} must be a whole number >= 1")
    if not 0 <= directional_split <= 1:
        raise ValueError(f"directional_split = {directional_split!r} must lie in [0, 1]")
    if isinstance(vehicles_per_day, bool) or not np.isfinite(vehicles_per_day) or vehicles_per_day <= 0:
        raise ValueError(f"vehicles_per_day = {vehicles_per_day!r} must be a number > 0")
    near = n // 2 if n > 1 else 1
    far = n - near
    shares = [None] * n if fall_shares is None else list(fall_shares)
    if len(shares) != n:
        raise ValueError(f"fall_shares = {fall_shares!r}: give one share per lane ({n})")
    out = []
    for i in range(n):
        if i < near:
            d, split, k = "towards slope side", directional_split, near
        else:
            d, split, k = "away from slope side", 1.0 - directional_split, far
        if n == 1:
            split, d = 1.0, "both directions"
        out.append(Lane(d, max(float(vehicles_per_day) * split / k, 1e-300), float(speed_kmh), shares[i]))
    return tuple(out)


def _shares(lanes) -> np.ndarray:
    q = np.array([np.nan if la.fall_share is None else la.fall_share for la in lanes], dtype=float)
    if np.all(np.isnan(q)):
        return np.full(len(lanes), 1.0 / len(lanes))
    if np.any(np.isnan(q)):
        raise ValueError("lanes: give fall_share for every lane or for none")
    if abs(q.sum() - 1.0) > 1e-6:
        raise ValueError(f"lanes: fall_share values {q.tolist()} must sum to 1")
    return q


def lane_hit_probability(lanes, vehicle_length_m: float, traffic_factor=1.0):
    """P(a fall reaching the road lands on a moving vehicle) = sum_i q_i N_i L_v / (24 x 1000 x V_i)
    (Bunce et al. 1997, per lane).  ``traffic_factor`` (a number or an array of samples) scales every lane's
    traffic.

    Parameters
    ----------
    lanes : sequence of Lane
        The road's lanes.
    vehicle_length_m : float
        Vehicle length L_v [m], > 0.
    traffic_factor : float or array_like, optional
        Factor on every lane's traffic [-] (an array of uncertainty samples allowed).

    Returns
    -------
    float or numpy.ndarray
        P(hit) per fall reaching the road [-].

    Raises
    ------
    ValueError
        When the lane traffic is continuous (P >= 1) or an input is out of range.

    References
    ----------
    Bunce, C. M., Cruden, D. M. and Morgenstern, N. R. (1997). Assessment of the hazard from rock fall on a highway.
    Canadian Geotechnical Journal 34, 344-356.

    Examples
    --------
    >>> round(lane_hit_probability(lanes_from_traffic(6000, 80), 5.0), 7)   # 3000 x 5 / (24000 x 80)
    0.0078125
    """
    if not vehicle_length_m > 0:
        raise ValueError(f"vehicle_length_m = {vehicle_length_m!r} must be > 0")
    q = _shares(lanes)
    f = np.asarray(traffic_factor, dtype=float)
    p = sum(qi * la.vehicles_per_day * vehicle_length_m / (HOURS_PER_DAY * M_PER_KM * la.speed_kmh)
            for qi, la in zip(q, lanes)) * f
    if np.any(p >= 1):
        raise ValueError(f"P(hit) = {float(np.max(p)):.3g} >= 1: the lane traffic is continuous; Bunce's formula "
                         "no longer applies")
    return float(p) if np.ndim(p) == 0 else p


def lane_strike_probability(lanes, hours_on_road: float, p_cannot_stop: float, traffic_factor=1.0):
    """P(a vehicle strikes a rock lying in its lane before it is removed) = sum_i q_i p (1 - exp(-N_i t / 24)):
    the first vehicle of the lane to arrive within ``hours_on_road`` fails to stop with probability ``p``.

    Parameters
    ----------
    lanes : sequence of Lane
        The road's lanes.
    hours_on_road : float
        Time t a rock lies on the road [h], > 0.
    p_cannot_stop : float
        Probability p that the arriving driver fails to stop [-], in [0, 1].
    traffic_factor : float or array_like, optional
        Factor on every lane's traffic [-] (an array of uncertainty samples allowed).

    Returns
    -------
    float or numpy.ndarray
        P(strike) per fall reaching the road [-].

    Raises
    ------
    ValueError
        When an input is out of range.

    References
    ----------
    Bunce, C. M., Cruden, D. M. and Morgenstern, N. R. (1997). Assessment of the hazard from rock fall on a highway.
    Canadian Geotechnical Journal 34, 344-356.

    Examples
    --------
    >>> round(lane_strike_probability(lanes_from_traffic(6000, 80), 0.5, 0.002), 8)  # 0.002 (1 - exp(-3000*0.5/24))
    0.002
    """
    if not hours_on_road > 0:
        raise ValueError(f"hours_on_road = {hours_on_road!r} must be > 0")
    if not 0 <= p_cannot_stop <= 1:
        raise ValueError(f"p_cannot_stop = {p_cannot_stop!r} must lie in [0, 1]")
    q = _shares(lanes)
    f = np.asarray(traffic_factor, dtype=float)
    p = sum(qi * p_cannot_stop * -np.expm1(-la.vehicles_per_day * f * hours_on_road / HOURS_PER_DAY)
            for qi, la in zip(q, lanes))
    return float(p) if np.ndim(p) == 0 else p


@dataclass(frozen=True)
class Vulnerability:
    """Probability of death of a vehicle occupant by block mass: pairs (mass_kg, probability) interpolated
    linearly in log10(mass), constant beyond the ends, for a direct hit on a moving vehicle (``direct``) and
    for a vehicle striking a rock on the road (``strike``); ``factor_range`` (low, high) multiplies both in the
    uncertainty study (capped at 1); ``injury_given_survival``: probability that an occupant who survives is
    injured (central, low, high)."""

    direct: tuple
    strike: tuple
    factor_range: tuple = (1.0, 1.0)
    injury_given_survival: tuple = (0.5, 0.2, 0.8)
    basis: str = ""

    def probability(self, mass_kg, which: str = "direct", factor=1.0) -> np.ndarray:
        """V(D:T) for blocks of ``mass_kg`` [kg]: ``which`` "direct" or "strike"; ``factor`` multiplies it.

        Parameters
        ----------
        mass_kg : float or array_like
            Block masses [kg].
        which : str, optional
            ``"direct"`` (hit on a moving vehicle) or ``"strike"`` (vehicle strikes a lying rock).
        factor : float or array_like, optional
            Factor on the vulnerability [-]; the result is capped at 1.

        Returns
        -------
        numpy.ndarray
            Probability of death [-].
        """
        table = np.asarray(self.direct if which == "direct" else self.strike, dtype=float)
        m = np.clip(np.asarray(mass_kg, dtype=float), 1e-12, None)
        v = np.interp(np.log10(m), np.log10(table[:, 0]), table[:, 1])
        return np.minimum(v * np.asarray(factor, dtype=float), 1.0)

    def summary(self) -> pd.DataFrame:
        """The model's points, one row per mass, with the low and high ends of the stated range.

        Returns
        -------
        pandas.DataFrame
            Columns ``case``, ``mass_kg`` [kg], ``vulnerability``, ``low`` and ``high`` [-].
        """
        lo, hi = self.factor_range
        rows = []
        for which, table in (("direct hit on a moving vehicle", self.direct),
                             ("vehicle strikes a rock on the road", self.strike)):
            for m, v in table:
                rows.append({"case": which, "mass_kg": m, "vulnerability": v, "low": min(v * lo, 1.0),
                             "high": min(v * hi, 1.0)})
        return pd.DataFrame(rows)


#: Default vulnerability model [kg -> probability of death of an occupant].  CHOSEN so that the predicted deaths
#: and injuries per fall reaching a road, and the vehicles involved, match the Hong Kong register of 1984-2020
#: (docs/validation/road-risk.md; tests/test_road_users.py): the register records 1 death among the occupants of
#: 12 vehicles involved in 703 falls reaching a road (rock and soil/rock cuts, failure volumes 0.01-4,000 m³,
#: median 3 m³), i.e. about 0.06 deaths per occupant (95 %: 0.0014-0.31), far below the AGS (2000) "vehicle
#: crushed" values (0.9-1.0, p. 47 of the reproduction above) that a failure volume taken as one block would
#: imply.  Hence 0.01-0.06 up to 10 t, inside the AGS "vehicle damaged only" range (0-0.3), rising to 0.5 at
#: 1,000 t and 0.9 ("crushed") at 10,000 t.  CAVEAT: the register gives failure volumes, not the block that
#: struck; for intact blocks of several tonnes the values may be low, which the factor range x0.25-x3 (the
#: register's 95 % interval around 0.06) carries into the uncertainty study.  A vehicle striking a rock lying on
#: the road: a third of the direct-hit value (ASSUMPTION: the driver brakes; no published value found).
DEFAULT_VULNERABILITY = Vulnerability(
    direct=((10.0, 0.01), (100.0, 0.02), (1000.0, 0.04), (10000.0, 0.06), (100000.0, 0.15), (1e6, 0.5),
            (1e7, 0.9)),
    strike=((10.0, 0.0033), (100.0, 0.0067), (1000.0, 0.013), (10000.0, 0.02), (100000.0, 0.05), (1e6, 0.17),
            (1e7, 0.3)),
    factor_range=(0.25, 3.0),
    basis="chosen to match the Hong Kong CEDD/GEO register 1984-2020 (riskrf.risk.road_validation)")


@dataclass(frozen=True)
class RoadUserRisk:
    """Expected consequences per fall reaching the road, direct hits and strikes on fallen rocks apart."""

    hit_probability: float
    strike_probability: float
    deaths_direct: float
    deaths_strike: float
    injuries_direct: float
    injuries_strike: float
    occupants: float

    @property
    def deaths(self) -> float:
        """Expected deaths per fall reaching the road (both ways)."""
        return self.deaths_direct + self.deaths_strike

    @property
    def injuries(self) -> float:
        """Expected injuries per fall reaching the road (both ways)."""
        return self.injuries_direct + self.injuries_strike

    def summary(self) -> pd.DataFrame:
        """One row per way of being harmed, and the total.

        Returns
        -------
        pandas.DataFrame
            Indexed by ``case``; columns ``vehicles_involved``, ``deaths`` and ``injuries``, each per fall reaching the
            road [-].
        """
        return pd.DataFrame([
            {"case": "direct hit on a moving vehicle", "vehicles_involved": self.hit_probability,
             "deaths": self.deaths_direct, "injuries": self.injuries_direct},
            {"case": "vehicle strikes a rock on the road", "vehicles_involved": self.strike_probability,
             "deaths": self.deaths_strike, "injuries": self.injuries_strike},
            {"case": "total", "vehicles_involved": self.hit_probability + self.strike_probability,
             "deaths": self.deaths, "injuries": self.injuries}]).set_index("case")


def per_fall_risk(lanes, mass_kg, *, vehicle_length_m: float = 5.0, occupants: float = 1.5,
                  hours_on_road: float = 0.5, p_cannot_stop: float = 0.002, share_stopping_on_road: float = 1.0,
                  vulnerability: Vulnerability = DEFAULT_VULNERABILITY, factor: float = 1.0,
                  injury_given_survival: float | None = None) -> RoadUserRisk:
    """Expected vehicles involved, deaths and injuries per fall reaching the road, for falls of masses
    ``mass_kg`` [kg] (each equally likely), direct hits and strikes on fallen rocks apart.

    deaths_direct = occupants x P(hit) x mean V_direct(m); deaths_strike = occupants x P(strike) x s x mean
    V_strike(m) with s = ``share_stopping_on_road`` (the share of falls that stop on the carriageway);
    injuries: occupants x P x mean (1 - V(m)) x injury_given_survival.

    Parameters
    ----------
    lanes : sequence of Lane
        The road's lanes.
    mass_kg : float or array_like
        Masses of the falls [kg], equally likely.
    vehicle_length_m : float, optional
        Vehicle length [m].
    occupants : float, optional
        Mean occupants per vehicle [persons].
    hours_on_road : float, optional
        Time a rock lies on the road [h].
    p_cannot_stop : float, optional
        Probability that the arriving driver fails to stop [-].
    share_stopping_on_road : float, optional
        Share of the falls that stop on the carriageway [-].
    vulnerability : Vulnerability, optional
        The vulnerability model.
    factor : float, optional
        Factor on the vulnerability [-].
    injury_given_survival : float, optional
        Probability that a survivor is injured [-]; the model's central value by default.

    Returns
    -------
    RoadUserRisk
        Vehicles involved, deaths and injuries per fall reaching the road [-].

    References
    ----------
    Bunce, C. M., Cruden, D. M. and Morgenstern, N. R. (1997). Assessment of the hazard from rock fall on a highway.
    Canadian Geotechnical Journal 34, 344-356.
    """
    m = np.atleast_1d(np.asarray(mass_kg, dtype=float))
    ph = lane_hit_probability(lanes, vehicle_length_m)
    ps = lane_strike_probability(lanes, hours_on_road, p_cannot_stop) * share_stopping_on_road
    vd = vulnerability.probability(m, "direct", factor)
    vs = vulnerability.probability(m, "strike", factor)
    inj = vulnerability.injury_given_survival[0] if injury_given_survival is None else injury_given_survival
    return RoadUserRisk(ph, ps, occupants * ph * vd.mean(), occupants * ps * vs.mean(),
                        occupants * ph * (1 - vd).mean() * inj, occupants * ps * (1 - vs).mean() * inj, occupants)


__all__ = ["DEFAULT_VULNERABILITY", "LITERATURE_VULNERABILITY", "Lane", "RoadUserRisk", "Vulnerability",
           "lane_hit_probability", "lane_strike_probability", "lanes_from_traffic", "per_fall_risk"]
