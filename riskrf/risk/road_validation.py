"""Road-user risk checked against real casualty records: the Hong Kong slope incident register.

The register of the Civil Engineering and Development Department, Geotechnical Engineering Office (CEDD/GEO,
Hong Kong SAR Government, via DATA.GOV.HK; 1984-2020, 37 years) records every reported slope incident with
its feature type, its failure volume (SCALE, read as m³), the facility affected (FACAFF), the consequence in
words (CONSEC) and the numbers killed (DEATHNO) and injured (INJURYNO).  The incidents on man-made rock cuts
and soil/rock cuts whose facility affected is a road are the falls that reached a road; the records say how
many vehicles were involved (a casualty, or a vehicle named as damaged in CONSEC), how many people died and
how many were injured.

:func:`hong_kong_road_validation` predicts the same three numbers with :mod:`riskrf.risk.road_users` (Bunce et
al. 1997 per lane, the stated vulnerability model) under a stated range of Hong Kong traffic, and compares
them with the records: per fall reaching a road, with the 5-95 % range of the prediction over the uncertain
inputs and the exact 95 % Poisson interval of the record (Garwood 1936), and the probability of a count at
most / at least the recorded one under the prediction (a Poisson mixture over the samples).

Caveats of the data (repeat them wherever the numbers are used; shared/inventories-raw/hong-kong-cedd/
PROVENANCE.md): a regional record of all man-made cuts, not one slope; the failure mechanism is not given (rock
falls, small rock slides and soil/rock debris are mixed); reporting practice changed over 37 years; SCALE is
the failure volume, so a mass of SCALE x 2,650 kg/m³ is an upper bound of the block that strikes a vehicle;
an injured pedestrian on the road is counted with the vehicles involved (CONSEC does not always say); the
traffic on the roads affected is not in the register and is an assumption stated below.
"""
from __future__ import annotations

import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from ..core.units import DEFAULT_DENSITY_KG_M3
from .road_users import DEFAULT_VULNERABILITY, Vulnerability, lane_hit_probability, lane_strike_probability, \
    lanes_from_traffic

#: Feature types kept: rock cuts and soil/rock cuts (compared case-insensitively; the file spells both ways).
ROAD_FEATURES = ("rock cut", "soil/rock cut")
#: A facility affected that is a road: the word "road" or "roads" (so "roadside" footpaths are not roads).
ROAD_PATTERN = r"\broads?\b"
#: A vehicle named in the consequence text.
VEHICLE_PATTERN = r"\b(?:vehicles?|cars?|bus|buses|taxis?|lorry|lorries|vans?|minibus(?:es)?|trucks?|motorcycles?|coach)\b"

#: Traffic of the roads affected: NOT in the register.  ASSUMPTION, stated: two-way vehicles a day log-uniform in
#: 5,000-50,000 (Hong Kong roads beside cut slopes, from village access roads to urban trunk roads), 2, 3 or 4
#: lanes equally likely, 50-70 km/h (Hong Kong's general urban limit is 50 km/h), 1.2-2.5 occupants a vehicle
#: (cars to a share of buses and minibuses), a rock lying 1 h on the road, 0.2 % of drivers unable to stop.
HONG_KONG_TRAFFIC = {"vehicles_per_day": (5000.0, 50000.0), "lanes": (2, 3, 4), "speed_kmh": (50.0, 70.0),
                     "occupants": (1.2, 2.5), "hours_on_road": 1.0, "p_cannot_stop": 0.002,
                     "vehicle_length_m": 5.0}


def poisson_interval(k: int, level: float = 0.95) -> tuple:
    """Exact (Garwood 1936) two-sided interval of a Poisson mean given ``k`` events: chi2 quantiles / 2.

    Parameters
    ----------
    k : int
        Number of events observed.
    level : float, optional
        Confidence level [-].

    Returns
    -------
    tuple of float
        (low, high) of the Poisson mean [events].

    References
    ----------
    Garwood, F. (1936). Fiducial limits for the Poisson distribution. Biometrika 28, 437-442.
    """
    a = 1.0 - level
    lo = 0.0 if k == 0 else stats.chi2.ppf(a / 2, 2 * k) / 2
    hi = stats.chi2.ppf(1 - a / 2, 2 * k + 2) / 2
    return float(lo), float(hi)


@dataclass(frozen=True)
class RoadRecords:
    """Falls reaching a road in the register and their recorded consequences."""

    incidents: pd.DataFrame           # one row per incident: feature, volume_m3 (NaN if no size), deaths, ...
    years: int
    source: str

    @property
    def falls(self) -> int:
        """Incidents that reached a road."""
        return len(self.incidents)

    @property
    def deaths(self) -> int:
        """People killed (DEATHNO summed over the falls that reached a road)."""
        return int(self.incidents["deaths"].sum())

    @property
    def injuries(self) -> int:
        """People injured (INJURYNO summed over the falls that reached a road)."""
        return int(self.incidents["injuries"].sum())

    @property
    def vehicles_involved(self) -> int:
        """Incidents with a casualty or a vehicle named in the consequence (one vehicle each, at least)."""
        return int(self.incidents["vehicle_involved"].sum())


def read_hong_kong_road_records(path) -> RoadRecords:
    """Rock-cut and soil/rock-cut incidents that affected a road, from the CEDD/GEO register CSV.

    Raises ValueError naming the file and the missing column.

    Parameters
    ----------
    path : str or pathlib.Path
        The CEDD/GEO slope incident register (CSV).

    Returns
    -------
    RoadRecords
        One row per incident (``volume_m3`` [m3], deaths, injuries, vehicle involved, year) and the years covered.

    Raises
    ------
    FileNotFoundError
        When the file does not exist.
    ValueError
        Naming the file and a missing column, or the row and column of an unreadable count.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"register file not found: {path}")
    text = path.read_bytes().decode("utf-8-sig", errors="replace")
    t = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    need = ("FEATTYPE", "SCALE", "FACAFF", "CONSEC", "CONSEC - DEATHNO", "CONSEC - INJURYNO", "CALLDATE")
    missing = [c for c in need if c not in t.columns]
    if missing:
        raise ValueError(f"{path}: column(s) {missing} missing; found {list(t.columns)[:20]}")
    ft = t["FEATTYPE"].str.strip().str.lower()
    sel = t[ft.isin(ROAD_FEATURES) & t["FACAFF"].str.contains(ROAD_PATTERN, case=False, regex=True)]

    def count(col):
        v = pd.to_numeric(sel[col].str.strip().replace("-", "0"), errors="coerce")
        bad = v.isna()
        if bad.any():
            i = bad.idxmax()
            raise ValueError(f"{path}: row {i}, column {col!r}: {sel.loc[i, col]!r} is not a count")
        return v.astype(int)

    def size(s):
        m = re.match(r"^[<~]?\s*(\d+(?:\.\d+)?)$", s.strip())
        return float(m.group(1)) if m else np.nan

    deaths, injuries = count("CONSEC - DEATHNO"), count("CONSEC - INJURYNO")
    named = sel["CONSEC"].str.contains(VEHICLE_PATTERN, case=False, regex=True) \
        & ~sel["CONSEC"].str.contains(r"bus stops?", case=False, regex=True)
    years = pd.to_datetime(sel["CALLDATE"], format="%d/%m/%Y", errors="coerce").dt.year
    inc = pd.DataFrame({"feature": ft[sel.index], "volume_m3": sel["SCALE"].map(size), "deaths": deaths,
                        "injuries": injuries, "vehicle_involved": (deaths + injuries > 0) | named,
                        "year": years, "consequence": sel["CONSEC"]}).reset_index(drop=True)
    n_years = int(years.max() - years.min() + 1) if years.notna().any() else 0
    return RoadRecords(inc, n_years, str(path))


@dataclass(frozen=True)
class RoadValidation:
    """Predicted vs recorded vehicles involved, deaths and injuries per fall reaching a road."""

    records: RoadRecords
    predicted: dict = field(repr=False)      # name -> per-fall samples (S,)
    traffic: dict = field(default_factory=dict)
    vulnerability: Vulnerability = DEFAULT_VULNERABILITY
    seed: int = 1

    def summary(self) -> pd.DataFrame:
        """One row per quantity: recorded count and rate per fall with its 95 % Poisson interval, predicted per
        fall (mean and 5-95 %), predicted count over the recorded falls, P(count <= recorded) and P(count >=
        recorded) under the prediction, and whether the record lies inside the prediction's 95 % range.

        Returns
        -------
        pandas.DataFrame
            Indexed by ``quantity``; counts, rates per fall [-] with their intervals, probabilities [-] and
            ``consistent``.
        """
        n = self.records.falls
        rec = {"vehicles involved": self.records.vehicles_involved, "deaths": self.records.deaths,
               "injuries": self.records.injuries}
        rows = []
        for name, k in rec.items():
            s = self.predicted[name]
            lo, hi = poisson_interval(k)
            mu = s * n
            p_le = float(np.mean(stats.poisson.cdf(k, mu)))
            p_ge = float(np.mean(stats.poisson.sf(k - 1, mu)))
            rows.append({"quantity": name, "recorded": k, "recorded_per_fall": k / n,
                         "recorded_low_95": lo / n, "recorded_high_95": hi / n,
                         "predicted_per_fall": float(s.mean()), "predicted_p05": float(np.quantile(s, 0.05)),
                         "predicted_p95": float(np.quantile(s, 0.95)), "predicted_count": float(mu.mean()),
                         "p_count_at_most_recorded": p_le, "p_count_at_least_recorded": p_ge,
                         "consistent": bool(min(p_le, p_ge) > 0.025)})
        return pd.DataFrame(rows).set_index("quantity")


def hong_kong_road_validation(path, *, vulnerability: Vulnerability = DEFAULT_VULNERABILITY,
                              traffic: dict | None = None, samples: int = 4000, seed: int = 1,
                              two_way: bool = False) -> RoadValidation:
    """Predict the register's vehicles involved, deaths and injuries per fall reaching a road.

    Each sample draws the traffic (:data:`HONG_KONG_TRAFFIC` unless ``traffic`` overrides it), the vulnerability
    factor (log-uniform over ``vulnerability.factor_range``) and the injury share; the per-fall expectation is
    averaged over the register's own incident sizes (mass = SCALE x 2,650 kg/m³; incidents without a size take
    the others' distribution).  ``two_way=True`` evaluates Bunce's formula with the two-way traffic in one lane
    (the form used before lanes were separated), to show what that does.

    Parameters
    ----------
    path : str or pathlib.Path
        The CEDD/GEO slope incident register (CSV).
    vulnerability : riskrf.risk.road_users.Vulnerability, optional
        The vulnerability model.
    traffic : dict, optional
        Overrides of :data:`HONG_KONG_TRAFFIC` (traffic [vehicles/day], speed [km/h], occupants [persons], hours on
        road [h], vehicle length [m]).
    samples : int, optional
        Number of samples S.
    seed : int, optional
        Random seed.
    two_way : bool, optional
        Put the two-way traffic in one lane.

    Returns
    -------
    RoadValidation
        Recorded and predicted (S samples) vehicles involved, deaths and injuries per fall reaching a road [-].

    References
    ----------
    Bunce, C. M., Cruden, D. M. and Morgenstern, N. R. (1997). Assessment of the hazard from rock fall on a highway.
    Canadian Geotechnical Journal 34, 344-356.
    """
    rec = read_hong_kong_road_records(path)
    tr = {**HONG_KONG_TRAFFIC, **(traffic or {})}
    rng = np.random.default_rng(seed)
    vol = rec.incidents["volume_m3"].dropna().to_numpy()
    mass = np.clip(vol, 1e-3, None) * DEFAULT_DENSITY_KG_M3
    S = int(samples)
    aadt = np.exp(rng.uniform(*np.log(tr["vehicles_per_day"]), S))
    lanes = rng.choice(np.asarray(tr["lanes"]), S)
    speed = rng.uniform(*tr["speed_kmh"], S)
    occ = rng.uniform(*tr["occupants"], S)
    lo, hi = vulnerability.factor_range
    fac = np.exp(rng.uniform(np.log(lo), np.log(hi), S)) if hi > lo else np.full(S, lo)
    _, ilo, ihi = vulnerability.injury_given_survival
    inj = rng.uniform(ilo, ihi, S)
    out = {k: np.empty(S) for k in ("vehicles involved", "deaths", "injuries", "deaths_direct", "deaths_strike")}
    for s in range(S):
        la = lanes_from_traffic(aadt[s], speed[s], 1 if two_way else int(lanes[s]))
        ph = lane_hit_probability(la, tr["vehicle_length_m"])
        ps = lane_strike_probability(la, tr["hours_on_road"], tr["p_cannot_stop"])
        vd = vulnerability.probability(mass, "direct", fac[s]).mean()
        vs = vulnerability.probability(mass, "strike", fac[s]).mean()
        out["vehicles involved"][s] = ph + ps
        out["deaths_direct"][s] = occ[s] * ph * vd
        out["deaths_strike"][s] = occ[s] * ps * vs
        out["deaths"][s] = out["deaths_direct"][s] + out["deaths_strike"][s]
        out["injuries"][s] = occ[s] * (ph * (1 - vd) + ps * (1 - vs)) * inj[s]
    return RoadValidation(rec, out, tr, vulnerability, seed)


__all__ = ["HONG_KONG_TRAFFIC", "RoadRecords", "RoadValidation", "hong_kong_road_validation", "poisson_interval",
           "read_hong_kong_road_records"]
