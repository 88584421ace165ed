"""Risk to road users (Bunce, Cruden & Morgenstern 1997; AGS 2007; Wyllie 2014, 8.5) and discounting.

Formulas (shared/research/domain-methods.md section 4):

* spatial-temporal probability that a moving vehicle occupies the impact point,
  P(S:T) = N_v L_v / (24 x 1000 x V_v)   (N_v vehicles/day, L_v m, V_v km/h);
* at least one vehicle hit by N_r falls, P(S:H) = 1 - (1 - P(S:T))^N_r   (AGS 2000, eq. E1);
* a vehicle striking a rock already on the road: the rock stays ``t`` hours; the
  vehicles arriving meanwhile are N_v t / 24, each failing to stop with probability
  ``p_no_stop`` (shorter sight than stopping distance): P = 1 - exp(-N_v t p / 24);
* annual probability of death of one commuter making ``trips`` passes a day,
  R = lambda x trips x (L_v/1000) / (24 V_v) x V(D:T)  (AGS 2007 form);
* F-N curve F(N) = sum of frequencies of scenarios with N_i >= N, against
  criterion lines F = C / N^k.

Criterion defaults are named and sourced; override them freely:
AGS (2007) tolerable individual risk 1e-4/yr (existing slopes) and 1e-5/yr (new)
[R, high confidence]; Hong Kong GEO Report 75 (1998) societal lines of slope -1
through F = 1e-3 (unacceptable above) and 1e-5 (broadly acceptable below) at N = 1 [R].
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from .units import HOURS_PER_DAY, M_PER_KM
from .validation import check_positive

#: Tolerable annual individual risk of death (AGS 2007c) [R].
AGS2007_INDIVIDUAL_RISK = {"existing slope": 1e-4, "new slope": 1e-5}
#: Hong Kong GEO (1998) F-N criterion lines: F = C / N^k [R].
HK_GEO_FN_LINES = {"unacceptable above": (1e-3, 1.0), "broadly acceptable below": (1e-5, 1.0)}
#: Vulnerability (probability of death) of a person in a vehicle (Finlay et al. 1999; AGS 2000) [V].
VULNERABILITY = {"vehicle crushed or buried": 1.0, "vehicle damaged only": 0.3}


def spatial_temporal_probability(vehicles_per_day, vehicle_length_m, speed_kmh):
    """P(S:T) = N_v L_v / (24 x 1000 x V_v): probability that a vehicle occupies the impact point."""
    n = check_positive(vehicles_per_day, "vehicles_per_day")
    length = check_positive(vehicle_length_m, "vehicle_length_m")
    v = check_positive(speed_kmh, "speed_kmh")
    p = n * length / (HOURS_PER_DAY * M_PER_KM * v)
    if p >= 1:
        raise ValueError(f"P(S:T) = {p:.3g} >= 1: traffic of {n:g} vehicles/day at {v:g} km/h is continuous; "
                         "the formula no longer applies")
    return p


def probability_at_least_one_hit(p_st, falls):
    """P(S:H) = 1 - (1 - P(S:T))^N_r for N_r falls (AGS 2000, eq. E1)."""
    return -np.expm1(np.asarray(falls, dtype=float) * np.log1p(-float(p_st)))


def stationary_rock_strike_probability(vehicles_per_day, hours_on_road, p_cannot_stop):
    """P(a vehicle strikes a rock lying on the road before it is removed): 1 - exp(-N_v t p / 24)."""
    n = check_positive(vehicles_per_day, "vehicles_per_day")
    t = check_positive(hours_on_road, "hours_on_road")
    if not 0 <= p_cannot_stop <= 1:
        raise ValueError(f"p_cannot_stop must lie in [0, 1]; got {p_cannot_stop!r}")
    return -np.expm1(-n * t * p_cannot_stop / 24.0)


def individual_risk(falls_per_year, trips_per_day, vehicle_length_m, speed_kmh, vulnerability):
    """Annual probability of death of one commuter: lambda x P(T:S) x V(D:T) (AGS 2007)."""
    p_ts = check_positive(trips_per_day, "trips_per_day") * check_positive(vehicle_length_m, "vehicle_length_m") \
        / (HOURS_PER_DAY * M_PER_KM * check_positive(speed_kmh, "speed_kmh"))
    return float(falls_per_year) * p_ts * float(vulnerability)


def fn_curve(scenarios) -> pd.DataFrame:
    """F-N curve from scenarios ``[(frequency_per_year, fatalities), ...]``: F(N) = sum f_i for N_i >= N."""
    arr = np.asarray(scenarios, dtype=float).reshape(-1, 2)
    if np.any(arr < 0):
        i = int(np.argmax(np.any(arr < 0, axis=1)))
        raise ValueError(f"scenarios[{i}] = {tuple(arr[i])}: frequencies and fatalities must be >= 0")
    arr = arr[arr[:, 1] >= 1]
    if arr.size == 0:
        return pd.DataFrame({"N": [], "F": []})
    Ns = np.unique(np.ceil(arr[:, 1]))
    F = np.array([arr[arr[:, 1] >= n, 0].sum() for n in Ns])
    return pd.DataFrame({"N": Ns, "F": F})


def vehicle_occupant_fn(hit_frequency, occupants, vulnerability) -> pd.DataFrame:
    """F-N curve of vehicle hits: N ~ Binomial(occupants, vulnerability), F(N) = f P(N' >= N)."""
    n_occ = int(round(occupants))
    Ns = np.arange(1, max(n_occ, 1) + 1)
    F = float(hit_frequency) * stats.binom.sf(Ns - 1, n_occ, vulnerability)
    return pd.DataFrame({"N": Ns.astype(float), "F": F})


def pv_factor(rate, years):
    """Uniform-series present-value factor (1 - (1 + r)^-n) / r; n when r = 0.

    e.g. 18.256 for 5 % over 50 years (domain-methods.md section 5).
    """
    r = float(rate)
    n = check_positive(years, "years")
    if r < 0 or r >= 1:
        raise ValueError(f"discount rate must lie in [0, 1); got {rate!r}")
    return n if r == 0 else (1.0 - (1.0 + r) ** -n) / r


def pv_of_renewals(cost, life_years, horizon_years, rate):
    """Present value of re-building every ``life_years`` within the horizon (the first build excluded)."""
    life = check_positive(life_years, "life_years")
    k = np.arange(1, int(np.floor((float(horizon_years) - 1e-9) / life)) + 1)
    return float(cost * np.sum((1.0 + float(rate)) ** -(k * life)))


def fn_zone(fn: pd.DataFrame, lines: dict | None = None) -> str:
    """Where an F-N curve lies against two criterion lines F = C / N^k (upper: unacceptable above,
    lower: broadly acceptable below): "unacceptable", "ALARP" (between) or "broadly acceptable"."""
    lines = HK_GEO_FN_LINES if lines is None else lines
    (c_hi, k_hi), (c_lo, k_lo) = lines["unacceptable above"], lines["broadly acceptable below"]
    if len(fn) == 0 or not np.any(fn["F"] > 0):
        return "broadly acceptable"
    N, F = fn["N"].to_numpy(dtype=float), fn["F"].to_numpy(dtype=float)
    if np.any(F > c_hi / N ** k_hi):
        return "unacceptable"
    if np.any(F > c_lo / N ** k_lo):
        return "ALARP"
    return "broadly acceptable"
