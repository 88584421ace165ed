"""The pooled calibration itself: :func:`calibrate_pooled`.

It checks its arguments, simulates the releases (:mod:`simulation.pooled.simulator`) over an adaptive design
with the kernel likelihood (:mod:`simulation.pooled.likelihood`), draws the posterior
(:mod:`simulation.pooled.posterior`) and checks it against the data: the posterior-predictive coverage of each
release's stops (:func:`_coverage`) and the reach constraints' far limits (:func:`_constraint_table`).  The
method and its references are in :mod:`simulation.pooled`.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .likelihood import _log_likelihood
from .posterior import N_REPLICATE_SEEDS, _adaptive_design, _bound_notes, _importance_weights, _posterior
from .releases import _check_constraints, check_releases
from .result import PooledCalibration
from .simulator import _ConstraintPool, _Pool


def calibrate_pooled(releases, parameters: dict, *, n_per_release: int = 200, seed=1, n_initial: int | None = None,
                     n_per_iteration: int | None = None, iterations: int = 3, n_posterior: int = 2000,
                     n_predictive: int = 40, obs_error_m: float = 0.5, constraints=()) -> PooledCalibration:
    """Fit material parameters shared by many releases to all their observed stops; a posterior sample.

    Parameters
    ----------
    releases : list of Release
        See :class:`Release` and :func:`read_releases`.
    parameters : dict
        Dotted material path -> (low, high): the uniform prior, e.g.
        ``{"materials.soil.ground_friction_angle_deg": (10, 45), "materials.soil.tangential.mean": (0.2, 1)}``.
        Each path is set in every release whose scenario defines that material.
    n_per_release : int
        Simulated blocks per release and parameter set.
    seed : int
        Seed of the simulations (common random numbers), the design and the resampling.
    n_initial, n_per_iteration : int, optional
        Parameter sets in the initial Sobol design (default 64 x number of parameters, a power of 2) and in
        each adaptive round (default 32 x number of parameters).
    iterations : int
        Adaptive rounds after the design.
    n_posterior : int
        Size of the returned posterior sample.
    n_predictive : int
        Posterior draws simulated for the predictive coverage (0 to skip).
    obs_error_m : float
        Smallest kernel width [m]: the observation error of a stop position.
    constraints : list of ReachConstraint, optional
        Published far limits of deposition (shadow angles) added to the likelihood; each is simulated with its
        own ``n_blocks`` per parameter set and reported in ``constraint_table``.

    Returns
    -------
    PooledCalibration
    """
    releases = check_releases(releases)
    _check_pooled_arguments(parameters, n_per_release, iterations, n_posterior, n_predictive, obs_error_m)
    constraints = _check_constraints(constraints)
    cpool = _ConstraintPool(constraints, parameters)
    pool = _Pool(releases, parameters, extra_materials=cpool.materials)
    names = pool.names
    lo = np.array([pool.bounds[k][0] for k in names])
    hi = np.array([pool.bounds[k][1] for k in names])
    lengths = pool.support_lengths()
    seed = int(np.random.SeedSequence().entropy % (2 ** 31)) if seed is None else seed
    ss = np.random.SeedSequence(seed)
    rng_design, rng_prop, rng_resample, rng_pred = (np.random.default_rng(c) for c in ss.spawn(4))
    sim_seed, *replicate_seeds = (int(v % (2 ** 31)) for v in ss.generate_state(1 + N_REPLICATE_SEEDS))

    def loglik(u, seed=sim_seed):
        values = dict(zip(names, lo + u * (hi - lo)))
        ll = _log_likelihood(pool.simulate(values, n_per_release, seed), releases, lengths, obs_error_m)
        return ll + (cpool.log_likelihood(cpool.simulate(values, seed)) if constraints else 0.0)

    u_all, ll_all, proposals = _adaptive_design(loglik, len(names), n_initial, n_per_iteration, iterations,
                                                rng_design, rng_prop)
    (posterior, ess, notes), u_all, ll_all, proposals = _posterior(
        u_all, ll_all, proposals, lo, hi, names, n_posterior, rng_resample,
        refine=(loglik, n_per_iteration or 32 * len(names), rng_prop, tuple(replicate_seeds)))
    evaluations = pd.DataFrame(lo + u_all * (hi - lo), columns=names).assign(
        log_likelihood=ll_all, weight=_importance_weights(u_all, ll_all, proposals))
    notes += _bound_notes(posterior, pool.bounds, names)
    coverage = _coverage(pool, releases, posterior, n_predictive, rng_pred)
    ctable = _constraint_table(cpool, posterior, n_predictive, rng_pred)
    return PooledCalibration(parameters={k: float(posterior[k].median()) for k in names}, bounds=dict(pool.bounds),
                             posterior=posterior, evaluations=evaluations, coverage_table=coverage, ess=ess,
                             n_per_release=int(n_per_release), seed=seed, releases=tuple(releases),
                             notes=tuple(notes), constraint_table=ctable)


def _check_pooled_arguments(parameters, n_per_release, iterations, n_posterior, n_predictive, obs_error_m):
    """Refuse bad counts, kernel width or parameter table of :func:`calibrate_pooled` before any work.

    Parameters
    ----------
    parameters : dict
        Dotted material path -> (low, high).
    n_per_release, iterations, n_posterior, n_predictive : int
        The counts, checked in this order.
    obs_error_m : float
        Smallest kernel width [m].

    Raises
    ------
    ValueError
        A count that is not a whole number at or above its least value, or a width not > 0.
    TypeError
        ``parameters`` not a non-empty dict.
    """
    for arg, v, lo in (("n_per_release", n_per_release, 10), ("iterations", iterations, 0),
                       ("n_posterior", n_posterior, 10), ("n_predictive", n_predictive, 0)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise ValueError(f"{arg} must be a whole number >= {lo}; got {v!r}")
    if not (isinstance(obs_error_m, (int, float)) and obs_error_m > 0):
        raise ValueError(f"obs_error_m must be > 0 m; got {obs_error_m!r}")
    if not isinstance(parameters, dict) or not parameters:
        raise TypeError(f"parameters must be a non-empty dict of dotted material path -> (low, high); got "
                        f"{parameters!r}")


def _constraint_table(cpool, posterior, n_predictive, rng):
    """Simulated far limits of the reach constraints for ``n_predictive`` posterior draws.

    Parameters
    ----------
    cpool : _ConstraintPool
        The constraints and their scenarios.
    posterior : pandas.DataFrame
        The posterior sample.
    n_predictive : int
        Posterior draws (0: none).
    rng : numpy.random.Generator
        The predictive stream (after the coverage draws).

    Returns
    -------
    pandas.DataFrame
        :meth:`_ConstraintPool.table`, empty without constraints or draws.
    """
    if not (cpool.constraints and n_predictive):
        return pd.DataFrame()
    draws = posterior.iloc[rng.choice(len(posterior), size=n_predictive, replace=False)]
    return cpool.table([cpool.far_angles(cpool.simulate(row.to_dict(), 20_000 + t))
                        for t, (_, row) in enumerate(draws.iterrows())])


def _coverage(pool, releases, posterior, n_predictive, rng) -> pd.DataFrame:
    """Per release: observed stops inside the central 90 % / 99 % posterior-predictive intervals."""
    cols = ["release", "n_observed", "p05", "p95", "p005", "p995", "inside_90", "inside_99", "beyond_p99"]
    if n_predictive == 0:
        return pd.DataFrame(columns=cols).set_index("release")
    draws = posterior.iloc[rng.choice(len(posterior), size=n_predictive, replace=False)]
    per_release = [[] for _ in releases]
    n_each = max(10, int(math.ceil(400 / n_predictive)))
    for t, (_, row) in enumerate(draws.iterrows()):
        sims = pool.simulate(row.to_dict(), n_each, 10_000 + t)
        for i, s in enumerate(sims):
            per_release[i].append(s)
    rows = []
    for r, sims in zip(releases, per_release):
        s = np.concatenate(sims)
        q = np.quantile(s, [0.05, 0.95, 0.005, 0.995])
        x = np.asarray(r.x_stop_m, dtype=float).ravel()
        rows.append({"release": r.name, "n_observed": x.size, "p05": q[0], "p95": q[1], "p005": q[2], "p995": q[3],
                     "inside_90": float(np.mean((x >= q[0]) & (x <= q[1]))),
                     "inside_99": float(np.mean((x >= q[2]) & (x <= q[3]))),
                     "beyond_p99": float(np.mean(x > q[3]))})
    return pd.DataFrame(rows, columns=cols).set_index("release")
