"""Where a pooled calibration simulates, and how it draws its posterior sample from the evaluations.

Every function works on the unit cube (the prior box scaled to [0, 1]).  :func:`_adaptive_design` is the
adaptive importance design: a Sobol design, then rounds drawn from a Student-t fitted to the importance weights
(:func:`_importance_weights`, the deterministic-mixture weights of :func:`_log_mixture`).  :func:`_posterior`
draws the posterior: from the Gaussian of a concave quadratic fit (:func:`_quadratic_surrogate`), else from the
Gaussian-process surrogate of :mod:`simulation.surrogate` after simulating where its posterior lies
(:func:`_refine_gp`, :func:`_gp_posterior`), else by ABC rejection (:func:`_abc_posterior`).
:func:`_bound_notes` flags a posterior cut by the prior box.  A posterior that deserves caution is warned of
with :class:`PooledCalibrationWarning`.
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
from scipy import stats

from ..surrogate import _in_unit_box, _t_draw, _t_logpdf, gp_posterior_sample, replicate_noise


class PooledCalibrationWarning(UserWarning):
    """The pooled calibration ran but its posterior deserves caution (few effective samples, mass at a bound)."""


def _log_mixture(u, proposals):
    """Log density of the defensive mixture of all proposals so far at the unit-cube points ``u``.

    Parameters
    ----------
    u : numpy.ndarray
        (n, d) points in the unit cube (the prior box scaled to [0, 1]).
    proposals : list of tuple
        (kind, number of points drawn, mean, covariance, truncation mass); kind "prior" is the uniform prior,
        "t" a multivariate t truncated to the unit cube.

    Returns
    -------
    numpy.ndarray
        (n,) log densities, each component weighted by its share of the points.
    """
    n_tot = sum(p[1] for p in proposals)
    terms = []
    for kind, n_k, mean, cov, z in proposals:
        if kind == "prior":
            terms.append(np.full(u.shape[0], math.log(n_k / n_tot)))
        else:
            terms.append(math.log(n_k / n_tot) + _t_logpdf(u, mean, cov) - math.log(z))
    return np.logaddexp.reduce(np.vstack(terms), axis=0)


def _importance_weights(u_all, ll_all, proposals):
    """Normalised importance weights (likelihood x prior / proposal mixture) of the evaluated points.

    Parameters
    ----------
    u_all : numpy.ndarray
        (n, d) evaluated points in the unit cube.
    ll_all : numpy.ndarray
        (n,) their log-likelihoods.
    proposals : list of tuple
        The proposals they were drawn from, see :func:`_log_mixture`.

    Returns
    -------
    numpy.ndarray
        (n,) weights summing to 1.
    """
    lw = ll_all - _log_mixture(u_all, proposals)
    w = np.exp(lw - lw.max())
    return w / w.sum()


def _adaptive_design(loglik, d, n_initial, n_per_iteration, iterations, rng_design, rng_prop):
    """The evaluated points: a scrambled Sobol design on the unit cube, then adaptive importance rounds.

    Each round fits a multivariate t (4 degrees of freedom, twice the weighted covariance) to the importance
    weights so far, draws ``n_per_iteration`` points from it inside the unit cube and evaluates them.

    Parameters
    ----------
    loglik : callable
        Log-likelihood of one unit-cube point.
    d : int
        Number of parameters.
    n_initial, n_per_iteration : int or None
        Points in the design (default the power of 2 at or above 64 d) and per round (default 32 d).
    iterations : int
        Adaptive rounds.
    rng_design, rng_prop : numpy.random.Generator
        Streams of the design and of the proposals.

    Returns
    -------
    tuple
        (points (n, d), log-likelihoods (n,), proposals as in :func:`_log_mixture`).
    """
    n0 = n_initial or 2 ** int(math.ceil(math.log2(64 * d)))
    n_it = n_per_iteration or 32 * d
    u_all = stats.qmc.Sobol(d, scramble=True, seed=rng_design).random(n0)
    ll_all = np.array([loglik(u) for u in u_all])
    # proposals: (kind, weight in the mixture, mean, cov, truncation mass); the first is the prior (uniform on the box)
    proposals = [("prior", n0, None, None, 1.0)]
    for _ in range(iterations):
        w = _importance_weights(u_all, ll_all, proposals)
        mean = np.sum(w[:, None] * u_all, axis=0)
        diff = u_all - mean
        cov = (w[:, None] * diff).T @ diff / max(1.0 - np.sum(w * w), 1e-12)
        cov = 2.0 * cov + np.eye(d) * 1e-6                      # widened: heavier than the target
        u_all, ll_all = _simulate_round(loglik, u_all, ll_all, proposals, mean, cov, n_it, rng_prop)
    return u_all, ll_all, proposals


def _simulate_round(loglik, u_all, ll_all, proposals, mean, cov, n_it, rng):
    """One round of new evaluations: ``n_it`` points from a multivariate t (4 degrees of freedom, ``mean``,
    ``cov``) truncated to the unit cube, appended to ``proposals`` (with the truncation mass, estimated from
    20,000 draws) and simulated.

    Parameters
    ----------
    loglik : callable
        Log-likelihood of one unit-cube point.
    u_all, ll_all : numpy.ndarray
        The points (n, d) and log-likelihoods (n,) so far.
    proposals : list of tuple
        See :func:`_log_mixture`; extended in place.
    mean, cov : numpy.ndarray
        Centre (d,) and scale matrix (d, d) of the t.
    n_it : int
        Points to draw.
    rng : numpy.random.Generator
        Stream of the draws.

    Returns
    -------
    tuple
        (points, log-likelihoods) with the round's appended.
    """
    test = _t_draw(rng, mean, cov, 20000)
    z = max(float(np.mean(np.all((test >= 0) & (test <= 1), axis=1))), 1e-6)
    new = _in_unit_box(lambda: _t_draw(rng, mean, cov, 4 * n_it), n_it)
    proposals.append(("t", n_it, mean, cov, z))
    return np.vstack([u_all, new]), np.concatenate([ll_all, [loglik(u) for u in new]])


def _posterior(u_all, ll_all, proposals, lo, hi, names, n_posterior, rng, refine=None):
    """The posterior: from the Gaussian surrogate when a concave quadratic fits the evaluations; else from the
    Gaussian-process surrogate, after simulating where its posterior lies while it extrapolates
    (:func:`_refine_gp`, with ``refine``); else by ABC rejection.

    Parameters
    ----------
    u_all, ll_all, proposals, lo, hi, names, n_posterior, rng
        As in :func:`_abc_posterior`.
    refine : tuple, optional
        (log-likelihood ``f(point, seed=...)`` of a unit-cube point, points per round, random stream, seeds
        independent of the evaluations') for the noise floor (:func:`simulation.surrogate.replicate_noise` at the
        :data:`N_REPLICATE` best points) and :func:`_refine_gp`; None: no new simulations and no noise floor.

    Returns
    -------
    tuple
        ((posterior DataFrame, effective sample size, notes), points, log-likelihoods, proposals), the last three
        with any refinement rounds' evaluations appended.
    """
    fitted = _surrogate_posterior(u_all, ll_all, lo, hi, names, n_posterior, rng)
    if fitted is None:
        gp, noise_floor = None, 0.0
        if refine is not None:
            loglik, n_it, rng_sim, seeds = refine
            best = u_all[np.argsort(np.where(np.isfinite(ll_all), ll_all, -np.inf))[::-1][:N_REPLICATE]]
            noise_floor = replicate_noise(lambda p, s: loglik(p, seed=s), best, seeds)
            u_all, ll_all, proposals, gp = _refine_gp(loglik, u_all, ll_all, proposals, n_it, rng_sim, noise_floor)
        fitted = _gp_posterior(u_all, ll_all, lo, hi, names, n_posterior, rng, gp=gp, noise_floor=noise_floor)
        if isinstance(fitted, str):                    # why the Gaussian process was not used
            post, ess, notes = _abc_posterior(u_all, ll_all, proposals, lo, hi, names, n_posterior, rng)
            fitted = post, ess, notes + [f"the Gaussian-process surrogate was not used: {fitted}"]
    return fitted, u_all, ll_all, proposals


def _surrogate_posterior(u_all, ll_all, lo, hi, names, n_posterior, rng):
    """Posterior sample from the Gaussian a quadratic fit of the log-likelihood defines, truncated to the box.

    The log-likelihood near its top is quadratic (smooth under common random numbers): sampling the Gaussian it
    defines averages out the Monte Carlo noise that makes a few evaluated points dominate the importance weights.

    Parameters
    ----------
    u_all, ll_all : numpy.ndarray
        Evaluated unit-cube points (n, d) and their log-likelihoods (n,).
    lo, hi : numpy.ndarray
        Prior bounds of each parameter.
    names : list of str
        Parameter paths (the columns).
    n_posterior : int
        Size of the sample.
    rng : numpy.random.Generator
        The resampling stream.

    Returns
    -------
    tuple or None
        (posterior DataFrame, effective sample size, notes), or None when no concave quadratic fits or the
        Gaussian puts no draw inside the box.
    """
    surrogate = _quadratic_surrogate(u_all, ll_all)
    if surrogate is None:
        return None
    mean, cov, r2 = surrogate
    draws = _in_unit_box(lambda: rng.multivariate_normal(mean, cov, size=4 * n_posterior), n_posterior, give_up=True)
    if draws is None:
        return None
    return (pd.DataFrame(lo + draws * (hi - lo), columns=names), float(n_posterior),
            [f"posterior: Gaussian surrogate of the log-likelihood (R^2 {r2:.3f} over the evaluations near its top), "
             "truncated to the prior box"])


#: Least effective sample of the Gaussian-process surrogate's importance weights for its posterior to be used.
GP_MIN_ESS = 200
#: Most rounds of simulations drawn where the Gaussian-process posterior lies (``n_per_iteration`` points each).
GP_REFINE_ROUNDS = 3
#: Most share of the surrogate's leave-one-out standardised residuals beyond 3 before its posterior is flagged
#: (0.3 % for a normal; the margin allows the heavier tails of a simulated log-likelihood).
LOO_MAX_BEYOND_3 = 0.02
#: Least sd of those residuals before the surrogate is flagged as smoothing more than the evaluations scatter.
LOO_MIN_SD = 0.5
#: Best evaluated points re-simulated with :data:`N_REPLICATE_SEEDS` independent seeds for the surrogate's noise
#: floor (32 extra simulations, only when the Gaussian-process path is taken).
N_REPLICATE = 4
N_REPLICATE_SEEDS = 8


def _gp_overreach(gp, draws, u_all) -> float:
    """How far [log-likelihood units] the surrogate rises over its own posterior draws above its highest value at
    a simulated point, beyond 1 (a likelihood ratio of e): > 0 when the posterior rests on extrapolation."""
    return float(gp.mean(draws).max() - gp.mean(u_all).max() - 1.0)


def _refine_gp(loglik, u_all, ll_all, proposals, n_it, rng, noise_floor=0.0):
    """Simulate where the Gaussian-process posterior lies until the surrogate claims no log-likelihood the
    simulations have not shown (at most :data:`GP_REFINE_ROUNDS` rounds).

    A Gaussian process extrapolates: fitted to a likelihood that rises toward an unexplored corner of the prior
    box, its mean can put the posterior where nothing was simulated.  Each round draws ``n_it`` points from a
    multivariate t (4 degrees of freedom) with the mean and twice the covariance of the surrogate's posterior
    sample, truncated to the cube (a proposal of the importance mixture, like the adaptive design's), and
    simulates them; the next fit then knows the likelihood there (the acquisition of Gutmann & Corander 2016,
    J. Mach. Learn. Res. 17(125), with the posterior itself as the acquisition density).

    Parameters
    ----------
    loglik : callable
        Log-likelihood of one unit-cube point.
    u_all, ll_all : numpy.ndarray
        Evaluated points (n, d) and their log-likelihoods (n,).
    proposals : list of tuple
        The proposals the points were drawn from (:func:`_log_mixture`); extended in place.
    n_it : int
        Points per round.
    rng : numpy.random.Generator
        Stream of the surrogate's sampling and of the new points.
    noise_floor : float
        Least noise sd of the surrogate (:class:`simulation.surrogate.GPSurrogate`).

    Returns
    -------
    tuple
        (points, log-likelihoods, proposals, surrogate): the rounds' points appended, and the surrogate fitted to
        the final points (None when the last fit failed or points were added after it).
    """
    d = u_all.shape[1]
    for _ in range(GP_REFINE_ROUNDS):
        try:
            draws, _, gp = gp_posterior_sample(u_all, ll_all, 2000, rng, noise_floor=noise_floor)
        except (np.linalg.LinAlgError, ValueError):
            return u_all, ll_all, proposals, None
        if _gp_overreach(gp, draws, u_all) <= 0.0:
            return u_all, ll_all, proposals, gp
        mean = draws.mean(axis=0)
        cov = 2.0 * np.cov(draws, rowvar=False).reshape(d, d) + np.eye(d) * 1e-6
        u_all, ll_all = _simulate_round(loglik, u_all, ll_all, proposals, mean, cov, n_it, rng)
    return u_all, ll_all, proposals, None


def _gp_posterior(u_all, ll_all, lo, hi, names, n_posterior, rng, gp=None, noise_floor=0.0):
    """Posterior sample from a Gaussian-process surrogate of the log-likelihood (:mod:`simulation.surrogate`),
    when no concave quadratic fits it near its top.

    Parameters
    ----------
    u_all, ll_all, lo, hi, names, n_posterior, rng
        As in :func:`_surrogate_posterior`.
    gp : simulation.surrogate.GPSurrogate, optional
        The surrogate already fitted to these points (:func:`_refine_gp`); fitted here when None.
    noise_floor : float
        Least noise sd of a surrogate fitted here.

    Returns
    -------
    tuple or str
        (posterior DataFrame, effective sample size of the importance weights, notes), or why not (in words) when
        too few evaluations lie near the top, the surrogate cannot be fitted or its importance weights have an
        effective sample below :data:`GP_MIN_ESS`.
    """
    d = u_all.shape[1]
    near = int(np.sum(ll_all >= ll_all.max() - 8.0 * stats.chi2.ppf(0.999, d)))
    if near < 10 * d:
        return f"{near} evaluations near the top, fewer than {10 * d} (10 per parameter)"
    try:
        draws, ess, gp = gp_posterior_sample(u_all, ll_all, n_posterior, rng, gp=gp, noise_floor=noise_floor)
    except (np.linalg.LinAlgError, ValueError) as err:
        return f"its fit failed ({err})"
    if ess < GP_MIN_ESS:
        return (f"its importance weights have an effective sample of {ess:.0f} (< {GP_MIN_ESS}): the surrogate's "
                "peak is narrower than its length-scale floor resolves, or it rests on a few points")
    scales = ", ".join(f"{n.split('.', 1)[1]} {v:.2g}" for n, v in zip(names, gp.lengths))
    beyond, loo_sd = float(np.mean(np.abs(gp.loo_z) > 3.0)), float(np.std(gp.loo_z))
    floor = f"{gp.noise_floor:.2f}" if gp.noise_floor > 0 else "not measured"
    notes = [f"posterior: Gaussian-process surrogate of the log-likelihood (no concave quadratic fits it near its "
             f"top), fitted to {gp.n_points} evaluations near the top (noise sd {gp.noise:.2f}, the spread between "
             f"independent seeds {floor}; length scales on the unit prior box: {scales}; "
             f"leave-one-out standardised residuals sd {loo_sd:.2f}, {beyond:.1%} beyond 3), "
             f"importance-sampled (effective sample {ess:,.0f})"]
    over = _gp_overreach(gp, draws, u_all)
    for flagged, message in (
            (loo_sd < LOO_MIN_SD,
             f"the Gaussian-process surrogate smooths more than its evaluations scatter (leave-one-out standardised "
             f"residuals sd {loo_sd:.2f}; about 1 expected): its noise floor, the spread between seeds ({floor}), "
             "may hide structure, and its posterior may be too wide"),
            (beyond > LOO_MAX_BEYOND_3,
             f"the Gaussian-process surrogate misfits its evaluations: {beyond:.1%} of their leave-one-out "
             f"standardised residuals lie beyond 3 (at most {LOO_MAX_BEYOND_3:.0%} expected); its posterior is "
             "approximate"),
            (over > 0.0,
             f"the Gaussian-process posterior rests on extrapolation: the surrogate rises {over + 1.0:.1f} above its "
             "value at every simulated point where nothing was simulated; raise iterations or n_per_iteration")):
        if flagged:
            notes.append(message)
            warnings.warn(message, PooledCalibrationWarning, stacklevel=4)     # at the caller of calibrate_pooled
    return pd.DataFrame(lo + draws * (hi - lo), columns=names), ess, notes


def _abc_posterior(u_all, ll_all, proposals, lo, hi, names, n_posterior, rng):
    """Posterior sample by ABC rejection, when neither surrogate fits; warns when it is poorly resolved.

    Keeps the evaluated points whose log-likelihood is within chi2_d(0.999) of the best (twice the drop of the
    approximate 99.9 % likelihood region, Wilks: the best value of a noisy simulated likelihood is itself inflated
    by the noise), weighted by prior / proposal mixture, and resamples them systematically.

    Parameters
    ----------
    u_all, ll_all, lo, hi, names, n_posterior, rng
        As in :func:`_surrogate_posterior`.
    proposals : list of tuple
        The proposals the points were drawn from, see :func:`_log_mixture`.

    Returns
    -------
    tuple
        (posterior DataFrame, effective sample size, notes).
    """
    band = ll_all >= ll_all.max() - stats.chi2.ppf(0.999, u_all.shape[1])
    wb = np.where(band, np.exp(-_log_mixture(u_all, proposals)), 0.0)
    wb /= wb.sum()
    ess = float(1.0 / np.sum(wb * wb))
    pos = (rng.random() + np.arange(n_posterior)) / n_posterior     # systematic resampling
    idx = np.minimum(np.searchsorted(np.cumsum(wb), pos), wb.size - 1)
    posterior = pd.DataFrame((lo + u_all * (hi - lo))[idx], columns=names)
    notes = [f"posterior: ABC rejection of the {int(band.sum())} evaluations within chi2_d(0.999) of the best "
             "log-likelihood (no concave quadratic fits it near its top)"]
    if ess < 20:
        notes.append(f"effective sample size of the posterior sample is {ess:.0f} (< 20): the posterior is poorly "
                     "resolved; raise n_per_iteration or iterations")
        warnings.warn(notes[-1], PooledCalibrationWarning, stacklevel=3)     # at the caller of calibrate_pooled
    return posterior, ess, notes


def _bound_notes(posterior, bounds, names):
    """Notes (each also a warning) on parameters with over 10 % of the posterior within 1 % of a prior bound.

    Parameters
    ----------
    posterior : pandas.DataFrame
        The posterior sample.
    bounds : dict
        Parameter path -> (low, high).
    names : list of str
        Parameter paths, in the order of the notes.

    Returns
    -------
    list of str
        The notes.
    """
    notes = []
    for k in names:
        b_lo, b_hi = bounds[k]
        at = np.mean(np.minimum(posterior[k] - b_lo, b_hi - posterior[k]) < 0.01 * (b_hi - b_lo))
        if at > 0.1:
            msg = (f"parameter {k!r}: {at:.0%} of the posterior lies within 1 % of a bound [{b_lo:g}, {b_hi:g}]; "
                   "the posterior is cut by the prior box")
            notes.append(msg)
            warnings.warn(msg, PooledCalibrationWarning, stacklevel=3)        # at the caller of calibrate_pooled
    return notes


def _quadratic_surrogate(u, ll):
    """Gaussian (mean, covariance, R^2) from a quadratic fitted to the log-likelihood ``ll`` at the points ``u``
    (unit cube) within k chi2_d(0.999) of its maximum, k = 1, 2, 4, 8: the first concave fit (a jagged
    likelihood gets a wider, smoother fit) whose 99.9 % region holds one of the five best evaluations (a
    quadratic forced over a kinked or skewed likelihood can put its peak away from where the simulations were
    best); None when no fit qualifies or there are too few points."""
    d = u.shape[1]
    n_coef = 1 + d + d * (d + 1) // 2
    drop = stats.chi2.ppf(0.999, d)
    iu = np.triu_indices(d)
    for widen in (1.0, 2.0, 4.0, 8.0):
        sel = ll >= ll.max() - widen * drop
        if sel.sum() < 3 * n_coef:
            continue
        us, ys = u[sel], ll[sel]
        quad = np.einsum("ni,nj->nij", us, us)[:, iu[0], iu[1]]
        design = np.hstack([np.ones((us.shape[0], 1)), us, quad])
        coef, *_ = np.linalg.lstsq(design, ys, rcond=None)
        b = coef[1:1 + d]
        a = np.zeros((d, d))
        a[iu] = coef[1 + d:]
        prec = -(a + a.T)                         # ll = c + b.u + 1/2 u' A u, A = a + a' (diagonal doubled)
        try:
            np.linalg.cholesky(prec)
        except np.linalg.LinAlgError:
            continue
        cov = np.linalg.inv(prec)
        top = u[np.argsort(ll)[-5:]] - cov @ b                 # the five best evaluations, from the fitted peak
        if np.einsum("ij,jk,ik->i", top, prec, top).min() > drop:
            continue                                          # a quadratic that puts its peak away from the best
        resid = ys - design @ coef
        r2 = 1.0 - float(np.sum(resid ** 2) / max(np.sum((ys - ys.mean()) ** 2), 1e-300))
        return cov @ b, cov, r2
    return None
