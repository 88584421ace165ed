"""The result of a pooled calibration and its file.

:class:`PooledCalibration` holds the posterior sample with its summary, correlations, intervals,
posterior-predictive coverage and figures; :meth:`PooledCalibration.write` writes the sample as CSV and
:func:`read_posterior` reads it back, checked against a scenario.
"""
from __future__ import annotations

import copy
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .._display import Displayed, short_repr
from ..parameters import scenario_dict, set_parameter
from ..materials import parameter_materials, parameter_sets_any
from ..scenario import Material, ScenarioError


@dataclass(frozen=True)
class PooledCalibration(Displayed):
    """Posterior of material parameters shared by many releases (:func:`calibrate_pooled`).

    ``posterior``: a sample (one row per draw, one column per dotted parameter); ``parameters``: its median;
    ``bounds``: the uniform prior; ``evaluations``: every parameter set simulated with its log-likelihood and
    importance weight; ``coverage_table``: per release, its observed stops and the share inside the 90 % and
    99 % posterior-predictive intervals; ``ess``: effective sample size of the posterior sample (its size when
    drawn from the Gaussian surrogate; of the importance weights with the Gaussian-process surrogate; of the
    ABC-rejection weights otherwise).
    """

    parameters: dict
    bounds: dict
    posterior: pd.DataFrame = field(repr=False)
    evaluations: pd.DataFrame = field(repr=False)
    coverage_table: pd.DataFrame = field(repr=False)
    ess: float
    n_per_release: int
    seed: object
    releases: tuple = field(repr=False, default=())
    notes: tuple = ()
    constraint_table: pd.DataFrame = field(repr=False, default_factory=pd.DataFrame)

    def summary(self) -> pd.DataFrame:
        """One row per parameter: posterior median, mean, sd, 5/95 % and 0.5/99.5 % quantiles, prior sd (uniform
        within the bounds) and the ratio of posterior to prior sd (near 1: the data do not constrain it).

        Returns
        -------
        pandas.DataFrame
            Indexed by ``parameter``; columns ``median``, ``mean``, ``sd``, ``q05``, ``q95``, ``q005``, ``q995``,
            ``bound_low``, ``bound_high``, ``prior_sd`` (in the parameter's own unit, e.g. [-] for a restitution
            coefficient) and ``sd_ratio`` [-].
        """
        rows = []
        for k in self.posterior.columns:
            v = self.posterior[k].to_numpy()
            lo, hi = self.bounds[k]
            prior_sd = (hi - lo) / math.sqrt(12.0)
            q = np.quantile(v, [0.005, 0.05, 0.5, 0.95, 0.995])
            rows.append({"parameter": k, "median": q[2], "mean": float(v.mean()), "sd": float(v.std(ddof=1)),
                         "q05": q[1], "q95": q[3], "q005": q[0], "q995": q[4], "bound_low": lo, "bound_high": hi,
                         "prior_sd": prior_sd, "sd_ratio": float(v.std(ddof=1)) / prior_sd})
        return pd.DataFrame(rows).set_index("parameter")

    def correlations(self) -> pd.DataFrame:
        """Pearson correlations between parameters in the posterior sample (identifiability: |r| near 1 means two
        parameters trade off against each other and only a combination is constrained).

        Returns
        -------
        pandas.DataFrame
            Square matrix of Pearson r [-], indexed and labelled by the dotted parameter names.
        """
        return self.posterior.corr()

    def interval(self, parameter: str, level: float = 0.9) -> tuple[float, float]:
        """Central posterior interval of one parameter.

        Parameters
        ----------
        parameter : str
            A dotted parameter name (a column of ``posterior``).
        level : float, optional
            Central probability of the interval [-] (default 0.9).

        Returns
        -------
        (float, float)
            Lower and upper posterior quantiles, in the parameter's own unit.
        """
        a = (1.0 - level) / 2.0
        v = self.posterior[parameter].to_numpy()
        return float(np.quantile(v, a)), float(np.quantile(v, 1.0 - a))

    def coverage(self) -> pd.Series:
        """Share of all observed stops inside their release's 90 % and 99 % posterior-predictive intervals.

        Returns
        -------
        pandas.Series
            ``inside_90``, ``inside_99`` and ``beyond_p99`` (shares [-] of all observed stops, weighted by each
            release's number of stops) and ``observed_stops`` (count).

        Raises
        ------
        ValueError
            When no posterior-predictive check was run (``n_predictive=0``).
        """
        t = self.coverage_table
        n = t["n_observed"].sum() if len(t) else 0
        if n == 0:
            raise ValueError("coverage: no posterior-predictive check was run (the calibration was called with "
                             "n_predictive=0); calibrate with n_predictive > 0 to get it")
        return pd.Series({"inside_90": float((t["inside_90"] * t["n_observed"]).sum() / n),
                          "inside_99": float((t["inside_99"] * t["n_observed"]).sum() / n),
                          "beyond_p99": float((t["beyond_p99"] * t["n_observed"]).sum() / n),
                          "observed_stops": int(n)})

    def write(self, path) -> Path:
        """Write the posterior sample as CSV (a first comment line records the bounds); read it back with
        :func:`read_posterior`.

        Parameters
        ----------
        path : str or pathlib.Path
            The CSV file to write (overwritten).

        Returns
        -------
        pathlib.Path
            ``path``.
        """
        path = Path(path)
        with open(path, "w") as fh:
            fh.write("# simulation pooled posterior; bounds = " + json.dumps(self.bounds) + "\n")
            self.posterior.to_csv(fh, index=False)
        return path

    def __repr__(self) -> str:
        return short_repr(self, f"{len(self.releases)} releases", f"{len(self.bounds)} parameters",
                          f"{len(self.posterior)} draws", ess=self.ess, n_per_release=self.n_per_release,
                          seed=self.seed if isinstance(self.seed, (int, np.integer)) else None)

    def plot(self, kind: str = "pairs", ax=None, *, fig=None):
        """The posterior sample's pairs or the releases' posterior-predictive coverage
        (:mod:`simulation.plotting`).

        Parameters
        ----------
        kind : {"pairs", "coverage"}
            ``"pairs"``: pairwise scatter of the posterior sample, histograms against the prior box on the
            diagonal, correlations above (:func:`simulation.plotting.plot_posterior_pairs`); ``"coverage"``: per
            release, the 90 % and 99 % posterior-predictive intervals of the stops with the observed stops
            (:func:`simulation.plotting.plot_pooled_coverage`).
        ax : matplotlib.axes.Axes, optional
            Axes for ``"coverage"`` (a new figure when None); for ``"pairs"`` only with one parameter.
        fig : matplotlib.figure.Figure, optional
            Figure to draw the pairs in (a new one when None).

        Returns
        -------
        matplotlib.axes.Axes
            For ``"pairs"`` the lower-left panel; ``ax.figure`` holds every panel.

        Raises
        ------
        ValueError
            An unknown ``kind``, or ``"coverage"`` of a calibration run with ``n_predictive=0``.
        """
        from .. import plotting
        if kind == "pairs":
            return plotting.plot_posterior_pairs(self, ax=ax, fig=fig)
        if kind == "coverage":
            return plotting.plot_pooled_coverage(self, ax=ax)
        raise ValueError(f"plot: kind must be 'pairs' or 'coverage', not {kind!r}")


def read_posterior(path, scenario=None) -> pd.DataFrame:
    """A posterior sample written by :meth:`PooledCalibration.write`, checked against ``scenario`` (path, dict
    or Scenario): every column must be a dotted material path naming a material the scenario defines, with
    values inside the recorded bounds.  Errors name the file, the column (field) and the scenario.

    Parameters
    ----------
    path : str or pathlib.Path
        A CSV written by :meth:`PooledCalibration.write`.
    scenario : str, pathlib.Path, dict or Scenario, optional
        Scenario whose materials the columns must name (None: not checked against a scenario).

    Returns
    -------
    pandas.DataFrame
        One row per draw, one column per dotted parameter (values in the parameter's own unit).

    Raises
    ------
    FileNotFoundError
        When ``path`` does not exist.
    ValueError
        A file not written by :meth:`PooledCalibration.write`, a column without bounds, not numeric, outside its
        bounds or not naming a material of ``scenario``.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"posterior file not found: {path}")
    with open(path) as fh:
        head = fh.readline()
    if not head.startswith("# simulation pooled posterior; bounds = "):
        raise ValueError(f"{path}: not a posterior written by PooledCalibration.write (first line {head.strip()!r})")
    bounds = json.loads(head.split("=", 1)[1])
    df = pd.read_csv(path, comment="#")
    for col in df.columns:
        if col not in bounds:
            raise ValueError(f"{path}: column {col!r} has no recorded bounds")
        if not pd.api.types.is_numeric_dtype(df[col]):
            raise ValueError(f"{path}: column {col!r} is not numeric")
    if scenario is not None:
        data, src = scenario_dict(scenario)
        mats = data.get("materials", {})
        for col in df.columns:
            parts = col.split(".")
            named = parameter_materials(col)
            if not named or not all(named) or not parameter_sets_any(col, mats):
                raise ValueError(f"{path}: field {col!r} names material "
                                 f"{' or '.join(repr(m) for m in named) if named else repr(col)}, "
                                 f"which {src} does not define (materials: {sorted(mats)})")
            for m in (m for m in named if m in mats):
                try:
                    Material.parse(m, _set_in(mats[m], parts[2:], float(df[col].iloc[0])), src)
                except (ScenarioError, ValueError) as exc:
                    raise ValueError(f"{path}: field {col!r} does not fit material {m!r} of {src}: {exc}") from None
    return df


def _set_in(spec, keys, value):
    holder = {"materials": {"m": copy.deepcopy(spec)}}
    set_parameter(holder, ".".join(["materials", "m"] + list(keys)), value)
    return holder["materials"]["m"]
