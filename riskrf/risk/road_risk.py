"""Risk to road users (Bunce, Cruden & Morgenstern 1997; AGS 2007; Wyllie 2014, 8.5).

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
[R, high confidence]; the Hong Kong societal risk diagram of ERM-Hong Kong for GEO,
GEO Report No. 75 (1998), "Landslides and boulder falls from natural terrain: interim
risk guidelines": lines of slope -1 through F = 1e-3 (unacceptable above) and 1e-5
(broadly acceptable below) at N = 1, drawn to N = 1,000; an "intense scrutiny" band
for N = 1,000-5,000 and any N > 5,000 unacceptable [R].

Consequences depend on the block: the probability that an occupant dies grows with
the block's mass, between the AGS (2000) / Finlay et al. (1999) values for a vehicle
"damaged only" (0-0.3) and "crushed" (0.9-1.0) [V]; where those values are placed on
the mass axis is an assumption (:data:`VULNERABILITY_DIRECT_BY_MASS`), labelled as
such in every output.  Occupants per vehicle are a distribution, not a rounded mean.

Discounting lives in :mod:`riskrf.risk.economics`.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from ..core.units import HOURS_PER_DAY, M_PER_KM
from ..core.validation import check_positive

#: Tolerable annual individual risk of death (AGS 2007c) [R].
AGS2007_INDIVIDUAL_RISK = {"existing slope": 1e-4, "new slope": 1e-5}
#: Hong Kong GEO Report 75 (ERM-Hong Kong 1998) F-N criterion lines: F = C / N^k, drawn for 1 <= N <= 1,000 [R].
HK_GEO_FN_LINES = {"unacceptable above": (1e-3, 1.0), "broadly acceptable below": (1e-5, 1.0)}
#: End of the sloping lines of the GEO diagram, end of the "intense scrutiny" band (N > 5,000 unacceptable),
#: and the lowest frequency drawn for the band [R: GEO Report 75, 1998].
HK_GEO_N_CUTOFF = 1000
HK_GEO_N_LIMIT = 5000
HK_GEO_SCRUTINY_F_MIN = 1e-9
#: Vulnerability of a vehicle occupant hit directly by a falling block, by block mass [kg]: pairs
#: (mass_kg, probability of death), interpolated linearly in log10(mass) and held constant beyond the ends.
#: ASSUMPTION: the end values are the AGS (2000) / Finlay et al. (1999) "vehicle damaged only" (0.3 taken at
#: 100 kg, 0.05 at 10 kg) and "vehicle crushed" (1.0 from 10 t) values; the masses where they apply are
#: engineering judgement, not from a source.
VULNERABILITY_DIRECT_BY_MASS = ((10.0, 0.05), (100.0, 0.3), (1000.0, 0.7), (10000.0, 1.0))
#: Vulnerability of an occupant of a vehicle striking a block lying on the road, by block mass [kg].
#: ASSUMPTION: a tenth of the direct-hit value below 1 t rising to 0.3 ("damaged only", AGS 2000) at 10 t.
VULNERABILITY_STRIKE_BY_MASS = ((10.0, 0.005), (100.0, 0.03), (1000.0, 0.1), (10000.0, 0.3))
#: Largest number of occupants of one vehicle in the default occupancy distribution (cars and vans).
MAX_OCCUPANTS = 9
#: Vulnerability (probability of death) of a person in a vehicle (Finlay et al. 1999; AGS 2000) [V].
VULNERABILITY = {"vehicle crushed or buried": 1.0, "vehicle damaged only": 0.3}


def _positive_array(value, name):
    v = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(v)) or np.any(v <= 0):
        raise ValueError(f"{name} must be finite and > 0; got {value!r}")
    return v


def spatial_temporal_probability(vehicles_per_day, vehicle_length_m, speed_kmh):
    """P(S:T) = N_v L_v / (24 x 1000 x V_v): probability that a vehicle occupies the impact point.

    ``vehicles_per_day`` may be an array (uncertainty samples).

    Parameters
    ----------
    vehicles_per_day : float or array_like
        Traffic N_v [vehicles/day], > 0; an array of uncertainty samples is allowed.
    vehicle_length_m : float
        Vehicle length L_v [m].
    speed_kmh : float
        Speed V_v [km/h].

    Returns
    -------
    float or numpy.ndarray
        P(S:T) [-], shaped as ``vehicles_per_day``.

    Raises
    ------
    ValueError
        When an input is not positive or P(S:T) >= 1 (continuous traffic).

    References
    ----------
    Bunce, C. M., Cruden, D. M. and Morgenstern, N. R. (1997). Assessment of the hazard from rock fall on a highway.
    Canadian Geotechnical Journal 34, 344-356.
    """
    n = _positive_array(vehicles_per_day, "vehicles_per_day")
    length = check_positive(vehicle_length_m, "vehicle_length_m")
    v = check_positive(speed_kmh, "speed_kmh")
    p = n * length / (HOURS_PER_DAY * M_PER_KM * v)
    if np.any(p >= 1):
        bad = float(np.max(n))
        raise ValueError(f"P(S:T) = {float(np.max(p)):.3g} >= 1: traffic of {bad:g} vehicles/day at {v:g} km/h is "
                         "continuous; the formula no longer applies")
    return float(p) if p.ndim == 0 else p


def probability_at_least_one_hit(p_st, falls):
    """P(S:H) = 1 - (1 - P(S:T))^N_r for N_r falls (AGS 2000, eq. E1).

    Parameters
    ----------
    p_st : float
        P(S:T), probability that a vehicle occupies the impact point [-].
    falls : float or array_like
        Number of falls N_r reaching the road [-].

    Returns
    -------
    numpy.ndarray
        P(S:H) [-], shaped as ``falls``.

    References
    ----------
    AGS (2000). Australian Geomechanics Society, landslide risk management concepts and guidelines, eq. E1.
    """
    return -np.expm1(np.asarray(falls, dtype=float) * np.log1p(-float(p_st)))


def stationary_rock_strike_probability(vehicles_per_day, hours_on_road, p_cannot_stop):
    """P(a vehicle strikes a rock lying on the road before it is removed): 1 - exp(-N_v t p / 24).

    N_v vehicles/day pass in the ``hours_on_road`` the rock stays; each fails to stop
    with probability ``p_cannot_stop`` (sight distance shorter than stopping distance).

    Parameters
    ----------
    vehicles_per_day : float or array_like
        Traffic N_v [vehicles/day], > 0.
    hours_on_road : float
        Time t the rock lies on the road before removal [h].
    p_cannot_stop : float
        Probability that a vehicle fails to stop in time [-], in [0, 1].

    Returns
    -------
    float or numpy.ndarray
        Probability that a vehicle strikes the rock [-], shaped as ``vehicles_per_day``.

    References
    ----------
    Bunce, C. M., Cruden, D. M. and Morgenstern, N. R. (1997). Assessment of the hazard from rock fall on a highway.
    Canadian Geotechnical Journal 34, 344-356.
    """
    n = _positive_array(vehicles_per_day, "vehicles_per_day")
    t = check_positive(hours_on_road, "hours_on_road")
    if not 0 <= p_cannot_stop <= 1:
        raise ValueError(f"p_cannot_stop must lie in [0, 1]; got {p_cannot_stop!r}")
    p = -np.expm1(-n * t * p_cannot_stop / HOURS_PER_DAY)
    return float(p) if p.ndim == 0 else p


def commuter_passage_probability(trips_per_day, vehicle_length_m, speed_kmh):
    """P(T:S) = trips x L_v / (24 x 1000 x V_v): a given commuter's car is at the impact point (AGS 2007).

    Parameters
    ----------
    trips_per_day : float
        Passes of the commuter through the exposed road [1/day].
    vehicle_length_m : float
        Vehicle length L_v [m].
    speed_kmh : float
        Speed V_v [km/h].

    Returns
    -------
    float
        P(T:S) [-].

    References
    ----------
    AGS (2007). Australian Geomechanics Society, practice note guidelines for landslide risk management (AGS 2007c).
    """
    return check_positive(trips_per_day, "trips_per_day") * check_positive(vehicle_length_m, "vehicle_length_m") \
        / (HOURS_PER_DAY * M_PER_KM * check_positive(speed_kmh, "speed_kmh"))


def commuter_strike_probability(trips_per_day, hours_on_road, p_cannot_stop):
    """P(a given commuter arrives while a rock lies on the road and cannot stop): 1 - exp(-trips t p / 24).

    Parameters
    ----------
    trips_per_day : float
        Passes of the commuter through the exposed road [1/day].
    hours_on_road : float
        Time t a rock lies on the road [h].
    p_cannot_stop : float
        Probability that the commuter fails to stop in time [-].

    Returns
    -------
    float
        Probability that the commuter strikes a lying rock, per fall [-].

    References
    ----------
    Bunce, C. M., Cruden, D. M. and Morgenstern, N. R. (1997). Assessment of the hazard from rock fall on a highway.
    Canadian Geotechnical Journal 34, 344-356.
    """
    return float(-np.expm1(-check_positive(trips_per_day, "trips_per_day") * check_positive(hours_on_road,
                                                                                          "hours_on_road")
                           * float(p_cannot_stop) / HOURS_PER_DAY))


def individual_risk(falls_per_year, trips_per_day, vehicle_length_m, speed_kmh, vulnerability):
    """Annual probability of death of one commuter hit directly: lambda x P(T:S) x V(D:T) (AGS 2007).

    Parameters
    ----------
    falls_per_year : float
        Frequency lambda of falls reaching the road [1/yr].
    trips_per_day : float
        Passes of the commuter [1/day].
    vehicle_length_m : float
        Vehicle length L_v [m].
    speed_kmh : float
        Speed V_v [km/h].
    vulnerability : float
        Probability of death given a hit, V(D:T) [-].

    Returns
    -------
    float
        Annual probability of death of the commuter [1/yr].

    References
    ----------
    AGS (2007). Australian Geomechanics Society, practice note guidelines for landslide risk management (AGS 2007c).
    """
    return float(falls_per_year) * commuter_passage_probability(trips_per_day, vehicle_length_m, speed_kmh) \
        * float(vulnerability)


def vulnerability_by_mass(mass_kg, table):
    """Probability of death for blocks of ``mass_kg`` from ``table``: a number (constant) or pairs
    (mass_kg, vulnerability) interpolated linearly in log10(mass), constant beyond the ends.

    Parameters
    ----------
    mass_kg : float or array_like
        Block masses [kg].
    table : float or sequence of (float, float)
        A constant vulnerability [-], or pairs (mass [kg], vulnerability [-]) such as
        :data:`VULNERABILITY_DIRECT_BY_MASS`.

    Returns
    -------
    numpy.ndarray
        Probability of death [-], shaped as ``mass_kg``.
    """
    m = np.asarray(mass_kg, dtype=float)
    if isinstance(table, (int, float)):
        return np.full(m.shape, float(table))
    arr = np.asarray(table, dtype=float)
    return np.interp(np.log10(m), np.log10(arr[:, 0]), arr[:, 1])


def occupancy_distribution(mean_occupants: float, pmf: dict | None = None, max_occupants: int = MAX_OCCUPANTS):
    """Occupants per vehicle as a distribution: (k, P(k)) arrays.

    ``pmf`` {occupants: probability} is used as given (checked to sum to 1).  Without it,
    1 + Poisson(mean - 1) truncated at ``max_occupants`` (every vehicle has a driver;
    ASSUMPTION: passengers Poisson), renormalised, so the mean is ``mean_occupants`` up
    to the truncation.

    Parameters
    ----------
    mean_occupants : float
        Mean occupants per vehicle [persons], >= 1; ignored when ``pmf`` is given.
    pmf : dict, optional
        {occupants [persons]: probability [-]}, summing to 1.
    max_occupants : int, optional
        Largest number of occupants in the default distribution [persons].

    Returns
    -------
    k : numpy.ndarray of int
        Numbers of occupants [persons].
    p : numpy.ndarray
        P(K = k) [-], summing to 1.

    Raises
    ------
    ValueError
        When ``pmf`` is not a distribution over whole numbers >= 1, or ``mean_occupants`` < 1.
    """
    if pmf:
        k = np.array(sorted(int(x) for x in pmf), dtype=int)
        p = np.array([float(pmf[x] if x in pmf else pmf[str(x)]) for x in k])
        if np.any(k < 1) or np.any(p < 0) or abs(p.sum() - 1) > 1e-6:
            raise ValueError(f"occupants_distribution = {pmf!r}: occupants must be whole numbers >= 1 and the "
                             "probabilities >= 0 summing to 1")
        return k, p / p.sum()
    mean = float(mean_occupants)
    if mean < 1:
        raise ValueError(f"occupants_per_vehicle = {mean_occupants!r} must be >= 1 (the driver)")
    k = np.arange(1, max_occupants + 1)
    p = stats.poisson.pmf(k - 1, mean - 1.0)
    return k, p / p.sum()


def share_with_at_least(vulnerabilities, occupants_k, occupants_p, max_n: int | None = None) -> np.ndarray:
    """P(N >= n) for n = 1 ... max_n deaths in one vehicle: K occupants ~ ``occupants_p`` over ``occupants_k``,
    each dying independently with probability v, N | K ~ Binomial(K, v).  Shape: vulnerabilities.shape + (max_n,).

    Exact binomial sums, vectorised over any array of vulnerabilities: the pmf of Binomial(k, v) is built up one
    occupant at a time (pmf_k(i) = pmf_(k-1)(i) (1 - v) + pmf_(k-1)(i - 1) v), so no power is evaluated.

    Parameters
    ----------
    vulnerabilities : array_like
        Probability of death of each occupant v [-], any shape.
    occupants_k : array_like of int
        Numbers of occupants of a vehicle, K [persons].
    occupants_p : array_like of float
        P(K = k) for each entry of ``occupants_k`` [-], summing to 1.
    max_n : int, optional
        Largest number of deaths n [persons]; the largest K by default.

    Returns
    -------
    numpy.ndarray
        P(N >= n) [-] for n = 1 ... max_n, shape ``vulnerabilities.shape + (max_n,)``.
    """
    v_all = np.asarray(vulnerabilities, dtype=float)
    k_all = np.asarray(occupants_k, dtype=int)
    p_all = np.asarray(occupants_p, dtype=float)
    max_n = int(k_all.max()) if max_n is None else int(max_n)
    if v_all.size > 64:               # vulnerabilities repeat (a curve by mass class x a factor): each value once
        u, inverse = np.unique(v_all, return_inverse=True)
        if u.size < v_all.size // 2:
            return share_with_at_least(u, k_all, p_all, max_n)[inverse.ravel()].reshape(v_all.shape + (max_n,))
    v = v_all[..., None]
    weight = dict(zip(k_all.tolist(), p_all.tolist()))
    out = np.zeros(v.shape[:-1] + (max_n,))
    pmf = np.ones(v.shape)                                            # Binomial(0, v): N = 0
    for k in range(1, int(k_all.max()) + 1):
        nxt = np.zeros(v.shape[:-1] + (k + 1,))
        nxt[..., :k] = pmf * (1.0 - v)
        nxt[..., 1:] += pmf * v
        pmf = nxt
        if weight.get(k, 0.0):
            tail = np.cumsum(pmf[..., ::-1], axis=-1)[..., ::-1]      # tail[..., n] = P(N >= n)
            m = min(max_n, k)
            out[..., :m] += weight[k] * tail[..., 1:m + 1]
    return out


def occupant_fn(frequencies, vulnerabilities, occupants_k, occupants_p) -> pd.DataFrame:
    """F-N curve of vehicle accidents with occupants as a distribution.

    Scenario s happens ``frequencies[s]`` times a year; each of the K occupants of the
    vehicle (K ~ ``occupants_p`` over ``occupants_k``) dies independently with
    probability ``vulnerabilities[s]``: F(N) = sum_s f_s sum_k P(K = k) P(Binomial(k, V_s) >= N)
    for every N = 1 ... max k.  sum_N F(N) equals the expected deaths per year.

    Parameters
    ----------
    frequencies : array_like
        Frequency f_s of each scenario [1/yr].
    vulnerabilities : array_like
        Probability of death V_s of an occupant in each scenario [-].
    occupants_k : array_like of int
        Numbers of occupants of a vehicle, K [persons].
    occupants_p : array_like of float
        P(K = k) for each entry of ``occupants_k`` [-], summing to 1.

    Returns
    -------
    pandas.DataFrame
        Columns ``N`` (deaths [persons]) and ``F`` (frequency of N or more deaths [1/yr]).
    """
    f = np.asarray(frequencies, dtype=float).ravel()
    v = np.asarray(vulnerabilities, dtype=float).ravel()
    k = np.asarray(occupants_k, dtype=int)
    pk = np.asarray(occupants_p, dtype=float)
    Ns = np.arange(1, int(k.max()) + 1)
    F = f @ share_with_at_least(v, k, pk)
    return pd.DataFrame({"N": Ns.astype(float), "F": F})


def fn_curve(scenarios) -> pd.DataFrame:
    """F-N curve from scenarios ``[(frequency_per_year, fatalities), ...]``: F(N) = sum f_i for N_i >= N.

    Parameters
    ----------
    scenarios : array_like
        Pairs (frequency [1/yr], fatalities [persons]), all >= 0.

    Returns
    -------
    pandas.DataFrame
        Columns ``N`` (fatalities [persons]) and ``F`` (frequency of N or more [1/yr]); empty when no scenario
        kills anyone.

    Raises
    ------
    ValueError
        When a frequency or number of fatalities is negative.
    """
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
    """F-N curve of vehicle hits with a fixed whole number of occupants: N ~ Binomial(occupants, vulnerability).

    Parameters
    ----------
    hit_frequency : float
        Frequency of vehicle hits [1/yr].
    occupants : int
        Occupants of the vehicle [persons], a whole number >= 1.
    vulnerability : float
        Probability of death of each occupant [-].

    Returns
    -------
    pandas.DataFrame
        Columns ``N`` (deaths [persons]) and ``F`` (frequency of N or more deaths [1/yr]).

    Raises
    ------
    ValueError
        When ``occupants`` is not a whole number >= 1.
    """
    n_occ = int(occupants)
    if n_occ != occupants or n_occ < 1:
        raise ValueError(f"occupants = {occupants!r} must be a whole number >= 1; for a mean such as 1.4 use "
                         "occupant_fn with occupancy_distribution")
    return occupant_fn([hit_frequency], [vulnerability], [n_occ], [1.0])


def fn_zone(fn: pd.DataFrame, lines: dict | None = None) -> str:
    """Where an F-N curve lies on the Hong Kong GEO (1998) diagram.

    "unacceptable": F(N) above the upper line C/N^k for some N <= 1,000, or any N > 5,000
    with F > 0; "intense scrutiny": F(N) >= 1e-9 for some 1,000 < N <= 5,000;
    "ALARP": above the lower line; else "broadly acceptable".

    Parameters
    ----------
    fn : pandas.DataFrame
        F-N curve with columns ``N`` [persons] and ``F`` [1/yr].
    lines : dict, optional
        ``{"unacceptable above": (C, k), "broadly acceptable below": (C, k)}`` criterion lines F = C / N^k
        (C [1/yr]); :data:`HK_GEO_FN_LINES` by default.

    Returns
    -------
    str
        ``"unacceptable"``, ``"intense scrutiny"``, ``"ALARP"`` or ``"broadly acceptable"``.

    References
    ----------
    ERM-Hong Kong (1998). Landslides and boulder falls from natural terrain: interim risk guidelines. GEO Report
    No. 75, Geotechnical Engineering Office, Hong Kong.
    """
    lines = HK_GEO_FN_LINES if lines is None else lines
    (c_hi, k_hi), (c_lo, k_lo) = lines["unacceptable above"], lines["broadly acceptable below"]
    if len(fn) == 0 or not np.any(fn["F"] > 0):
        return "broadly acceptable"
    N, F = fn["N"].to_numpy(dtype=float), fn["F"].to_numpy(dtype=float)
    low = N <= HK_GEO_N_CUTOFF
    if np.any(F[low] > c_hi / N[low] ** k_hi) or np.any(F[N > HK_GEO_N_LIMIT] > 0):
        return "unacceptable"
    if np.any(F[(N > HK_GEO_N_CUTOFF) & (N <= HK_GEO_N_LIMIT)] >= HK_GEO_SCRUTINY_F_MIN):
        return "intense scrutiny"
    if np.any(F[low] > c_lo / N[low] ** k_lo):
        return "ALARP"
    return "broadly acceptable"
