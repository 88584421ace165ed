"""The mass model of one fall [kg]: the :class:`MassModel` protocol the energy, hazard and risk calculations call,
and :func:`mass_model`, the one place that looks at the type of a mass description.

Accepted descriptions: a fitted power law (:class:`~riskrf.GutenbergRichterFit` in kg, the truncated law between
m_min and m_max, carrying its rate above m_min), a Gumbel/GEV fit of annual maxima (then E is the energy of the
year's largest block; its bootstrap draws the parameters from their covariance), any scipy frozen distribution
with a positive support, an array of masses (empirical law), or a user-written :class:`MassModel`.  The velocity
models are in :mod:`riskrf.hazard.velocity_models`, P(E > e) in :mod:`riskrf.hazard.impact_energy`.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import replace

import numpy as np

from ..frequency.extremes import _AnnualMaximumFit
from ..frequency.power_law import GutenbergRichterFit
from ..core.format import sig


def _positive_samples(values, name):
    arr = np.asarray(values, dtype=float).ravel()
    if arr.size == 0:
        raise ValueError(f"{name} samples are empty")
    bad = ~np.isfinite(arr) | (arr < 0)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{name} sample [{i}] = {float(arr[i])!r}: samples must be finite and >= 0")
    return arr


# ---------------------------------------------------------------- mass models
class MassModel(ABC):
    """What the energy, hazard and risk calculations ask of a mass model [kg] of one fall.

    Every accepted mass description (a :class:`~riskrf.GutenbergRichterFit`, a Gumbel/GEV fit of annual maxima,
    a scipy frozen distribution or an array of masses) is wrapped by :func:`mass_model`, the one place that looks
    at its type; the calculations then call these methods.  A user-written model subclasses this class and gives
    at least ``sf``, ``isf`` and ``rvs``; the other members have the defaults of a law with no parameters to vary.

    Attributes
    ----------
    description : str
        One line naming the model (in summaries and reports).
    support : tuple of float
        Lowest and highest mass [kg] the model gives.
    rate_per_year : float or None
        Falls per year the model itself carries (a fitted power law: its rate above m_min), else None.  Callers
        must then be given the rate; the T-year block isf(1 / (T rate)) is reported only for models that carry
        their rate, so that the law and the rate come from the same inventory.
    power_law : GutenbergRichterFit or None
        The power law behind the model, for the calculations that vary its exponent b or truncation m_max
        (risk-engine sampling, design-energy tornado); None for models without those parameters.
    """

    description: str = "user mass model"
    rate_per_year: float | None = None
    power_law = None

    @abstractmethod
    def sf(self, mass_kg):
        """P(M > m) for masses ``mass_kg`` [kg] (vectorised).

        Parameters
        ----------
        mass_kg : float or numpy.ndarray
            Masses [kg].

        Returns
        -------
        numpy.ndarray
            Probabilities [-], the shape of ``mass_kg``.
        """

    @abstractmethod
    def isf(self, p):
        """The mass [kg] exceeded with probability ``p`` (vectorised).

        Parameters
        ----------
        p : float or numpy.ndarray
            Exceedance probabilities [-].

        Returns
        -------
        numpy.ndarray
            Masses [kg], the shape of ``p``.
        """

    @abstractmethod
    def rvs(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """``n`` masses [kg] drawn with ``rng``.

        Parameters
        ----------
        n : int
            Number of masses.
        rng : numpy.random.Generator
            Random generator.

        Returns
        -------
        numpy.ndarray
            ``n`` masses [kg].
        """

    @property
    def support(self) -> tuple:
        """Lowest and highest mass [kg] of the model (default: ``isf(1)`` and ``isf(0)``)."""
        return (float(self.isf(1.0)), float(self.isf(0.0)))

    def perturbed(self, rng: np.random.Generator, rate_per_year: float):
        """One bootstrap replicate of the model and of the fall rate [1/yr]: (mass model, rate).  Default: both
        unchanged (no fitted parameters to resample).

        Parameters
        ----------
        rng : numpy.random.Generator
            Random generator of the bootstrap.
        rate_per_year : float
            Falls per year [1/yr] of the hazard.

        Returns
        -------
        tuple
            (mass model accepted by :func:`mass_model`, rate [1/yr]) of the replicate.
        """
        return self, rate_per_year

    def grid_bounds_kg(self, top_kg: float | None = None) -> tuple:
        """Lowest and highest mass [kg] of a mass grid covering the model (``top_kg``: a sampled m_max the grid
        must reach, used by power laws only).  Default: the 1 - 1e-9 and 1e-9 quantiles.

        Parameters
        ----------
        top_kg : float, optional
            Largest sampled truncation m_max [kg] the grid must reach (power laws only).

        Returns
        -------
        tuple of float
            (lowest, highest) mass [kg].
        """
        return float(self.isf(1 - 1e-9)), float(self.isf(1e-9))

    def bin_probabilities(self, edges_kg: np.ndarray, b=None, m_max=None) -> np.ndarray:
        """Probability of each mass bin between ``edges_kg`` [kg] for one fall, the last bin taking the tail: an
        array (1, J), or (S, J) for sampled power-law exponents ``b`` and truncations ``m_max`` [kg] (power laws
        only; ignored by other models).

        Parameters
        ----------
        edges_kg : numpy.ndarray
            Bin edges [kg], increasing (J + 1).
        b : numpy.ndarray, optional
            Sampled power-law exponents (S); None for the model's own law.
        m_max : numpy.ndarray, optional
            Sampled truncations [kg] (S), with ``b``.

        Returns
        -------
        numpy.ndarray
            Bin probabilities [-], (1, J) or (S, J).
        """
        sf = np.asarray(self.sf(edges_kg), dtype=float)
        sf[-1] = 0.0
        return np.clip(-np.diff(sf), 0.0, None)[None, :]



class _FunctionMass(MassModel):
    """A mass model given by its functions (scipy distribution, annual maximum, empirical masses)."""

    def __init__(self, sf, isf, rvs, description, support, source=None):
        self._sf, self._isf, self._rvs = sf, isf, rvs
        self.description, self._support, self.source = description, support, source

    def sf(self, mass_kg):
        return self._sf(mass_kg)

    def isf(self, p):
        return self._isf(p)

    def rvs(self, n, rng):
        return self._rvs(n, rng)

    @property
    def support(self):
        return self._support



class _AnnualMaximumMass(_FunctionMass):
    """A Gumbel/GEV fit of annual maxima: the bootstrap draws its parameters from their covariance."""

    def perturbed(self, rng, rate_per_year):
        m = self.source
        if m.cov is None:
            return m, rate_per_year
        params = rng.multivariate_normal(np.asarray(m.params), m.cov)
        if params[1] <= 0:
            params[1] = m.params[1]
        return replace(m, **dict(zip(m.param_names, map(float, params)))), rate_per_year



class _PowerLawMass(_FunctionMass):
    """A :class:`~riskrf.GutenbergRichterFit` in kg: carries its rate above m_min and its exponent b."""

    def __init__(self, fit):
        super().__init__(fit.sf, fit.isf, lambda n, rng: fit.rvs(n, rng),
                         f"power law b = {sig(fit.b)} above {sig(fit.m_min)} kg"
                         + (f", truncated at {sig(fit.m_max)} kg" if fit.m_max else ""), fit.support, fit)

    @property
    def power_law(self):
        return self.source

    @property
    def rate_per_year(self):
        return self.source.rate_min

    def perturbed(self, rng, rate_per_year):
        """b and the rate from their Jeffreys-prior posteriors, b x Gamma(n)/n and rate x Gamma(n)/n (n falls in
        the tail), the rate at m_min following the rate."""
        m = self.source
        n = m.n_tail
        b = m.b * rng.gamma(n) / n
        rate = rate_per_year * rng.gamma(n) / n
        return replace(m, b=float(b), a=float(np.log10(rate) + b * np.log10(m.m_min)), rate_min=float(rate)), rate

    def grid_bounds_kg(self, top_kg=None):
        m = self.source
        return m.m_min, max([m.m_max or m.m_min * 1e6] + ([top_kg] if top_kg else []))

    def bin_probabilities(self, edges_kg, b=None, m_max=None):
        if b is None:
            return super().bin_probabilities(edges_kg)
        m_min = self.source.m_min
        b = np.atleast_1d(b)[:, None]
        top = np.atleast_1d(m_max if m_max is not None else np.inf)[:, None]
        z = np.clip(edges_kg[None, :], m_min, top)
        with np.errstate(divide="ignore"):
            t = np.where(np.isfinite(top), top ** -b, 0.0)
        sf = (z ** -b - t) / (m_min ** -b - t)
        sf[:, -1] = 0.0                                     # the last bin takes the tail
        return np.clip(-np.diff(sf, axis=1), 0.0, None)


_MassModel = MassModel      # the former name



def mass_model(mass) -> MassModel:
    """Wrap any accepted mass description in the :class:`MassModel` interface (the one place that looks at its
    type); a :class:`MassModel` is returned as is.

    Parameters
    ----------
    mass : MassModel, GutenbergRichterFit, GumbelFit, GEVFit, scipy frozen distribution or array_like
        Mass model or samples [kg] (a power law must be in kg: :meth:`GutenbergRichterFit.to_mass`).

    Returns
    -------
    MassModel
        ``sf(m)``, ``isf(p)``, ``rvs(n, rng)`` of the mass of one fall [kg], a ``description``, the support and
        the protocol members the calculations call (``rate_per_year``, ``perturbed``, ``grid_bounds_kg``,
        ``bin_probabilities``, ``power_law``).
    """
    if isinstance(mass, MassModel):
        return mass
    if isinstance(mass, GutenbergRichterFit):
        if mass.units != "kg":
            raise ValueError(f"the power-law fit is in {mass.units!r}; convert it with .to_mass(density) first")
        return _PowerLawMass(mass)
    if isinstance(mass, _AnnualMaximumFit):
        d = mass.dist
        lo = float(d.ppf(1e-12))
        if lo <= 0:
            # Annual-maximum laws fitted to masses can put a little probability below zero: condition on m > 0.
            p0 = float(d.cdf(0.0))
            return _AnnualMaximumMass(lambda m: np.minimum(d.sf(np.maximum(m, 0.0)) / (1 - p0), 1.0),
                                      lambda p: d.isf(np.asarray(p) * (1 - p0)),
                                      lambda n, rng: d.isf(rng.uniform(size=n) * (1 - p0)),
                                      f"{type(mass).__name__[:-3]} annual maximum (conditioned on m > 0)",
                                      (0.0, np.inf), mass)
        return _AnnualMaximumMass(d.sf, d.isf, lambda n, rng: d.rvs(size=n, random_state=rng),
                                  f"{type(mass).__name__[:-3]} annual maximum", (lo, float(d.isf(1e-12))), mass)
    if hasattr(mass, "sf") and hasattr(mass, "isf") and hasattr(mass, "rvs"):
        lo = float(mass.ppf(0.0)) if hasattr(mass, "ppf") else 0.0
        if not np.isfinite(lo) or lo < 0:
            raise ValueError(f"mass model {getattr(mass.dist, 'name', mass)!r} has support reaching {lo:g} kg: "
                             "masses must be positive; use a positive distribution (lognormal, gamma, ...) or "
                             "truncate it")
        return _FunctionMass(mass.sf, mass.isf, lambda n, rng: mass.rvs(size=n, random_state=rng),
                             f"scipy {getattr(getattr(mass, 'dist', None), 'name', 'distribution')}",
                             (lo, float(mass.isf(0.0))), mass)
    m = np.sort(_positive_samples(mass, "mass"))
    if np.any(m <= 0):
        raise ValueError(f"mass samples must be > 0; found {int(np.sum(m <= 0))} zero masses")

    def sf(x):
        return 1.0 - np.searchsorted(m, x, side="right") / m.size

    def isf(p):
        return np.quantile(m, 1.0 - np.asarray(p), method="inverted_cdf")
    return _FunctionMass(sf, isf, lambda n, rng: rng.choice(m, size=n), f"empirical ({m.size:,} masses)",
                         (float(m[0]), float(m[-1])), mass)
