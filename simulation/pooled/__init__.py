"""Calibration pooled over many releases, with a posterior sample.

Each :class:`Release` is one or more observed blocks released in one way: its own scenario (profile and
materials), mass, optionally radius, shape and release state (position, height, velocity, push), and the
observed stop positions x [m].  :func:`calibrate_pooled` (also reached as ``simulation.calibrate(releases,
parameters=...)``) fits material parameters shared by every release to all observed stops at once and returns
a :class:`PooledCalibration`: a posterior sample, its correlations, the posterior width against the prior's,
and posterior-predictive coverage per release.

**3-D releases.**  A release whose scenario has a ``[terrain]`` table (a DEM; see
:func:`simulation.terrain_scenario_from_dict`) is simulated with the 3-D kernel (:func:`simulation.run_terrain`)
from the scenario's sources, and its ``x_stop_m`` are the observed **plan runouts**: the horizontal distance
[m] of each stop from its release point (``TerrainResult.stops()["runout_m"]``).  The likelihood is the same
kernel density on that one number; the defensive mixture spreads over the DEM's plan diagonal.  2-D and 3-D
releases may be pooled; a 3-D release takes ``mass_kg`` and ``height_m`` only (the sources give the rest).

Method
------
* **Likelihood by kernel ABC.**  For a parameter set theta every release is simulated (``n_per_release``
  blocks, with its own mass and release state); the density of the release's simulated stops, smoothed by a
  Gaussian kernel, is evaluated at each of its observed stops and the logs are added over releases.  This is
  ABC with a Gaussian acceptance kernel on each stop, which is exact inference for the simulator plus a
  Gaussian observation error of the kernel's width (Wilkinson 2013, Stat. Appl. Genet. Mol. Biol. 12:129;
  the simulated-likelihood form of Diggle & Gratton 1984, JRSS B 46:193).  The kernel width of a release is
  the larger of ``obs_error_m`` and Silverman's rule for its simulated stops; a share ``1e-3`` of the density
  is spread uniformly over the profile, so that a stop the simulation never reaches costs a bounded amount
  instead of ruling a parameter set out (a defensive mixture).
* **Common random numbers.**  Every parameter set is simulated with the same seed per release, so the
  log-likelihood is a smooth function of theta and differences between parameter sets are not masked by
  Monte Carlo noise (Glasserman 2004, sec. 4.2).
* **Where to simulate: adaptive importance sampling** (population Monte Carlo, Cappé et al. 2004, J. Comput.
  Graph. Stat. 13:907; deterministic-mixture weights of AMIS, Cornuet et al. 2012, Scand. J. Stat. 39:798):
  a Sobol design over the prior box (uniform prior within the bounds), then ``iterations`` rounds that draw
  from a Student-t (4 degrees of freedom) fitted to the importance-weighted evaluations so far, truncated to
  the box.
* **Posterior from a surrogate.**  The simulated log-likelihood is noisy (a bounce more or less moves a stop
  by metres), so importance weights on the evaluations alone collapse on a few lucky points.  A quadratic is
  fitted to the log-likelihood of the evaluations near its top (a Gaussian surrogate; the fit region widens
  until the quadratic is concave) and the posterior sample is drawn from that Gaussian truncated to the box
  (Wood 2010, Nature 466:1102, for the Gaussian synthetic-likelihood idea; Wilkinson 2014, AISTATS, for
  surrogates of ABC likelihoods).  When no concave quadratic fits (a flat, curved or cut direction), a
  Gaussian process fitted to the best evaluations smooths the log-likelihood and the posterior is
  importance-sampled from it (:mod:`simulation.surrogate`).  Only when that fails too (an effective sample
  below ``GP_MIN_ESS``), ABC rejection: the evaluations within chi2_d(0.999) of the best log-likelihood,
  weighted by prior / proposal.  ``notes`` says which was used.
* **Posterior-predictive coverage.**  For ``n_predictive`` posterior draws every release is simulated again
  (another seed); the share of observed stops inside each release's central 90 % and 99 % predictive intervals
  should be near 0.90 and 0.99 when the model and its fitted parameters describe the data.

Where it lives
--------------
- :mod:`~simulation.pooled.releases`: the observations, :class:`~simulation.pooled.releases.Release`,
  :func:`~simulation.pooled.releases.read_releases`, :func:`~simulation.pooled.releases.check_releases` and
  :class:`~simulation.pooled.releases.ReachConstraint`;
- :mod:`~simulation.pooled.simulator`: every release (and reach constraint) simulated for one parameter set;
- :mod:`~simulation.pooled.likelihood`: the kernel density of the simulated stops at the observed ones
  (:func:`~simulation.pooled.likelihood.stop_density`, :data:`~simulation.pooled.likelihood.DEFENSIVE_SHARE`);
- :mod:`~simulation.pooled.posterior`: the adaptive design and the posterior sample drawn from the evaluations
  (quadratic and Gaussian-process surrogates, ABC rejection), and
  :class:`~simulation.pooled.posterior.PooledCalibrationWarning`;
- :mod:`~simulation.pooled.result`: :class:`~simulation.pooled.result.PooledCalibration` and
  :func:`~simulation.pooled.result.read_posterior`;
- :mod:`~simulation.pooled.fit`: :func:`~simulation.pooled.fit.calibrate_pooled`.

The names in ``_EXPORTS`` below are importable from here too (imported on first use, as in :mod:`simulation`):
the public ones and the internals that the validation scripts and tests import from ``simulation.pooled``.

References: see above; Sisson, Fan & Beaumont (2018) Handbook of ABC, ch. 1 and 4.
"""
from __future__ import annotations

from .._lazy import lazy_exports as _lazy_exports

#: Name -> the module of this package that holds it.
_EXPORTS = {
    **dict.fromkeys(["Release", "ReachConstraint", "read_releases", "check_releases"], "releases"),
    **dict.fromkeys(["_Pool", "_ConstraintPool", "_density", "_with_release_state"], "simulator"),
    **dict.fromkeys(["DEFENSIVE_SHARE", "stop_density", "stop_bandwidth"], "likelihood"),
    **dict.fromkeys(["PooledCalibrationWarning", "_posterior", "_quadratic_surrogate"], "posterior"),
    **dict.fromkeys(["PooledCalibration", "read_posterior"], "result"),
    "calibrate_pooled": "fit",
}

__all__ = sorted(name for name in _EXPORTS if not name.startswith("_"))

_lazy_exports(__name__, _EXPORTS)
