"""Rock falls reaching a road, and the risk to its users, per metre along the road (3-D terrain).

On 3-D terrain a road is a line in plan, and the simulated blocks cross it at positions that the terrain
decides (gullies gather them, spurs shed them).  From a run with masses spread log-uniformly over the mass
model's range (:func:`riskrf.energy_hazard`, :class:`~riskrf.hazard.mass_coupling.MassCoupledSamples`), each
simulated block stands for

    w_b = rate x P(M in class(b)) / n_class(b)          [falls per year]

falls released per year (``rate`` falls per year above m_min at the source, ``P(M in class)`` under the mass
model, ``n_class`` blocks simulated in the class).  Summing w_b over the blocks whose first crossing of the
road lies in a bin of ``bin_m`` metres gives the annual frequency of falls reaching that stretch; divided by
the bin length, per metre.  The share per metre (the same sum without ``rate``) is the probability that one
released fall reaches the road in that metre.

Road users per metre: the expected deaths and injuries per fall reaching the road for the masses that reach
each bin are those of :func:`riskrf.risk.road_users.per_fall_risk` (Bunce et al. 1997 per lane, a rock left on
the road, vulnerability by mass); multiplied by the frequency per metre they give deaths and injuries per year
per metre of road.  Within a mass class the simulated blocks have equal weight, so each (bin, class) group
calls :func:`per_fall_risk` with its own masses.

References
----------
Bunce, C.M., Cruden, D.M. & Morgenstern, N.R. (1997). Assessment of the hazard from rock fall on a highway.
Can. Geotech. J. 34: 344-356.
Hantz, D., Corominas, J., Crosta, G.B. & Jaboyedoff, M. (2021). Definitions and concepts for quantitative
rockfall hazard and risk analysis. Geosciences 11(4): 158 (frequency of arrivals by block size).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..core.validation import RiskrfError
from .road_users import DEFAULT_VULNERABILITY, Vulnerability, per_fall_risk


class RoadProfileError(RiskrfError, ValueError):
    """Inputs of a per-metre road profile are inconsistent; the message names the argument and value."""


@dataclass(frozen=True)
class RoadRiskProfile:
    """Falls reaching a road line and road-user risk per metre along it.

    ``table`` has one row per bin: ``start_m``, ``end_m`` (position along the road line from its first vertex
    [m]), ``reach_share_per_m`` (probability per released fall of reaching the road in that metre [1/m]),
    ``falls_per_year_per_m`` [1/(yr m)], ``deaths_per_year_per_m``, ``injuries_per_year_per_m``
    [1/(yr m)], ``blocks`` (simulated blocks behind the row).  ``road`` names the line, ``length_m`` its length,
    ``rate_per_year`` the falls per year at the source, ``notes`` the assumptions.
    """

    road: str
    length_m: float
    bin_m: float
    rate_per_year: float
    table: pd.DataFrame = field(repr=False)
    notes: tuple = ()

    def summary(self) -> pd.DataFrame:
        """The per-bin table (a copy).

        Returns
        -------
        pandas.DataFrame
            One row per bin: ``start_m``, ``end_m`` [m], ``reach_share_per_m`` [1/m], ``falls_per_year_per_m``,
            ``deaths_per_year_per_m``, ``injuries_per_year_per_m`` [1/(yr m)] and ``blocks``.
        """
        return self.table.copy()

    def totals(self) -> dict:
        """Whole-road figures: reach share, falls, deaths and injuries per year, and the worst metre.

        Returns
        -------
        dict
            ``road``, ``length_m`` [m], ``reach_share`` [-], ``falls_per_year``, ``deaths_per_year``,
            ``injuries_per_year`` [1/yr], ``worst_metre_start_m`` [m] and ``worst_deaths_per_year_per_m`` [1/(yr m)].
        """
        t = self.table
        w = t["end_m"] - t["start_m"]
        worst = int(t["deaths_per_year_per_m"].to_numpy().argmax()) if len(t) else 0
        return {"road": self.road, "length_m": self.length_m,
                "reach_share": float((t["reach_share_per_m"] * w).sum()),
                "falls_per_year": float((t["falls_per_year_per_m"] * w).sum()),
                "deaths_per_year": float((t["deaths_per_year_per_m"] * w).sum()),
                "injuries_per_year": float((t["injuries_per_year_per_m"] * w).sum()),
                "worst_metre_start_m": float(t["start_m"].iloc[worst]) if len(t) else float("nan"),
                "worst_deaths_per_year_per_m": float(t["deaths_per_year_per_m"].iloc[worst]) if len(t)
                else float("nan")}

    def plot(self, ax=None):
        """Falls and deaths per year per metre along the road (matplotlib axes).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            The axes of the falls (deaths on a twin axis).
        """
        from .figures import plot_road_profile
        return plot_road_profile(self, ax=ax)

    def __repr__(self) -> str:
        t = self.totals()
        return (f"RoadRiskProfile({self.road!r}, {self.length_m:.0f} m, {t['falls_per_year']:.3g} falls/yr, "
                f"{t['deaths_per_year']:.3g} deaths/yr)")


def block_weights_per_year(samples, mass_model, rate_per_year: float) -> np.ndarray:
    """Falls per year [1/yr] that each simulated block of a mass-coupled run stands for:
    rate x P(M in its class) / blocks simulated in its class (see the module docstring).

    Parameters
    ----------
    samples : riskrf.hazard.mass_coupling.MassCoupledSamples
        The mass-coupled run (masses [kg] and mass classes of every released block).
    mass_model : object
        The mass law [kg] of falls at the source (e.g. a truncated GutenbergRichterFit).
    rate_per_year : float
        Falls per year at the source [1/yr].

    Returns
    -------
    numpy.ndarray
        Weight of each block [1/yr].
    """
    from ..hazard.mass_models import mass_model as _wrap
    cls = samples.class_of(samples.mass_kg)
    counts = np.bincount(cls, minlength=samples.n_bins).astype(float)
    return float(rate_per_year) * samples.class_weights(_wrap(mass_model))[cls] / counts[cls]


def road_risk_along_line(samples, mass_model, rate_per_year: float, position_m, length_m: float, *,
                         road: str = "road", bin_m: float = 1.0, lanes=None, vehicle_length_m: float = 5.0,
                         occupants: float = 1.5, hours_on_road: float = 0.5, p_cannot_stop: float = 0.002,
                         share_stopping_on_road: float = 1.0,
                         vulnerability: Vulnerability = DEFAULT_VULNERABILITY) -> RoadRiskProfile:
    """Falls reaching the road and road-user risk per metre along a road line.

    Parameters
    ----------
    samples : MassCoupledSamples
        The mass-coupled run (masses and mass classes of every released block).
    mass_model : mass model (e.g. a truncated GutenbergRichterFit)
        The mass law [kg] of falls at the source.
    rate_per_year : float
        Falls per year at the source described by the mass model [1/yr].
    position_m : array (one per released block)
        Position [m] along the road line of the block's first crossing; NaN when it never reached the road.
    length_m : float
        Length of the road line [m].
    bin_m : float
        Bin length along the road [m] (1: per metre).
    lanes : sequence of Lane
        The road's lanes (:func:`riskrf.risk.road_users.lanes_from_traffic`); None: no road-user figures
        (deaths and injuries NaN).
    vehicle_length_m, occupants, hours_on_road, p_cannot_stop, share_stopping_on_road, vulnerability
        As in :func:`riskrf.risk.road_users.per_fall_risk`.

    Returns
    -------
    RoadRiskProfile
    """
    pos = np.asarray(position_m, dtype=float)
    if pos.shape != samples.mass_kg.shape:
        raise RoadProfileError(f"position_m has {pos.size} values; the run released {samples.mass_kg.size} blocks "
                               "(one position per block, NaN where it never reached the road)")
    if not (np.isfinite(length_m) and length_m > 0):
        raise RoadProfileError(f"length_m = {length_m!r} must be a road length > 0 m")
    if not (np.isfinite(bin_m) and 0 < bin_m <= length_m):
        raise RoadProfileError(f"bin_m = {bin_m!r} must lie in (0, length_m = {length_m:g}] m")
    if not (np.isfinite(rate_per_year) and rate_per_year > 0):
        raise RoadProfileError(f"rate_per_year = {rate_per_year!r} must be > 0 falls per year")
    reached = np.isfinite(pos)
    if np.any((pos[reached] < -1e-6) | (pos[reached] > length_m + 1e-6)):
        bad = pos[reached][(pos[reached] < -1e-6) | (pos[reached] > length_m + 1e-6)][0]
        raise RoadProfileError(f"position_m = {bad:g} lies outside the road line (0-{length_m:g} m)")
    w = block_weights_per_year(samples, mass_model, rate_per_year)
    cls = samples.class_of(samples.mass_kg)
    edges = np.arange(0.0, length_m + bin_m, bin_m)
    edges[-1] = length_m
    if edges.size >= 2 and edges[-1] - edges[-2] <= 1e-9:
        edges = edges[:-1]
        edges[-1] = length_m
    nb = edges.size - 1
    b = np.clip(np.searchsorted(edges, pos[reached], side="right") - 1, 0, nb - 1)
    falls = np.bincount(b, weights=w[reached], minlength=nb)
    share = falls / float(rate_per_year)
    blocks = np.bincount(b, minlength=nb)
    deaths = np.full(nb, np.nan)
    injuries = np.full(nb, np.nan)
    if lanes is not None:
        deaths[:] = 0.0
        injuries[:] = 0.0
        m_r, w_r, c_r = samples.mass_kg[reached], w[reached], cls[reached]
        for key in np.unique(b * samples.n_bins + c_r):
            sel = (b * samples.n_bins + c_r) == key
            risk = per_fall_risk(lanes, m_r[sel], vehicle_length_m=vehicle_length_m, occupants=occupants,
                                 hours_on_road=hours_on_road, p_cannot_stop=p_cannot_stop,
                                 share_stopping_on_road=share_stopping_on_road, vulnerability=vulnerability)
            f = w_r[sel].sum()
            deaths[key // samples.n_bins] += f * risk.deaths
            injuries[key // samples.n_bins] += f * risk.injuries
    width = np.diff(edges)
    table = pd.DataFrame({"start_m": edges[:-1], "end_m": edges[1:], "reach_share_per_m": share / width,
                          "falls_per_year_per_m": falls / width, "deaths_per_year_per_m": deaths / width,
                          "injuries_per_year_per_m": injuries / width, "blocks": blocks})
    notes = (f"each simulated block stands for rate x P(M in its mass class) / blocks in the class falls per year "
             f"({samples.mass_kg.size:,} blocks, {samples.n_bins} classes)",
             "road users: Bunce et al. (1997) per lane and a rock left on the road (riskrf.risk.road_users."
             "per_fall_risk), vulnerability by block mass" if lanes is not None else
             "no traffic given: falls per metre only")
    return RoadRiskProfile(road=road, length_m=float(length_m), bin_m=float(bin_m), rate_per_year=float(rate_per_year),
                           table=table, notes=notes)


def vulnerability_from_consequences(consequences) -> Vulnerability:
    """The site's vulnerabilities (:class:`riskrf.risk.mitigation_inputs.Consequences`: a number or
    [[mass_kg, probability], ...] each) as a :class:`Vulnerability` (a number: the same at every mass).

    Parameters
    ----------
    consequences : riskrf.risk.mitigation_inputs.Consequences
        The site's consequences (``vulnerability_moving_vehicle``, ``vulnerability_striking_rock``: a probability
        [-] or pairs (mass [kg], probability [-])).

    Returns
    -------
    riskrf.risk.road_users.Vulnerability
        The vulnerability model.
    """
    def table(v):
        return ((1.0, float(v)),) if np.ndim(v) == 0 else tuple(map(tuple, np.asarray(v, dtype=float).tolist()))
    return Vulnerability(direct=table(consequences.vulnerability_moving_vehicle),
                         strike=table(consequences.vulnerability_striking_rock),
                         injury_given_survival=DEFAULT_VULNERABILITY.injury_given_survival,
                         basis="the site's [consequences]")


__all__ = ["RoadProfileError", "RoadRiskProfile", "block_weights_per_year", "road_risk_along_line",
           "vulnerability_from_consequences"]
