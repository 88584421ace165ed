"""One error budget for the Monte Carlo outputs of a mitigation study.

A study's expected costs, their differences and P(best) are means over ``S`` joint samples of the uncertain
inputs.  Three sources of Monte Carlo randomness sit behind them:

1. **the joint input sampling** (rates, costs, the value of life, ... drawn per sample);
2. **the material re-simulations**: with uncertain slope materials each sample uses one of only ``G`` re-simulated
   slopes (``[uncertainty] material_draws``), so the samples come in ``G`` clusters that share a draw.  Treating
   the ``S`` samples as independent understates the error by about sqrt(S / G) when the draws matter (measured on
   the demo: a reported 8,400 CHF against 74,000 CHF between seeds of the sampling).  The standard error is
   therefore cluster-robust over the draws (:func:`clustered_se`), which covers sources 1 and 2 together;
3. **the trajectory ensembles** (the site's simulation and the options' re-simulations), held fixed across the
   samples (common random numbers).  Their error is added from repeated ensembles (:class:`EnsembleReplicates`):
   the study re-run with independent simulation seeds, usually at a fraction of the blocks, its between-replicate
   variance scaled by that fraction (a variance that falls as 1 / blocks: an approximation, stated).

:func:`combined_se` adds the two parts in quadrature; :func:`sources_text` says in words which sources a reported
error covers.  Costs in the study currency, probabilities dimensionless.

References
----------
Liang, K.-Y. & Zeger, S.L. (1986) Longitudinal data analysis using generalized linear models. Biometrika
73:13-22 (the cluster-robust variance).  Asmussen, S. & Glynn, P.W. (2007) Stochastic Simulation: Algorithms and
Analysis. Springer, ch. III (independent replications and batch means).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def clustered_se(x, clusters=None, design=None) -> np.ndarray:
    """Standard error of the mean over the samples (axis 0) of ``x``, with the samples grouped in clusters.

    Cluster-robust (Liang & Zeger 1986) with the small-sample factor G / (G - 1):
    ``se^2 = G / (G - 1) * sum_g (n_g (m_g - m) / S)^2``, m_g the mean of cluster g of n_g samples and m the
    overall mean.  With every sample its own cluster (or ``clusters`` None) this is the usual sd / sqrt(S).

    When the clusters are the draws of a Latin hypercube, ``design`` gives each draw's coordinates: the cluster
    means are then regressed (weighted by n_g) on them and ``m_g - m`` is replaced by the residual, with the
    factor G / (G - p - 1) for p coordinates.  A Latin hypercube removes the main effects from the mean's error
    (Stein 1987; Owen 1992): counting them, as the plain cluster-robust error does, would overstate it
    (several times on the demo).  Main effects that are not linear stay in the residual, so the error stays on the safe
    side.  With one coordinate the within-stratum variances come from the differences of neighbouring strata
    instead (Cochran 1977, sec. 5A.12).  With G <= p + 2 draws the plain form is used.

    Parameters
    ----------
    x : array_like, shape (S,) or (S, K)
        The per-sample values (e.g. total costs [currency] or 0/1 indicators).
    clusters : array_like, shape (S,), optional
        The cluster of each sample (e.g. the index of the material re-simulation it uses).  None: independent.
    design : array_like, shape (G, p), optional
        Coordinates of the clusters (one row per cluster, in the sorted order of the cluster labels), for a
        Latin-hypercube design.

    Returns
    -------
    numpy.ndarray or float
        Standard error of the mean, shaped as ``x.mean(axis=0)`` (units of ``x``); inf with fewer than 2
        clusters or samples.

    References
    ----------
    Cochran, W.G. (1977) Sampling Techniques, 3rd ed. Wiley, sec. 5A.12 (collapsed strata).  Stein, M. (1987)
    Large sample properties of simulations using Latin hypercube sampling. Technometrics
    29:143-151.  Owen, A.B. (1992) A central limit theorem for Latin hypercube sampling. J. R. Statist. Soc. B
    54:541-551.
    """
    x = np.asarray(x, dtype=float)
    S = x.shape[0]
    if S < 2:
        return np.full(x.shape[1:], np.inf) if x.ndim > 1 else float("inf")
    r = x - x.mean(axis=0)
    if clusters is None:
        return np.sqrt((r ** 2).sum(axis=0) / (S - 1)) / np.sqrt(S)
    _, inverse = np.unique(np.asarray(clusters), return_inverse=True)
    G = int(inverse.max()) + 1
    if G < 2:
        return np.full(x.shape[1:], np.inf) if x.ndim > 1 else float("inf")
    sums = np.zeros((G,) + x.shape[1:])
    np.add.at(sums, inverse, r)
    n = np.bincount(inverse, minlength=G).astype(float)
    D = None if design is None else np.asarray(design, dtype=float).reshape(G, -1)
    if D is None or G <= D.shape[1] + 2 or np.any(n == 0):
        return np.sqrt(G / (G - 1) * (sums ** 2).sum(axis=0)) / S
    dev = sums / n.reshape((G,) + (1,) * (x.ndim - 1))             # m_g - m
    if D.shape[1] == 1:
        # one coordinate: stratified sampling, one draw per stratum; the within-stratum variance of a cluster
        # mean from the differences of neighbouring strata, Var_g ~ (m_(g+1) - m_g)^2 / 2 (Cochran 1977, 5A.12)
        order = np.argsort(D[:, 0], kind="stable")
        m = dev.reshape(G, -1)[order]
        w = (n[order] / S)[:, None]
        diff2 = np.diff(m, axis=0) ** 2 / 2.0
        var_g = np.vstack([diff2[:1], (diff2[:-1] + diff2[1:]) / 2.0, diff2[-1:]])    # each stratum's neighbours
        se = np.sqrt((w ** 2 * var_g).sum(axis=0))
        return se.reshape(x.shape[1:]) if x.ndim > 1 else float(se[0])
    # main effects: linear in each coordinate, quadratic too where the draws allow (G > 2 p + 2)
    terms = [np.ones(G), *D.T] + ([*(D.T - 0.5) ** 2] if G > 2 * D.shape[1] + 2 else [])
    A = np.column_stack(terms) * np.sqrt(n)[:, None]
    flat = dev.reshape(G, -1) * np.sqrt(n)[:, None]
    coef, *_ = np.linalg.lstsq(A, flat, rcond=None)
    resid = (flat - A @ coef) / np.sqrt(n)[:, None]                 # residual of each cluster mean
    p = A.shape[1] - 1
    se = np.sqrt(G / (G - p - 1) * ((n[:, None] * resid) ** 2).sum(axis=0)) / S
    return se.reshape(x.shape[1:]) if x.ndim > 1 else float(se[0])


@dataclass(frozen=True)
class EnsembleReplicates:
    """The study repeated with independent trajectory ensembles: the expected cost and P(best) of every option in
    each replicate.

    ``names`` (options, in the study's order), ``mean`` (R, K) expected total cost [currency] and
    ``probability_best`` (R, K) [-] per replicate, ``effort`` the replicates' blocks as a share of the study's
    (their variance is multiplied by it), ``seeds`` the replicates' simulation seeds.
    """

    names: tuple
    mean: np.ndarray
    probability_best: np.ndarray
    effort: float = 1.0
    seeds: tuple = ()

    def __post_init__(self):
        m = np.asarray(self.mean, dtype=float)
        if m.ndim != 2 or m.shape[1] != len(self.names) or m.shape[0] < 2:
            raise ValueError(f"ensemble replicates: mean must be (R >= 2, {len(self.names)}); got {m.shape}")
        if not 0.0 < self.effort <= 1.0:
            raise ValueError(f"ensemble replicates: effort = {self.effort!r} must be > 0 and <= 1")

    @property
    def replicates(self) -> int:
        """Number of replicates R."""
        return int(np.asarray(self.mean).shape[0])

    def variance(self, values) -> np.ndarray:
        """Ensemble variance at the study's effort of a statistic whose replicate values are ``values``.

        Parameters
        ----------
        values : array_like, shape (R,) or (R, K)
            The statistic in each replicate.

        Returns
        -------
        numpy.ndarray or float
            Between-replicate variance (ddof 1) times ``effort``.
        """
        v = np.asarray(values, dtype=float)
        return v.var(axis=0, ddof=1) * self.effort

    def cost_variance(self, option: str) -> float:
        """Ensemble variance of one option's expected cost.

        Parameters
        ----------
        option : str
            Name of the option.

        Returns
        -------
        float
            Variance [currency^2].
        """
        return float(self.variance(np.asarray(self.mean)[:, self.names.index(option)]))

    def difference_variance(self, a: str, b: str) -> float:
        """Ensemble variance of (cost of ``b`` - cost of ``a``).

        Parameters
        ----------
        a, b : str
            Names of the two options.

        Returns
        -------
        float
            Variance [currency^2].
        """
        m = np.asarray(self.mean)
        return float(self.variance(m[:, self.names.index(b)] - m[:, self.names.index(a)]))

    def probability_variance(self, option: str) -> float:
        """Ensemble variance of P(``option`` best).

        Parameters
        ----------
        option : str
            Name of the option.

        Returns
        -------
        float
            Variance [-].
        """
        return float(self.variance(np.asarray(self.probability_best)[:, self.names.index(option)]))


def combined_se(sampling_se, ensemble_variance=None):
    """The reported standard error: the sampling part (joint samples and material draws, clustered) and the
    ensemble part added in quadrature.

    Parameters
    ----------
    sampling_se : float or numpy.ndarray
        From :func:`clustered_se` (units of the statistic).
    ensemble_variance : float or numpy.ndarray, optional
        From :meth:`EnsembleReplicates.variance` (units squared); None: not estimated.

    Returns
    -------
    float or numpy.ndarray
        sqrt(sampling_se^2 + ensemble_variance).
    """
    s = np.asarray(sampling_se, dtype=float)
    out = np.sqrt(s ** 2 + (0.0 if ensemble_variance is None else np.asarray(ensemble_variance, dtype=float)))
    return float(out) if out.ndim == 0 else out


def sources_text(samples: int, material_draws: int, ensemble: EnsembleReplicates | None) -> str:
    """Which Monte Carlo sources a reported standard error covers, in words.

    Parameters
    ----------
    samples : int
        Joint samples S.
    material_draws : int
        Material re-simulations G the samples share (0: none).
    ensemble : EnsembleReplicates or None
        The repeated ensembles, if any.

    Returns
    -------
    str
        One clause, e.g. "1,000 joint samples in 8 material re-simulations (clustered) and 4 repeated trajectory
        ensembles at 25 % of the blocks".
    """
    text = f"{samples:,} joint samples" + (f" in {material_draws} material re-simulations (clustered, a Latin "
                                          "hypercube)" if material_draws else "")
    if ensemble is None:
        return text + ("; the trajectory ensembles are held fixed (common random numbers) and their error is NOT "
                       "included (set [uncertainty] ensemble_replicates)")
    return text + (f" and {ensemble.replicates} repeated trajectory ensembles"
                   + (f" at {ensemble.effort:.0%} of the blocks (variance scaled as 1/blocks)"
                      if ensemble.effort < 1 else ""))




@dataclass(frozen=True)
class EffortRound:
    """One round of the adaptive effort: joint ``samples``, ``material_draws``, the standard errors reached
    (``difference_se`` of the two cheapest [currency], ``probability_best_se`` [-], ``worst_relative_se``: the
    largest 2 SE / expected cost over the options [-]) and whether the ranking was ``resolved``."""

    samples: int
    material_draws: int
    difference_se: float
    probability_best_se: float
    worst_relative_se: float
    resolved: bool


@dataclass(frozen=True)
class AdaptiveEffort:
    """How the effort was chosen: the ``rounds`` run and what stopped them (``reached``: "ranking resolved",
    "precision target" or "budget"), with the target and the budget."""

    rounds: tuple
    reached: str
    precision_target: float
    max_samples: int
    max_material_draws: int

    def text(self) -> str:
        """One sentence: the effort used and why it stopped.

        Returns
        -------
        str
            The sentence.
        """
        last = self.rounds[-1]
        why = {"ranking resolved": "the ranking is resolved (the lead exceeds 2 SE)",
               "precision target": f"every option's expected cost is known within +-{self.precision_target:.0%} "
                                   "(2 SE)",
               "budget": f"the budget ({self.max_samples:,} samples, {self.max_material_draws} material "
                         "re-simulations) is used: the ranking is NOT resolved"}[self.reached]
        return (f"Effort: {last.samples:,} joint samples" + (f", {last.material_draws} material re-simulations"
                                                             if last.material_draws else "")
                + f" after {len(self.rounds)} round(s); stopped because {why}.")

    def to_dict(self) -> dict:
        """JSON-ready: the rounds, what stopped them, the target and the budget.

        Returns
        -------
        dict
            ``reached``, ``precision_target``, ``max_samples``, ``max_material_draws``, ``rounds`` and ``text``.
        """
        return {"reached": self.reached, "precision_target": self.precision_target,
                "max_samples": self.max_samples, "max_material_draws": self.max_material_draws,
                "rounds": [r.__dict__ for r in self.rounds], "text": self.text()}


def adapt_effort(study, *, log=None):
    """Raise the study's effort until its ranking is resolved, every option's expected cost meets the precision
    target, or the budget is used (``[uncertainty] precision_target``, ``max_samples``, ``max_material_draws``).

    Each round doubles the joint samples and the material re-simulations (each up to its budget) and re-evaluates
    the study; the repeated trajectory ensembles (``study.ensemble``) are kept.  The ranking is resolved when the
    two cheapest options' difference (the lead) exceeds twice its standard error.

    Parameters
    ----------
    study : riskrf.risk.mitigation.MitigationStudy
        The study at its stated effort.
    log : callable, optional
        Called with one line per extra round.

    Returns
    -------
    study : MitigationStudy
        The study at the effort reached.
    effort : AdaptiveEffort
        The rounds and what stopped them.
    """
    from dataclasses import replace
    u = study.uncertainty
    materials = any(k.startswith("material:") for k in study.parameter_ranges())
    rounds = []
    while True:
        res = study.resolution()
        un = study.uncertain
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.where(np.abs(un["mean"]) > 0, 2 * un["se"] / np.abs(un["mean"]), 0.0)
        worst = float(np.max(rel)) if rel.size else 0.0
        cur = study.uncertainty
        rounds.append(EffortRound(int(un["samples"]), int(cur.material_draws) if materials else 0,
                                  float(res["difference_se"]), float(res["probability_best_se"]), worst,
                                  bool(res["distinguishable"])))
        if res["distinguishable"]:
            reached = "ranking resolved"
        elif worst <= u.precision_target:
            reached = "precision target"
        elif cur.samples >= u.max_samples and (not materials or cur.material_draws >= u.max_material_draws):
            reached = "budget"
        else:
            nxt = replace(cur, samples=min(2 * cur.samples, u.max_samples),
                          material_draws=min(2 * cur.material_draws, u.max_material_draws) if materials
                          else cur.material_draws)
            if log is not None:
                log(f"      not resolved at {cur.samples:,} samples"
                    + (f" and {cur.material_draws} material re-simulations" if materials else "")
                    + f": raising the effort to {nxt.samples:,}"
                    + (f" and {nxt.material_draws}" if materials else ""))
            study = replace(study, uncertainty=nxt)
            continue
        return study, AdaptiveEffort(tuple(rounds), reached, u.precision_target, u.max_samples,
                                     u.max_material_draws)


__all__ = ["AdaptiveEffort", "EffortRound", "EnsembleReplicates", "adapt_effort", "clustered_se", "combined_se",
           "sources_text"]
