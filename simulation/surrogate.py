"""Gaussian-process surrogate of a noisy simulated log-likelihood, and a posterior sample drawn through it.

Used by :func:`simulation.calibrate_pooled` when no concave quadratic fits the log-likelihood near its top (a
likelihood with a flat, curved or cut direction), before it falls back to ABC rejection.  The simulated
log-likelihood at the evaluated parameter sets is noisy (a bounce more or less moves a stop) and, under common
random numbers, jagged; resampling the evaluated points by their own likelihoods lets a few lucky points carry
the whole posterior (an effective sample of a few).  A Gaussian process smooths the evaluations into a surface
and the posterior is drawn from that surface by importance sampling, as in Gaussian-process emulation of
simulators (Kennedy & O'Hagan 2001, J. R. Stat. Soc. B 63:425) and its use for likelihood-free inference
(Wilkinson 2014, AISTATS, "Accelerating ABC methods using Gaussian processes"; Gutmann & Corander 2016,
J. Mach. Learn. Res. 17(125), section 4).

Model (Rasmussen & Williams 2006, *Gaussian Processes for Machine Learning*, MIT Press, eqs. 2.25-2.26 and
5.8): ll(u) = m0 + f(u) + noise, f a zero-mean GP with squared-exponential covariance with one length scale per
parameter (automatic relevance determination), the noise independent Gaussian (the Monte Carlo error of the
simulated log-likelihood).  The constant m0 sits one chi2 drop below the lowest point used, so regions the
design never reached are not favoured.  Hyperparameters maximise the log marginal likelihood (eq. 5.8), from
several starts (one start can stop at a poor optimum that calls a constrained parameter irrelevant), with a floor
on the length scales and on the noise (the spread between independent seeds): under common random numbers the
simulated surface is jagged, and a process free to follow the jags as signal gives intervals too narrow.  When
many points lie near the top, the fit uses the best few and a random draw of the rest, not the best of all
(which would be the luckiest).
"""
from __future__ import annotations

import math

import numpy as np
from scipy import linalg, optimize, stats

#: Most evaluated points the surrogate is fitted to: the fit costs O(n^3).
MAX_POINTS = 600
#: Of those, how many are the best evaluations (the peak); the rest are drawn at random from the others near the
#: top, so the fit does not select on the Monte Carlo noise (the best of many noisy values are the lucky ones).
N_TOP = 100
#: Least length scale on the unit prior box: a surface that changes faster than this is Monte Carlo jaggedness
#: (common random numbers: a bounce more or less moves a stop), not a likelihood.
LENGTH_FLOOR = 0.1
#: Starting length scales of the marginal-likelihood fits (the best of the fits is kept).
LENGTH_STARTS = (0.15, 0.4, 1.5)
#: Draws of the importance sampler.
N_PROPOSAL = 40_000


def _sq_dist(a, b, lengths):
    """Squared scaled distances between the rows of ``a`` and ``b`` (an (n, m) array, without an (n, m, d) one)."""
    a, b = a / lengths, b / lengths
    return np.maximum(np.sum(a * a, 1)[:, None] + np.sum(b * b, 1)[None, :] - 2.0 * a @ b.T, 0.0)


def _kernel(a, b, scale2, lengths):
    return scale2 * np.exp(-0.5 * _sq_dist(a, b, lengths))


def _neg_log_marginal(theta, diff2, y):
    """Minus the log marginal likelihood (Rasmussen & Williams eq. 5.8) and its gradient (eq. 5.9) at log
    hyperparameters ``theta`` (log signal sd, log length scales, log noise sd); ``diff2`` is the (n, n, d) array
    of squared coordinate differences of the points."""
    d = diff2.shape[2]
    scale2, lengths, noise2 = math.exp(2 * theta[0]), np.exp(theta[1:1 + d]), math.exp(2 * theta[-1])
    sq = diff2 / lengths ** 2                                         # (n, n, d) scaled squared differences
    kf = scale2 * np.exp(-0.5 * np.sum(sq, axis=2))
    try:
        c = linalg.cho_factor(kf + noise2 * np.eye(y.size), lower=True, check_finite=False)
    except linalg.LinAlgError:
        return 1e300, np.zeros_like(theta)
    alpha = linalg.cho_solve(c, y, check_finite=False)
    value = 0.5 * float(y @ alpha) + float(np.sum(np.log(np.diag(c[0])))) + 0.5 * y.size * math.log(2 * math.pi)
    inner = np.outer(alpha, alpha) - linalg.cho_solve(c, np.eye(y.size), check_finite=False)
    grad = np.empty_like(theta)
    grad[0] = -0.5 * np.sum(inner * 2.0 * kf)
    grad[1:1 + d] = -0.5 * np.einsum("ij,ijk->k", inner * kf, sq)
    grad[-1] = -0.5 * np.trace(inner) * 2.0 * noise2
    return value, grad


def _t_logpdf(u, mean, cov, dof=4.0):
    """Log density of a multivariate t (``dof`` degrees of freedom, centre ``mean``, scale ``cov``) at the rows
    of ``u`` (untruncated)."""
    d = u.shape[1]
    diff = u - mean
    inv = np.linalg.inv(cov)
    m = np.einsum("ij,jk,ik->i", diff, inv, diff)
    _, logdet = np.linalg.slogdet(cov)
    return (math.lgamma((dof + d) / 2) - math.lgamma(dof / 2) - 0.5 * d * math.log(dof * math.pi) - 0.5 * logdet
            - 0.5 * (dof + d) * np.log1p(m / dof))


def _t_draw(rng, mean, cov, n, dof=4.0):
    """``n`` draws of a multivariate t (``dof`` degrees of freedom, centre ``mean``, scale ``cov``)."""
    d = mean.size
    z = rng.multivariate_normal(np.zeros(d), cov, size=n)
    g = rng.chisquare(dof, size=n) / dof
    return mean + z / np.sqrt(g)[:, None]


def _in_unit_box(draw, n, give_up=False, max_batches=None):
    """The first ``n`` points inside the unit cube from repeated batches ``draw()`` (rows in order).

    Parameters
    ----------
    draw : callable
        Returns an (m, d) batch of candidate points.
    n : int
        Points wanted.
    give_up : bool
        Return None when a non-empty batch leaves no point kept so far.
    max_batches : int, optional
        Most batches drawn (None: no limit).

    Returns
    -------
    numpy.ndarray or None
        (n, d) points, or None (``give_up`` only).

    Raises
    ------
    ValueError
        Fewer than ``n`` points inside the cube after ``max_batches`` batches.
    """
    kept, batches = [], 0
    while len(kept) < n:
        if max_batches is not None and batches >= max_batches:
            raise ValueError(f"{len(kept)} of {n} proposal draws inside the prior box after {batches} batches: "
                             "the proposal puts almost no mass inside it")
        cand = draw()
        batches += 1
        kept.extend(cand[np.all((cand >= 0) & (cand <= 1), axis=1)].tolist())
        if give_up and len(kept) == 0 and len(cand) > 0:
            return None
    return np.array(kept[:n])


class GPSurrogate:
    """A Gaussian process fitted to log-likelihoods ``ll`` at unit-cube points ``u``.

    The points used are those within ``8 chi2_d(0.999)`` of the maximum: all of them up to :data:`MAX_POINTS`,
    else the :data:`N_TOP` best and a random draw (fixed seed) of the others.  The hyperparameters are the best of
    maximum-marginal-likelihood fits from each start in :data:`LENGTH_STARTS`, with length scales at or above
    :data:`LENGTH_FLOOR` and the noise sd at or above ``noise_floor``.

    Parameters
    ----------
    u : array_like
        (n, d) points in the unit cube.
    ll : array_like
        (n,) their log-likelihoods; NaN and -inf (failed simulations) are left out.
    noise_floor : float
        Least noise sd [log-likelihood units]: the spread of the log-likelihood between independent seeds at one
        point (:func:`replicate_noise`).  Under common random numbers the simulated surface is jagged on that
        scale, and a process allowed less noise follows the jags as signal (intervals too narrow).

    Attributes
    ----------
    m0 : float
        The constant mean (one chi2 drop below the lowest point used).
    scale, lengths, noise : float, numpy.ndarray, float
        Signal sd [log-likelihood units], length scales per parameter [unit cube], noise sd [log-likelihood
        units] of the fitted process.
    n_points : int
        Points it was fitted to.
    noise_floor : float
        The ``noise_floor`` it was given (0 when that was not a finite number > 0: not measured).
    loo_z : numpy.ndarray
        Leave-one-out standardised residuals of the points (Rasmussen & Williams eqs. 5.10-5.12): about N(0, 1)
        when the process describes the evaluations.
    """

    def __init__(self, u, ll, noise_floor: float = 0.0):
        ok = np.isfinite(np.asarray(ll, dtype=float))
        u = np.asarray(u, dtype=float)[ok]
        ll = np.asarray(ll, dtype=float)[ok]
        d = u.shape[1]
        if ll.size < d + 2:
            raise ValueError(f"{ll.size} finite log-likelihoods: too few for a surrogate in {d} parameters")
        drop = stats.chi2.ppf(0.999, d)
        band = np.flatnonzero(ll >= ll.max() - 8.0 * drop)
        if band.size > MAX_POINTS:
            order = band[np.argsort(ll[band])[::-1]]
            rest = np.random.default_rng(0).choice(order[N_TOP:], MAX_POINTS - N_TOP, replace=False)
            band = np.sort(np.concatenate([order[:N_TOP], rest]))
        self.u, y = u[band], ll[band]
        self.n_points = int(band.size)
        self.m0 = float(y.min() - drop)
        self.y = y - self.m0
        sd = max(float(np.std(self.y)), 1e-3)
        self.noise_floor = float(noise_floor) if np.isfinite(noise_floor) and noise_floor > 0 else 0.0
        nf = max(self.noise_floor, 1e-3 * sd)
        bounds = ([(math.log(0.01 * sd), math.log(100 * sd))] + [(math.log(LENGTH_FLOOR), math.log(10.0))] * d
                  + [(math.log(nf), math.log(max(sd, 2.0 * nf)))])
        diff2 = (self.u[:, None, :] - self.u[None, :, :]) ** 2
        fits = []
        for start in LENGTH_STARTS:
            theta0 = np.concatenate([[math.log(sd)], np.full(d, math.log(start)), [math.log(max(0.1 * sd, nf))]])
            theta0 = np.clip(theta0, [b[0] for b in bounds], [b[1] for b in bounds])
            fits.append(optimize.minimize(_neg_log_marginal, theta0, args=(diff2, self.y), jac=True,
                                          method="L-BFGS-B", bounds=bounds, options={"maxiter": 200}))
        th = min(fits, key=lambda f: f.fun).x
        self.scale, self.lengths = math.exp(th[0]), np.exp(th[1:1 + d])
        self.noise = max(math.exp(th[-1]), self.noise_floor)            # exp(log(x)) may fall one ulp below x
        k = _kernel(self.u, self.u, self.scale ** 2, self.lengths) + self.noise ** 2 * np.eye(self.n_points)
        c = linalg.cho_factor(k, lower=True)
        self._alpha = linalg.cho_solve(c, self.y)
        self.loo_z = self._alpha / np.sqrt(np.diag(linalg.cho_solve(c, np.eye(self.n_points))))

    def mean(self, u) -> np.ndarray:
        """The surrogate's log-likelihood at unit-cube points (the posterior mean of the process, in chunks).

        Parameters
        ----------
        u : array_like
            (n, d) points in the unit cube (the prior box scaled to [0, 1]).

        Returns
        -------
        numpy.ndarray
            (n,) log-likelihoods [the simulated log-likelihood's units].
        """
        u = np.atleast_2d(np.asarray(u, dtype=float))
        out = np.empty(u.shape[0])
        for s in range(0, u.shape[0], 4096):
            out[s:s + 4096] = self.m0 + _kernel(u[s:s + 4096], self.u, self.scale ** 2, self.lengths) @ self._alpha
        return out


def replicate_noise(loglik, u, seeds) -> float:
    """The noise sd of a simulated log-likelihood: its spread between independent seeds at the same points.

    Under common random numbers the evaluations' noise is shared by nearby points (one seed moves a whole
    neighbourhood), so two seeds at many nearby points measure it about once; several seeds per point measure it
    as often as there are seeds.

    Parameters
    ----------
    loglik : callable
        ``loglik(point, seed)``: the log-likelihood of one unit-cube point simulated with ``seed``.
    u : numpy.ndarray
        (k, d) points (e.g. the best evaluated ones).
    seeds : sequence of int
        At least two seeds, all independent of the one the evaluations used (else selecting the best points
        would select on their noise).

    Returns
    -------
    float
        The square root of the mean over the points of the sample variance (ddof 1) between seeds, counting only
        finite values and points with two or more [log-likelihood units]; NaN when there is none (not measured).

    Raises
    ------
    ValueError
        Fewer than two seeds.
    """
    seeds = list(seeds)
    if len(seeds) < 2:
        raise ValueError(f"replicate_noise: {len(seeds)} seed(s) given; the spread between seeds needs two or more")
    values = np.array([[loglik(p, s) for s in seeds] for p in u], dtype=float)
    var = [np.var(v[np.isfinite(v)], ddof=1) for v in values if np.sum(np.isfinite(v)) >= 2]
    return float(np.sqrt(np.mean(var))) if var else float("nan")


def _t_proposal(centre, cov, n, rng):
    """``n`` draws of a multivariate t (4 degrees of freedom) inside the unit cube and their log densities
    (untruncated: the truncation constant cancels in normalised weights)."""
    prop = _in_unit_box(lambda: _t_draw(rng, centre, cov, n), n, max_batches=1000)
    return prop, _t_logpdf(prop, centre, cov)


def gp_posterior_sample(u, ll, n_posterior: int, rng, rounds: int = 3, gp=None, noise_floor: float = 0.0):
    """A posterior sample on the unit cube from the Gaussian-process surrogate of ``ll`` (uniform prior).

    Adaptive importance sampling of exp(surrogate) (Cappé et al. 2004, J. Comput. Graph. Stat. 13:907): the
    first proposal is a multivariate t (4 degrees of freedom) centred on the surrogate's best fitted point with
    twice the covariance of the points within chi2_d(0.999) of the maximum; each further round centres it on
    the weighted mean of the last with twice its weighted covariance.  Each round draws :data:`N_PROPOSAL`
    points inside the cube; the last round's are weighted by exp(surrogate) / proposal density and resampled
    systematically.

    Parameters
    ----------
    u, ll : numpy.ndarray
        Evaluated unit-cube points (n, d) and their simulated log-likelihoods (n,).
    n_posterior : int
        Size of the sample.
    rng : numpy.random.Generator
        Stream of the proposals and the resampling.
    rounds : int
        Importance-sampling rounds.
    gp : GPSurrogate, optional
        The surrogate already fitted to ``u`` and ``ll`` (fitted here when None).
    noise_floor : float
        Least noise sd of the surrogate fitted here (see :class:`GPSurrogate`).

    Returns
    -------
    tuple
        (sample (n_posterior, d), effective sample size of the last round's importance weights, the surrogate).
    """
    gp = GPSurrogate(u, ll, noise_floor) if gp is None else gp
    d = gp.u.shape[1]
    band = gp.u[gp.y >= gp.y.max() - stats.chi2.ppf(0.999, d)]           # within one drop of the best
    band = band if band.shape[0] > d else gp.u
    cov = 2.0 * np.cov(band, rowvar=False).reshape(d, d) + np.eye(d) * 1e-6
    centre = gp.u[int(np.argmax(gp.mean(gp.u)))]
    for _ in range(rounds):
        prop, log_q = _t_proposal(centre, cov, N_PROPOSAL, rng)
        lw = gp.mean(prop) - log_q
        w = np.exp(lw - lw.max())
        w /= w.sum()
        centre = w @ prop
        diff = prop - centre
        cov = 2.0 * (w[:, None] * diff).T @ diff + np.eye(d) * 1e-6
    ess = float(1.0 / np.sum(w * w))
    pos = (rng.random() + np.arange(n_posterior)) / n_posterior        # systematic resampling
    idx = np.minimum(np.searchsorted(np.cumsum(w), pos), w.size - 1)
    return prop[idx], ess, gp
