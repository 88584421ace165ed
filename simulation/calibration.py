"""Calibration of scenario parameters to observed stop points (runout distributions).

``calibrate(scenario, observed, parameters, n=..., seed=...)`` fits the
scenario values named by dotted paths (``"materials.talus.ground_friction_angle_deg"``,
``"materials.talus.normal_restitution.mean"``) within bounds so that the
simulated distribution of horizontal stop positions x [m] matches the observed
one.

Method
------
* **Distance between distributions**: the 1-Wasserstein distance (earth
  mover's distance, [m]) between the simulated and observed stop positions
  (default), or the Cramér-von Mises criterion (``distance="cvm"``: the mean of
  (F_sim - F_obs)^2 over the pooled sample; Anderson & Darling 1952 two-sample
  form).  With optional collector quantities (observed ``velocity_ms`` or
  ``height_m`` at a named collector), each term is divided by the observed
  standard deviation of its quantity and the terms are added.
* **Common random numbers**: every evaluation runs the simulator with the same
  ``seed``; the release states and the per-impact random numbers (keyed by
  seed and block index) are then identical, so the objective is a
  deterministic function of the parameters and differences between parameter
  sets are not masked by Monte Carlo noise.
* **Optimiser**: :func:`scipy.optimize.differential_evolution` (bounded,
  derivative-free, robust to the small jumps a finite Monte Carlo sample puts
  in the objective; seeded, no polishing by a gradient method).
* **Uncertainty**: a nonparametric bootstrap of the observed stops.  Each
  replicate resamples the observations with replacement and re-minimises the
  distance over every parameter set the optimiser evaluated plus a local design
  around the optimum (their simulated stops are kept, so no new simulations are
  needed).  With a few dozen observed blocks the sampling of the observations
  dominates the uncertainty of the fit (the Monte Carlo noise of n simulated
  blocks is smaller and held fixed by the common random numbers), which is why
  the observations and not the simulations are resampled.  The intervals are
  limited to the region and resolution the optimiser explored; parameters the
  runout does not constrain show intervals spanning most of their bounds.

References: Efron & Tibshirani (1993) An Introduction to the Bootstrap, ch. 6
and 13; Storn & Price (1997) J. Global Optimization 11:341-359; Glasserman
(2004) Monte Carlo Methods in Financial Engineering, sec. 4.2 (common random
numbers); Villani (2009) for the Wasserstein distance.
"""
from __future__ import annotations

import copy
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import optimize, stats

from ._display import Displayed, short_repr
from .materials import material_parameter, parameter_materials
from .parameters import (  # noqa: F401  (their names here before the split)
    _did_you_mean, apply_parameters, check_material_names, scenario_dict, set_parameter)
from .scenario import Scenario, ScenarioError, scenario_from_dict

#: Fewer observed stops than this give a warning: the calibration is weak.
MIN_OBSERVED = 10
_COLLECTOR_COLUMNS = ("velocity_ms", "height_m")


class CalibrationWarning(UserWarning):
    """The calibration ran but its result deserves caution (few observations, parameter at a bound)."""


# ---- scenario dictionaries and dotted paths --------------------------------------------------------------
def _check_parameters(data: dict, parameters, source: str) -> dict:
    if not isinstance(parameters, dict) or not parameters:
        raise TypeError(f"parameters must be a non-empty dict of dotted name -> (low, high); got {parameters!r}")
    bounds = {}
    for name, b in parameters.items():
        if not isinstance(name, str):
            raise TypeError(f"parameter names must be dotted strings; got {name!r}")
        try:
            lo, hi = b
            lo, hi = float(lo), float(hi)
        except (TypeError, ValueError):
            raise ValueError(f"parameter {name!r}: bounds must be (low, high) numbers; got {b!r}") from None
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise ValueError(f"parameter {name!r}: bounds must be finite; got ({lo:g}, {hi:g})")
        if not lo < hi:
            raise ValueError(f"parameter {name!r}: bounds reversed or empty: low = {lo:g} must be below "
                             f"high = {hi:g}")
        bounds[name] = (lo, hi)
    check_material_names(bounds)
    defined = list(data.get("materials") or {})
    for name in bounds:                  # one scenario: every material a shared name lists must be in it
        mats = parameter_materials(name)
        missing = [m for m in mats if m not in defined]
        if len(mats) > 1 and missing:
            raise ValueError(f"{source}: parameter {name!r}: the scenario defines no material {missing[0]!r}"
                             f"{_did_you_mean(missing[0], defined)}")
    # every path must exist and every bound give a valid scenario
    for name, (lo, hi) in bounds.items():
        for v in (lo, hi):
            trial = copy.deepcopy(data)
            set_parameter(trial, name, v, source=source)
            try:
                scenario_from_dict(trial, source=source)
            except ScenarioError as exc:
                raise ValueError(f"parameter {name!r} = {v:g} (a bound): {exc}") from None
    return bounds


# ---- observations -----------------------------------------------------------------------------------------
def read_observed(path, *, column: str = "x_stop_m", select: dict | None = None,
                  table: pd.DataFrame | None = None) -> pd.DataFrame:
    """Observed stops from a CSV (or Parquet/XLSX) file: column ``x_stop_m`` [m], optionally collector columns.

    ``select`` keeps rows whose columns equal the given values (e.g.
    ``{"profile": "P1"}``).  Without an ``x_stop_m`` column, a file with
    exactly one numeric column uses that column.  ``table``: the file already read (by a reader
    with other rules, e.g. ``riskrf.io.tables.read_numeric_table`` for separators, decimal commas,
    encodings, Excel sheets and header rows); ``path`` then only names it and the table's index
    is kept as the row labels of messages (that reader's index holds the file lines).

    Parameters
    ----------
    path : str or path
        The file.
    column : str
        Column of the stop positions [m].
    select : dict, optional
        Column → value rows must match.
    table : pandas.DataFrame, optional
        The file already read.

    Returns
    -------
    pandas.DataFrame
        ``x_stop_m`` [m] and any collector columns.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"observed file not found: {path}")
    suffix = path.suffix.lower()
    try:
        if table is not None:
            df = table
        elif suffix == ".parquet":
            df = pd.read_parquet(path)
        elif suffix in (".xlsx", ".xls"):
            df = pd.read_excel(path)
        else:
            df = pd.read_csv(path)
    except (ValueError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise ValueError(f"{path}: cannot read observed stops: {exc}") from None
    for key, value in (select or {}).items():
        if key not in df.columns:
            raise ValueError(f"{path}: select column {key!r} not in the file{_did_you_mean(key, list(df.columns))}")
        keep = df[key].astype(str) == str(value)
        if not keep.any():
            raise ValueError(f"{path}: no row has {key} = {value!r}; values are {sorted(df[key].astype(str).unique())}")
        df = df[keep]
    numeric = [c for c in df.columns if pd.api.types.is_numeric_dtype(df[c])]
    if column not in df.columns:
        if not numeric:
            raise ValueError(f"{path}: no numeric column (columns: {list(df.columns)}); observed stops need a "
                             f"'{column}' column of horizontal stop positions in m")
        if len(numeric) > 1:
            raise ValueError(f"{path}: no '{column}' column and several numeric columns {numeric}; name the stop "
                             f"positions '{column}' (or pass column=)")
        column = numeric[0]
    if not pd.api.types.is_numeric_dtype(df[column]):
        bad = pd.to_numeric(df[column], errors="coerce").isna()
        row = int(np.argmax(bad.to_numpy()))
        raise ValueError(f"{path}: column {column!r} is not numeric; row {row + 2} holds {df[column].iloc[row]!r}")
    out = df.rename(columns={column: "x_stop_m"})
    if table is None and suffix not in (".parquet", ".xlsx", ".xls"):
        out.index = out.index + 2            # row labels are the CSV file's line numbers (line 1 is the header)
    out.attrs["source"] = f"{path} (column {column!r})"
    return out


def _observed_frame(observed) -> tuple[pd.DataFrame, str]:
    if isinstance(observed, (str, Path)):
        df = read_observed(observed)
        return df, df.attrs["source"]
    if isinstance(observed, pd.DataFrame):
        # a table from read_observed (as the command line passes it) names its file in attrs["source"]
        source = observed.attrs.get("source") or "observed DataFrame"
        if "x_stop_m" not in observed.columns:
            raise ValueError(f"{source}: needs an 'x_stop_m' column [m]; columns are {list(observed.columns)}")
        return observed, str(source)
    if isinstance(observed, pd.Series):
        return pd.DataFrame({"x_stop_m": observed.to_numpy()}), "observed Series"
    try:
        arr = np.asarray(observed, dtype=float)
    except (TypeError, ValueError):
        raise TypeError("observed must be stop positions x [m] (array), a DataFrame with 'x_stop_m' or a file "
                        f"path; got {type(observed).__name__}") from None
    if arr.ndim != 1:
        raise ValueError(f"observed stop positions must be one-dimensional; got shape {arr.shape}")
    return pd.DataFrame({"x_stop_m": arr}), "observed array"


def _check_observed(df: pd.DataFrame, source: str, scenario: Scenario, collector: str | None) -> dict:
    x = pd.to_numeric(df["x_stop_m"], errors="coerce").to_numpy(dtype=float)
    bad = ~np.isfinite(x)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{source}: x_stop_m must be finite numbers in m; row {df.index[i]} holds "
                         f"{df['x_stop_m'].iloc[i]}")
    lo, hi = scenario.profile.x[0], scenario.profile.x[-1]
    out = (x < lo) | (x > hi)
    if out.any():
        i = int(np.argmax(out))
        raise ValueError(f"{source}: x_stop_m = {x[i]:g} m (row {df.index[i]}) is outside the profile of {scenario.source} "
                         f"[{lo:g}, {hi:g}] m")
    if x.size == 0:
        raise ValueError(f"{source}: no observed stops")
    if x.size < MIN_OBSERVED:
        warnings.warn(f"{source}: only {x.size} observed stops (x_stop_m); with fewer than {MIN_OBSERVED} the "
                      "calibration is weak and its intervals unreliable", CalibrationWarning, stacklevel=3)
    quantities = {"x_stop_m": x}
    extra = [c for c in _COLLECTOR_COLUMNS if c in df.columns]
    if extra and collector is None:
        raise ValueError(f"{source}: columns {extra} are collector quantities; name the collector (collector=...) "
                         "or drop them")
    if collector is not None:
        scenario.collector_index(collector)    # KeyError naming the collectors
        if not extra:
            raise ValueError(f"{source}: collector={collector!r} given but no column {list(_COLLECTOR_COLUMNS)}")
        for c in extra:
            v = pd.to_numeric(df[c], errors="coerce").to_numpy(dtype=float)
            v = v[np.isfinite(v)]
            if v.size < 2:
                raise ValueError(f"{source}: column {c!r} has {v.size} finite values; need at least 2")
            quantities[c] = v
    return quantities


# ---- distances --------------------------------------------------------------------------------------------
def cvm_distance(a, b) -> float:
    """Cramér-von Mises criterion: mean of (F_a - F_b)^2 over the pooled sample (0 for equal samples).

    Parameters
    ----------
    a, b : array_like
        Two samples (e.g. stop positions [m]).

    Returns
    -------
    float
        The mean [-]; Anderson's statistic T is N M / (N + M) times it (N, M the sample sizes).

    References
    ----------
    Anderson, T. W. (1962). On the distribution of the two-sample Cramér-von Mises criterion. Annals of
    Mathematical Statistics 33(3), 1148-1159.
    """
    a, b = np.sort(np.asarray(a, float)), np.sort(np.asarray(b, float))
    z = np.concatenate([a, b])
    fa = np.searchsorted(a, z, side="right") / a.size
    fb = np.searchsorted(b, z, side="right") / b.size
    return float(np.mean((fa - fb) ** 2))


_DISTANCES = {"wasserstein": stats.wasserstein_distance, "cvm": cvm_distance}


def _simulate(data: dict, source: str, n: int, seed, collector: str | None) -> dict:
    from .engine import run
    sc = scenario_from_dict(data, source=source)
    res = run(sc, n=n, seed=seed, record_paths=0)
    from .kernel import LEFT_PROFILE
    out = {"x_stop_m": res.per_block["x"].copy(), "left_profile": float(np.mean(res.per_block["reason"] == LEFT_PROFILE))}
    if collector is not None:
        df = res.collector(collector, first_only=True)
        for c in _COLLECTOR_COLUMNS:
            out[c] = df[c].to_numpy()
    return out


def _objective(sim: dict, obs: dict, scales: dict, dist) -> float:
    total = 0.0
    for k, o in obs.items():
        s = sim.get(k)
        if s is None or len(s) == 0:
            return math.inf
        total += dist(s, o) / scales[k]
    return total


# ---- result -----------------------------------------------------------------------------------------------
@dataclass(frozen=True, repr=False)
class Calibration(Displayed):
    """Fitted parameters, the calibrated scenario and the fit, before and after.

    ``parameters`` fitted values; ``bounds``; ``scenario`` the calibrated
    Scenario and ``scenario_data`` its dictionary (``to_toml()`` writes it);
    ``observed`` and ``simulated`` / ``simulated_initial`` stop positions x [m]
    (after / before calibration, n blocks, the same seed); ``bootstrap`` one
    row of re-fitted parameters per bootstrap replicate; ``evaluations`` every
    parameter set tried with its distance.
    """

    parameters: dict
    bounds: dict
    scenario: Scenario = field(repr=False)
    scenario_data: dict = field(repr=False)
    initial_parameters: dict
    observed: np.ndarray = field(repr=False)
    simulated: np.ndarray = field(repr=False)
    simulated_initial: np.ndarray = field(repr=False)
    distance: float
    distance_initial: float
    distance_name: str
    bootstrap: pd.DataFrame = field(repr=False)
    evaluations: pd.DataFrame = field(repr=False)
    n: int
    seed: object
    observed_source: str
    left_profile_fraction: float
    notes: tuple = ()

    def summary(self, level: float = 0.95) -> pd.DataFrame:
        """One row per parameter: fitted value, bounds, initial value, bootstrap interval and standard deviation.

        Parameters
        ----------
        level : float
            Level of the bootstrap interval.

        Returns
        -------
        pandas.DataFrame
            Indexed by parameter (values in the parameter's unit).
        """
        a = (1 - level) / 2
        rows = []
        for k, v in self.parameters.items():
            b = self.bootstrap[k].to_numpy() if len(self.bootstrap) else np.array([np.nan])
            lo, hi = self.bounds[k]
            rows.append({"parameter": k, "value": v, "initial": self.initial_parameters.get(k, np.nan),
                         "bound_low": lo, "bound_high": hi,
                         f"ci{int(level * 100)}_low": float(np.quantile(b, a)),
                         f"ci{int(level * 100)}_high": float(np.quantile(b, 1 - a)),
                         "bootstrap_std": float(np.std(b, ddof=1)) if b.size > 1 else np.nan,
                         "at_bound": bool(min(v - lo, hi - v) < 0.01 * (hi - lo))})
        return pd.DataFrame(rows).set_index("parameter")

    def comparison(self) -> pd.DataFrame:
        """Observed vs simulated stop positions before and after calibration.

        Rows: quantiles p10-p90 and mean [m], 1-Wasserstein distance [m],
        two-sample Kolmogorov-Smirnov D and its p-value (scipy.stats.ks_2samp),
        the objective; columns observed, before, after.

        Returns
        -------
        pandas.DataFrame
        """
        qs = (0.1, 0.25, 0.5, 0.75, 0.9)
        cols = {"observed": self.observed, "before": self.simulated_initial, "after": self.simulated}
        rows = {}
        for q in qs:
            rows[f"p{int(q * 100)} [m]"] = {k: float(np.quantile(v, q)) for k, v in cols.items()}
        rows["mean [m]"] = {k: float(np.mean(v)) for k, v in cols.items()}
        for k in ("before", "after"):
            ks = stats.ks_2samp(cols[k], self.observed)
            rows.setdefault("wasserstein [m]", {"observed": 0.0})[k] = float(
                stats.wasserstein_distance(cols[k], self.observed))
            rows.setdefault("KS D", {"observed": 0.0})[k] = float(ks.statistic)
            rows.setdefault("KS p-value", {"observed": np.nan})[k] = float(ks.pvalue)
        rows[f"objective ({self.distance_name})"] = {"observed": 0.0, "before": self.distance_initial,
                                                      "after": self.distance}
        return pd.DataFrame(rows).T[["observed", "before", "after"]]

    def __repr__(self) -> str:
        return short_repr(self, repr(self.scenario.name), ", ".join(f"{k.rsplit('.', 1)[-1]}={v:.4g}"
                                                                 for k, v in self.parameters.items()),
                          distance=self.distance, distance_initial=self.distance_initial,
                          n_observed=int(self.observed.size), n=self.n)

    def to_toml(self) -> str:
        """The calibrated scenario as TOML text (fitted values in place, a comment naming them).

        Returns
        -------
        str
        """
        head = "# calibrated by simulation.calibrate: " + ", ".join(f"{k} = {v:.6g}" for k, v in self.parameters.items())
        return head + "\n" + dump_toml(self.scenario_data)

    def plot(self, ax=None):
        """Empirical CDFs of observed and simulated stop positions, before and after calibration.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            x: stop position [m]; y: fraction of blocks stopped before x.
        """
        if ax is None:
            import matplotlib.pyplot as plt
            ax = plt.figure(figsize=(7, 4.2)).add_subplot()
        for data, label, style in ((self.observed, f"observed ({self.observed.size})", dict(color="k", lw=2)),
                                   (self.simulated_initial, "simulated, before", dict(color="C0", ls="--")),
                                   (self.simulated, "simulated, calibrated", dict(color="C3"))):
            x = np.sort(data)
            ax.step(x, np.arange(1, x.size + 1) / x.size, where="post", label=label, **style)
        ax.set_xlabel("stop position x [m]")
        ax.set_ylabel("fraction of blocks stopped before x")
        ax.set_title(f"{self.scenario.name}: " + ", ".join(f"{k.split('.')[-2] if k.count('.') > 1 else k}."
                                                           f"{k.split('.')[-1]} = {v:.3g}"
                                                           for k, v in self.parameters.items()), fontsize="small")
        ax.legend(fontsize="small", loc="lower right")
        return ax


def dump_toml(data: dict) -> str:
    """TOML text of a scenario dictionary (tables, inline tables for distributions, [[collectors]]).

    Parameters
    ----------
    data : dict
        Scenario tables.

    Returns
    -------
    str
    """
    def val(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, np.integer)):
            return str(int(v))
        if isinstance(v, (float, np.floating)):
            return repr(float(v))
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {val(x)}" for k, x in v.items()) + " }"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(val(x) for x in v) + "]"
        raise TypeError(f"cannot write {v!r} to TOML")

    lines = [f"{k} = {val(v)}" for k, v in data.items() if not isinstance(v, (dict, list)) or
             (isinstance(v, list) and not any(isinstance(x, dict) for x in v))]

    def table(prefix, d):
        plain = {k: v for k, v in d.items() if not (isinstance(v, dict) and prefix == "materials")}
        sub = {k: v for k, v in d.items() if isinstance(v, dict) and prefix == "materials"}
        if plain:
            lines.append(f"\n[{prefix}]")
            lines.extend(f"{k} = {val(v)}" for k, v in plain.items())
        for k, v in sub.items():
            lines.append(f"\n[{prefix}.{k}]")
            lines.extend(f"{kk} = {val(vv)}" for kk, vv in v.items())

    for k, v in data.items():
        if isinstance(v, dict):
            table(k, v)
        elif isinstance(v, list) and any(isinstance(x, dict) for x in v):
            for item in v:
                lines.append(f"\n[[{k}]]")
                lines.extend(f"{kk} = {val(vv)}" for kk, vv in item.items())
    return "\n".join(lines) + "\n"


def _current_value(data: dict, name: str):
    """The value at dotted path ``name`` (material presets expanded), or nan when the scenario gives none (a
    shared ``materials.A+B.FIELD``: that of the first of its materials the scenario defines)."""
    from .materials import PresetError, resolve_materials
    shared = parameter_materials(name)
    if len(shared) > 1:
        first = next((m for m in shared if m in (data.get("materials") or {})), shared[0])
        name = material_parameter(name, first)
    try:
        node = resolve_materials(data)
    except PresetError:
        node = data
    for key in name.split("."):
        if isinstance(node, list):
            node = {str(i.get("name")): i for i in node if isinstance(i, dict)}
        if isinstance(node, (int, float)) and key == "mean":
            return float(node)
        if not isinstance(node, dict) or key not in node:
            return np.nan
        node = node[key]
    return float(node) if isinstance(node, (int, float)) and not isinstance(node, bool) else np.nan


# ---- the fit ----------------------------------------------------------------------------------------------
def calibrate(scenario, observed=None, parameters: dict | None = None, *, n: int = 1000, seed=1,
              distance: str = "wasserstein", collector: str | None = None, maxiter: int = 20, popsize: int = 8,
              n_bootstrap: int = 200, tol: float = 1e-3, **pooled):
    """Fit scenario parameters to observed stop positions (runout) by minimising a distance between distributions.

    With a list of :class:`simulation.Release` in place of the scenario, the fit is pooled over the releases
    (each with its own profile, mass, radius, shape and release state) and returns a posterior:
    ``calibrate(releases, parameters=...)`` is :func:`simulation.pooled.calibrate_pooled` (its keyword
    arguments ``n_per_release``, ``iterations``, ``n_posterior``, ``n_predictive``, ``obs_error_m``,
    ``n_initial``, ``n_per_iteration`` are accepted here; ``seed`` is passed on).

    Parameters
    ----------
    scenario : path, dict, Scenario or list of Release
        The scenario to calibrate (a Scenario must have been loaded from its TOML file), or the releases of a
        pooled calibration.
    observed : array, DataFrame or path
        Observed horizontal stop positions x [m] in the profile's coordinates (an
        array, a DataFrame with ``x_stop_m`` and optionally ``velocity_ms`` /
        ``height_m`` at ``collector``, or a CSV/Parquet/XLSX file read by
        :func:`read_observed`).  Fewer than 10 stops give a CalibrationWarning.
    parameters : dict
        Dotted scenario path -> (low, high) bounds, e.g.
        ``{"materials.talus.ground_friction_angle_deg": (15, 40),
        "materials.talus.normal_restitution.mean": (0.1, 0.6)}``.
    n : int
        Simulated blocks per evaluation.
    seed : int
        Seed of every evaluation (common random numbers) and of the optimiser and bootstrap
        (None: one is drawn and reported in ``Calibration.seed``).
    distance : {"wasserstein", "cvm"}
        Distance between simulated and observed distributions.
    collector : str, optional
        Collector at which observed ``velocity_ms`` / ``height_m`` columns were measured.
    maxiter, popsize, tol : differential-evolution budget (generations, population per parameter, tolerance).
    n_bootstrap : int
        Bootstrap replicates of the observed stops for the parameter intervals (0 to skip).

    Returns
    -------
    Calibration (one scenario) or PooledCalibration (releases)
    """
    from .pooled.fit import calibrate_pooled
    from .pooled.releases import Release
    if isinstance(scenario, (list, tuple)) and scenario and all(isinstance(r, Release) for r in scenario):
        if parameters is None and isinstance(observed, dict):
            observed, parameters = None, observed
        if observed is not None:
            raise TypeError("a pooled calibration takes the observed stops from each Release (x_stop_m); "
                            "pass observed=None and the parameters as parameters=")
        return calibrate_pooled(scenario, parameters, seed=seed, **pooled)
    if pooled:
        raise TypeError(f"calibrate() got keyword arguments {sorted(pooled)} that only a pooled calibration "
                        "(a list of simulation.Release) takes")
    if observed is None or parameters is None:
        raise TypeError("calibrate(scenario, observed, parameters): observed stops and parameters are required")
    if distance not in _DISTANCES:
        raise ValueError(f"distance = {distance!r} is not one of {sorted(_DISTANCES)}")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 10:
        raise ValueError(f"n must be a whole number of simulated blocks >= 10; got {n!r}")
    for arg, v, lo in (("maxiter", maxiter, 1), ("popsize", popsize, 2), ("n_bootstrap", n_bootstrap, 0)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise ValueError(f"{arg} must be a whole number >= {lo}; got {v!r}")
    if seed is None:          # common random numbers need one seed for every evaluation: draw it once, report it
        seed = int(np.random.SeedSequence().entropy)
    data, source = scenario_dict(scenario)
    base = scenario_from_dict(data, source=source)
    bounds = _check_parameters(data, parameters, source)
    obs_df, obs_source = _observed_frame(observed)
    obs = _check_observed(obs_df, obs_source, base, collector)
    scales = {k: max(float(np.std(v, ddof=1)) if v.size > 1 else 1.0, 1e-9) for k, v in obs.items()}
    dist = _DISTANCES[distance]
    names = list(bounds)
    lo = np.array([bounds[k][0] for k in names])
    hi = np.array([bounds[k][1] for k in names])

    cache: dict = {}

    def evaluate(theta) -> float:
        key = tuple(np.round(theta, 12))
        if key not in cache:
            trial = apply_parameters(data, dict(zip(names, theta)), source=source)
            sim = _simulate(trial, source, int(n), seed, collector)
            cache[key] = (sim, _objective(sim, obs, scales, dist))
        return cache[key][1]

    initial = _simulate(data, source, int(n), seed, collector)
    d_initial = _objective(initial, obs, scales, dist)
    opt = optimize.differential_evolution(evaluate, list(zip(lo, hi)), seed=np.random.SeedSequence(seed)
                                          .generate_state(1)[0], maxiter=maxiter, popsize=popsize, tol=tol,
                                          polish=False, init="sobol", updating="immediate")
    best = np.clip(opt.x, lo, hi)
    # a local design around the optimum, so the bootstrap can move off the optimiser's points
    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(2)[1])
    half = 0.1 * (hi - lo)
    for u in stats.qmc.Sobol(len(names), seed=rng).random(16):
        evaluate(np.clip(best - half + 2 * half * u, lo, hi))
    thetas = np.array(list(cache.keys()))
    sims = [cache[tuple(t)][0] for t in thetas]
    objective = np.array([cache[tuple(t)][1] for t in thetas])
    i_best = int(np.argmin(objective))
    best = thetas[i_best]

    boot_rows = []
    brng = np.random.default_rng(np.random.SeedSequence(seed).spawn(2)[0])
    for _ in range(n_bootstrap):
        resampled = {k: v[brng.integers(0, v.size, v.size)] for k, v in obs.items()}
        d = [_objective(s, resampled, scales, dist) for s in sims]
        boot_rows.append(thetas[int(np.argmin(d))])
    bootstrap = pd.DataFrame(np.array(boot_rows).reshape(-1, len(names)), columns=names)

    fitted = {k: float(v) for k, v in zip(names, best)}
    fitted_data = apply_parameters(data, fitted, source=source)
    notes = []
    for k, v in fitted.items():
        b_lo, b_hi = bounds[k]
        if min(v - b_lo, b_hi - v) < 0.01 * (b_hi - b_lo):
            msg = (f"parameter {k!r} = {v:.4g} is at its bound [{b_lo:g}, {b_hi:g}]: the best fit may lie outside; "
                   "widen the bounds if physically admissible")
            notes.append(msg)
            warnings.warn(msg, CalibrationWarning, stacklevel=2)
    best_sim = sims[i_best]
    if best_sim["left_profile"] > 0:
        notes.append(f"{best_sim['left_profile']:.1%} of simulated blocks left the profile (counted at its end)")
    evaluations = pd.DataFrame(thetas, columns=names).assign(distance=objective)
    return Calibration(
        parameters=fitted, bounds=bounds, scenario=scenario_from_dict(fitted_data, source=source),
        scenario_data=fitted_data, initial_parameters={k: _current_value(data, k) for k in names},
        observed=obs["x_stop_m"], simulated=best_sim["x_stop_m"], simulated_initial=initial["x_stop_m"],
        distance=float(objective[i_best]), distance_initial=float(d_initial), distance_name=distance,
        bootstrap=bootstrap, evaluations=evaluations, n=int(n), seed=seed, observed_source=obs_source,
        left_profile_fraction=float(best_sim["left_profile"]), notes=tuple(notes))
