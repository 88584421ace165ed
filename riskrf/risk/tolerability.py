"""Tolerability criteria as data: individual risk limits, F-N lines and marginal costs of agencies.

A :class:`CriteriaSet` holds one agency's published numbers; :data:`CRITERIA_SETS` names the sets a site file
selects with ``[criteria] set = "..."`` and ``slope = "existing" | "new"``; ``set = "user"`` takes its own
individual-risk limit, F-N line and marginal cost from the same table (:func:`user_criteria`).

Each number carries where it was read and how sure it is ("V": read in the source or a faithful
reproduction; "R": recalled from the literature, not re-read here):

* **Hong Kong GEO (1998)** - ERM-Hong Kong for GEO, GEO Report No. 75, "Landslides and boulder falls from
  natural terrain: interim risk guidelines": F-N lines of slope -1 through F = 1e-3 /yr (unacceptable above)
  and 1e-5 /yr (broadly acceptable below) at N = 1, drawn to N = 1,000; "intense scrutiny" for N = 1,000-5,000
  and N > 5,000 unacceptable [R; shared/research/domain-methods.md 4.2].  Individual risk 1e-4 /yr (existing
  slopes) and 1e-5 /yr (new) [R, the pair GEO shares with AGS 2007].
* **AGS (2007)** - Australian Geomechanics Society, "Practice note guidelines for landslide risk management",
  Australian Geomechanics 42(1), section 7, Table 1: tolerable loss-of-life individual risk for the person
  most at risk 1e-4 /yr for existing slopes, 1e-5 /yr for new slopes [V: AGS's own landslide-risk teaching
  site, regulators module question 10, citing AGS 2007c p. 68, states that AGS recommends tolerable
  loss-of-life values for the person most at risk; the 1e-4 / 1e-5 pair is R, high confidence]; for societal
  risk the commentary (AGS 2007d) points to the GEO (1998) diagram, used here [R].
* **UK HSE, R2P2 (2001)** - "Reducing risks, protecting people", HSE Books, ISBN 0 7176 2151 0, "Tolerability
  limits" pp. 44-47: individual risk of death 1 in 10,000 a year for members of the public as the limit of
  tolerability (para 130), 1 in 1,000,000 a year broadly acceptable (para 130) [V: the R2P2 text on
  tolerability limits reproduced in a third-party copy read on 2026-11-25 gives "1 in 10,000 per annum" for
  members of the public and 1 in 1,000,000 at the broadly acceptable end]; societal: 50 or more deaths in
  one event more often than 1 in 5,000 years intolerable (para 136) [R; contents page V,
  studylib.net/doc/8689343].  The point (N = 50, F = 2e-4) is drawn as a line of slope -1 (F = 1e-2 / N), the
  usual extension; R2P2 itself gives the point only.  No distinction between existing and new.
* **Switzerland (PLANAT 2013; ASTRA practice)** - individual risk of death from gravitational natural hazards
  at most 1e-5 /yr, not negotiable; a measure costing less than CHF 5 million per death avoided is "very
  effective" and should be built (marginal cost) [V: Canton of Bern, Naturgefahren, "Schutzziele",
  naturgefahren.sites.be.ch/.../schutzziele.html, applying the PLANAT recommendations]; no F-N criterion.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd


@dataclass(frozen=True)
class FNLine:
    """A criterion line F = C / N^k [1/yr] for n_min <= N <= n_max."""

    c: float
    k: float = 1.0
    n_min: float = 1.0
    n_max: float = np.inf

    def frequency(self, n) -> np.ndarray:
        """F on the line at N = ``n``.

        Parameters
        ----------
        n : float or array_like
            Number of deaths N [persons].

        Returns
        -------
        numpy.ndarray
            F [1/yr], shaped as ``n``.
        """
        return self.c / np.asarray(n, dtype=float) ** self.k


@dataclass(frozen=True)
class CriteriaSet:
    """One agency's tolerability criteria (see the module docstring for the sources)."""

    key: str
    name: str
    source: str
    individual_risk: dict                   # {"existing": limit, "new": limit} [1/yr], tolerable at or below
    individual_broadly_acceptable: float | None = None
    fn_unacceptable: FNLine | None = None   # unacceptable above
    fn_acceptable: FNLine | None = None     # broadly acceptable below
    scrutiny_band: tuple | None = None      # (N1, N2): intense scrutiny between, unacceptable above N2
    marginal_cost_per_life: float | None = None
    marginal_cost_currency: str = ""
    evidence: str = "R"

    def individual_limit(self, slope: str = "existing") -> float:
        """Tolerable individual risk [1/yr] for an ``existing`` or ``new`` slope.

        Parameters
        ----------
        slope : str, optional
            ``"existing"`` or ``"new"``.

        Returns
        -------
        float
            The limit [1/yr].

        Raises
        ------
        ValueError
            When ``slope`` is not a key of the set.

        References
        ----------
        ERM-Hong Kong (1998). Landslides and boulder falls from natural terrain: interim risk guidelines. GEO Report
        No. 75, Geotechnical Engineering Office, Hong Kong.

        AGS (2007). Australian Geomechanics Society, Practice note guidelines for landslide risk management. Australian
        Geomechanics 42(1).

        HSE (2001). Reducing risks, protecting people: HSE's decision-making process (R2P2). HSE Books.
        """
        if slope not in self.individual_risk:
            raise ValueError(f"criteria {self.key!r}: slope = {slope!r} must be one of {sorted(self.individual_risk)}")
        return float(self.individual_risk[slope])

    def fn_zone(self, fn: pd.DataFrame) -> str:
        """Where an F-N curve (columns N, F) lies: "unacceptable", "intense scrutiny", "ALARP", "broadly
        acceptable", or "no societal criterion" for a set without F-N lines.

        Parameters
        ----------
        fn : pandas.DataFrame
            F-N curve: columns ``N`` (deaths [persons]) and ``F`` (frequency of N or more [1/yr]).

        Returns
        -------
        str
            The zone.

        References
        ----------
        ERM-Hong Kong (1998). Landslides and boulder falls from natural terrain: interim risk guidelines. GEO Report
        No. 75, Geotechnical Engineering Office, Hong Kong.

        AGS (2007). Australian Geomechanics Society, Practice note guidelines for landslide risk management. Australian
        Geomechanics 42(1).

        HSE (2001). Reducing risks, protecting people: HSE's decision-making process (R2P2). HSE Books.
        """
        if self.fn_unacceptable is None:
            return "no societal criterion"
        if len(fn) == 0 or not np.any(fn["F"] > 0):
            return "broadly acceptable"
        N, F = fn["N"].to_numpy(dtype=float), fn["F"].to_numpy(dtype=float)
        up = self.fn_unacceptable
        on = (N >= up.n_min) & (N <= up.n_max)
        if np.any(F[on] > up.frequency(N[on])):
            return "unacceptable"
        if self.scrutiny_band is not None:
            n1, n2 = self.scrutiny_band
            if np.any(F[N > n2] > 0):
                return "unacceptable"
            if np.any(F[(N > n1) & (N <= n2)] > 0):
                return "intense scrutiny"
        lo = self.fn_acceptable
        if lo is not None:
            on = (N >= lo.n_min) & (N <= lo.n_max)
            if np.any(F[on] > lo.frequency(N[on])):
                return "ALARP"
            return "broadly acceptable"
        return "ALARP"

    def fn_exceedance(self, F, N) -> np.ndarray:
        """Largest ratio F(N) / line(N) over N (arrays ... x len(N)); > 1 means above the unacceptable line.

        Parameters
        ----------
        F : array_like
            Frequencies of N or more deaths [1/yr], last axis along ``N``.
        N : array_like
            Numbers of deaths [persons].

        Returns
        -------
        numpy.ndarray
            Largest ratio [-], shape ``F.shape[:-1]``; zeros for a set without F-N lines.
        """
        if self.fn_unacceptable is None:
            return np.zeros(np.shape(F)[:-1])
        up = self.fn_unacceptable
        N = np.asarray(N, dtype=float)
        on = (N >= up.n_min) & (N <= up.n_max)
        ratio = np.asarray(F, dtype=float)[..., on] / up.frequency(N[on])
        return ratio.max(axis=-1) if ratio.shape[-1] else np.zeros(np.shape(F)[:-1])

    def tolerable(self, individual_risk: float, fn: pd.DataFrame, slope: str = "existing") -> bool:
        """Individual risk at or below the limit and the F-N curve outside the unacceptable region.

        Parameters
        ----------
        individual_risk : float
            Individual risk of death of the person most at risk [1/yr].
        fn : pandas.DataFrame
            F-N curve: columns ``N`` (deaths [persons]) and ``F`` (frequency of N or more [1/yr]).
        slope : str, optional
            ``"existing"`` or ``"new"``.

        Returns
        -------
        bool
            True when both criteria are met.
        """
        return bool(individual_risk <= self.individual_limit(slope)
                    and self.fn_zone(fn) not in ("unacceptable", "intense scrutiny"))

    def describe(self, slope: str = "existing") -> str:
        """The criteria in one sentence.

        Parameters
        ----------
        slope : str, optional
            ``"existing"`` or ``"new"``.

        Returns
        -------
        str
            Limits in [1/yr], marginal cost per life in the set's currency (e.g. [CHF]).
        """
        parts = [f"individual risk <= {self.individual_limit(slope):.0e}/yr ({slope} slope)"]
        if self.fn_unacceptable is not None:
            up = self.fn_unacceptable
            parts.append(f"F-N below F = {up.c:.0e}/N^{up.k:g}")
        if self.marginal_cost_per_life:
            parts.append(f"measures up to {self.marginal_cost_per_life:,.0f} {self.marginal_cost_currency} per "
                         "statistical life saved are expected")
        return f"{self.name}: " + "; ".join(parts)

    def summary(self) -> pd.DataFrame:
        """The set's numbers, one row each, with the source.

        Returns
        -------
        pandas.DataFrame
            Columns ``criterion`` (with its unit), ``value``, ``source`` and ``evidence``.
        """
        rows = [{"criterion": f"individual risk, {k} slope [1/yr]", "value": v} for k, v in self.individual_risk.items()]
        if self.individual_broadly_acceptable:
            rows.append({"criterion": "individual risk broadly acceptable [1/yr]",
                         "value": self.individual_broadly_acceptable})
        for label, line in (("F-N unacceptable above: F = C/N^k, C", self.fn_unacceptable),
                            ("F-N broadly acceptable below: C", self.fn_acceptable)):
            if line is not None:
                rows.append({"criterion": label, "value": line.c})
        if self.marginal_cost_per_life:
            rows.append({"criterion": f"marginal cost per statistical life [{self.marginal_cost_currency}]",
                         "value": self.marginal_cost_per_life})
        df = pd.DataFrame(rows)
        df["source"] = self.source
        df["evidence"] = self.evidence
        return df


_GEO_UP = FNLine(1e-3, 1.0, 1.0, 1000.0)
_GEO_LO = FNLine(1e-5, 1.0, 1.0, 1000.0)

CRITERIA_SETS = {
    "hong-kong-geo-1998": CriteriaSet(
        "hong-kong-geo-1998", "Hong Kong GEO Report 75 (1998)",
        "ERM-Hong Kong for GEO (1998), GEO Report No. 75, societal risk diagram",
        {"existing": 1e-4, "new": 1e-5}, None, _GEO_UP, _GEO_LO, (1000.0, 5000.0)),
    "ags-2007": CriteriaSet(
        "ags-2007", "AGS (2007)", "AGS (2007c) Australian Geomechanics 42(1), section 7, Table 1; societal: the "
        "GEO (1998) diagram as the commentary AGS (2007d) refers to it",
        {"existing": 1e-4, "new": 1e-5}, 1e-6, _GEO_UP, _GEO_LO, (1000.0, 5000.0)),
    "uk-hse-r2p2": CriteriaSet(
        "uk-hse-r2p2", "UK HSE R2P2 (2001)", "HSE (2001) Reducing risks, protecting people, paras 130 and 136, "
        "pp. 44-47", {"existing": 1e-4, "new": 1e-4}, 1e-6, FNLine(1e-2, 1.0, 1.0, np.inf), None),
    "swiss-planat": CriteriaSet(
        "swiss-planat", "Switzerland, PLANAT (2013) / ASTRA", "individual risk 1e-5/yr and CHF 5 million per death "
        "avoided (Canton of Bern 'Schutzziele', applying PLANAT 2013)", {"existing": 1e-5, "new": 1e-5}, None,
        None, None, None, 5.0e6, "CHF", "V"),
}


def user_criteria(individual_risk_per_year: float, fn_c: float | None = None, fn_k: float = 1.0,
                  fn_acceptable_c: float | None = None, marginal_cost_per_life: float | None = None,
                  currency: str = "") -> CriteriaSet:
    """A criteria set of the user's own: an individual-risk limit, an optional F-N line F = fn_c / N^fn_k
    (unacceptable above) and broadly-acceptable line (same slope), an optional marginal cost per life.

    Parameters
    ----------
    individual_risk_per_year : float
        Tolerable individual risk [1/yr], > 0.
    fn_c : float, optional
        C of the unacceptable line [1/yr] at N = 1.
    fn_k : float, optional
        Slope k of the F-N lines [-], in (0, 3].
    fn_acceptable_c : float, optional
        C of the broadly acceptable line [1/yr] at N = 1.
    marginal_cost_per_life : float, optional
        Marginal cost per statistical life saved [currency/life], e.g. [CHF].
    currency : str, optional
        Currency of the marginal cost.

    Returns
    -------
    CriteriaSet
        The set, key ``"user"``.

    Raises
    ------
    ValueError
        When a number is not > 0 or ``fn_k`` is out of range.
    """
    for name, v in (("individual_risk_per_year", individual_risk_per_year), ("fn_c", fn_c),
                    ("fn_acceptable_c", fn_acceptable_c), ("marginal_cost_per_life", marginal_cost_per_life)):
        if v is not None and (isinstance(v, bool) or not np.isfinite(v) or v <= 0):
            raise ValueError(f"criteria.{name} = {v!r} must be a number > 0")
    if not (isinstance(fn_k, (int, float)) and 0 < fn_k <= 3):
        raise ValueError(f"criteria.fn_k = {fn_k!r} must be a slope between 0 and 3 (1: risk-neutral, 2: averse)")
    return CriteriaSet("user", "user-defined criteria", "site file [criteria]",
                       {"existing": individual_risk_per_year, "new": individual_risk_per_year}, None,
                       None if fn_c is None else FNLine(fn_c, fn_k),
                       None if fn_acceptable_c is None else FNLine(fn_acceptable_c, fn_k), None,
                       marginal_cost_per_life, currency, "user")


def cost_per_statistical_life_saved(extra_cost_pv, other_losses_saved_pv, deaths_avoided_per_year, horizon_years):
    """Cost per statistical life saved [currency/life] of a measure against a reference: (PV of its extra cost
    minus PV of the non-fatal losses it saves) / (deaths avoided per year x horizon).  inf when it saves no life;
    <= 0 when it pays for itself.

    Parameters
    ----------
    extra_cost_pv : float or array_like
        Present value of the measure's extra cost [currency], e.g. [CHF].
    other_losses_saved_pv : float or array_like
        Present value of the non-fatal losses it saves [currency].
    deaths_avoided_per_year : float or array_like
        Deaths avoided [1/yr].
    horizon_years : float
        Horizon [yr].

    Returns
    -------
    float or numpy.ndarray
        Cost per statistical life saved [currency/life].
    """
    lives = np.asarray(deaths_avoided_per_year, dtype=float) * float(horizon_years)
    net = np.asarray(extra_cost_pv, dtype=float) - np.asarray(other_losses_saved_pv, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(lives > 0, net / np.where(lives > 0, lives, 1.0), np.inf)
    return float(out) if out.ndim == 0 else out


__all__ = ["CRITERIA_SETS", "CriteriaSet", "FNLine", "cost_per_statistical_life_saved", "user_criteria"]
