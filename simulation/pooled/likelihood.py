"""The likelihood of a pooled calibration: the kernel density of a release's simulated stops at its observed ones.

Per release, a Gaussian kernel of Silverman's width (at least the observation error) over the simulated stops,
mixed with a share :data:`DEFENSIVE_SHARE` spread uniformly over the profile (a defensive mixture); the logs of
its values at the observed stops add over the releases (:func:`_log_likelihood`; kernel ABC, Wilkinson 2013,
Stat. Appl. Genet. Mol. Biol. 12:129).  :func:`stop_density` and :func:`stop_bandwidth` give that density and
its width for one release's simulated stops.
"""
from __future__ import annotations

import math

import numpy as np

#: Share of the predictive density spread uniformly over the profile (the defensive mixture).
DEFENSIVE_SHARE = 1e-3


def _log_likelihood(sims, releases, lengths, obs_error_m) -> float:
    """Sum over releases of the log predictive density (:func:`_predictive_density`) at each observed stop."""
    s = np.vstack(sims)                                       # releases x n_per (the same n for all)
    x = np.concatenate([np.asarray(r.x_stop_m, dtype=float).ravel() for r in releases])
    ri = np.repeat(np.arange(len(releases)), [np.asarray(r.x_stop_m).size for r in releases])
    return float(np.sum(np.log(_predictive_density(s, x, ri, np.asarray(lengths, float), obs_error_m))))


def _bandwidths(s, obs_error_m):
    """Kernel width [m] per row of simulated stops: Silverman's rule, at least ``obs_error_m``."""
    q75, q25 = np.percentile(s, [75, 25], axis=1)
    sd = s.std(axis=1)
    spread = np.where(q75 > q25, np.minimum(sd, (q75 - q25) / 1.34), sd)
    return np.maximum(obs_error_m, 0.9 * spread * s.shape[1] ** -0.2)


def _predictive_density(s, x, ri, lengths, obs_error_m):
    """Gaussian-kernel density of the simulated stops of release ri (rows of s) at the observed stops x, mixed
    with a uniform share ``DEFENSIVE_SHARE`` over the release's profile length [1/m]."""
    h = _bandwidths(s, obs_error_m)[ri]
    zz = (x[:, None] - s[ri]) / h[:, None]
    dens = np.exp(-0.5 * zz * zz).mean(axis=1) / (h * math.sqrt(2.0 * math.pi))
    return (1.0 - DEFENSIVE_SHARE) * dens + DEFENSIVE_SHARE / lengths[ri]


def stop_density(simulated_x_m, x_m, length_m: float, obs_error_m: float = 0.5) -> np.ndarray:
    """Predictive density [1/m] of stops at ``x_m`` given one release's simulated stops: the per-stop likelihood
    of :func:`calibrate_pooled` (Gaussian kernel of Silverman's width, at least ``obs_error_m`` [m], mixed with a
    uniform share ``DEFENSIVE_SHARE`` over the profile length ``length_m`` [m]).  Exact inference for the
    simulator plus a Gaussian observation error of the kernel's width (Wilkinson 2013).

    Parameters
    ----------
    simulated_x_m : array_like
        The release's simulated stops [m] (at least 2, finite).
    x_m : array_like
        Stops at which to evaluate the density [m] (any shape).
    length_m : float
        Length of the profile [m] over which the defensive uniform share is spread (> 0).
    obs_error_m : float, optional
        Least kernel width [m], the observation error of a stop (default 0.5).

    Returns
    -------
    numpy.ndarray
        Density [1/m], the shape of ``x_m``.

    Raises
    ------
    ValueError
        Fewer than 2 finite simulated stops, or ``length_m`` not > 0.

    References
    ----------
    Wilkinson, R.D. (2013) Stat. Appl. Genet. Mol. Biol. 12:129.  Diggle, P.J. & Gratton, R.J. (1984) JRSS B
    46:193.
    """
    s = np.asarray(simulated_x_m, dtype=float).ravel()
    x = np.asarray(x_m, dtype=float)
    if s.size < 2 or not np.isfinite(s).all():
        raise ValueError(f"simulated_x_m must hold at least 2 finite stops [m]; got {s.size}")
    if not (np.isfinite(length_m) and length_m > 0):
        raise ValueError(f"length_m = {length_m!r} must be a profile length > 0 m")
    flat = x.ravel()
    out = _predictive_density(s[None, :], flat, np.zeros(flat.size, dtype=int), np.array([float(length_m)]),
                              obs_error_m)
    return out.reshape(x.shape)


def stop_bandwidth(simulated_x_m, obs_error_m: float = 0.5) -> float:
    """Kernel width [m] of :func:`stop_density` for one release's simulated stops.

    Parameters
    ----------
    simulated_x_m : array_like
        The release's simulated stops [m].
    obs_error_m : float, optional
        Least kernel width [m] (default 0.5).

    Returns
    -------
    float
        The larger of ``obs_error_m`` and Silverman's rule for the simulated stops [m].
    """
    return float(_bandwidths(np.asarray(simulated_x_m, dtype=float).ravel()[None, :], obs_error_m)[0])
