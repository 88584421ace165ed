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

References: see above; Sisson, Fan & Beaumont (2018) Handbook of ABC, ch. 1 and 4.
"""
from __future__ import annotations

import copy
import json
import math
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from ._display import Displayed, short_repr
from .parameters import check_material_names, scenario_dict, set_parameter
from .materials import material_parameter, parameter_materials, parameter_sets_any
from .scenario import Distribution, Material, Scenario, ScenarioError, scenario_from_dict
from .surrogate import _in_unit_box, _t_draw, _t_logpdf, gp_posterior_sample, replicate_noise
from .units import DENSITY_RANGE_KG_M3

#: Share of the predictive density spread uniformly over the profile (the defensive mixture).
DEFENSIVE_SHARE = 1e-3
_RELEASE_FIELDS = ("x_m", "height_m", "vx_ms", "vz_ms", "downslope_speed_ms", "shape", "aspect_ratio")
#: Release fields a 3-D release may not set (its scenario's [sources] table gives them).
_PROFILE_ONLY_FIELDS = ("x_m", "vx_ms", "vz_ms", "downslope_speed_ms", "shape", "aspect_ratio", "radius_m")


class PooledCalibrationWarning(UserWarning):
    """The pooled calibration ran but its posterior deserves caution (few effective samples, mass at a bound)."""


@dataclass(frozen=True)
class Release(Displayed):
    """One release: observed stops of blocks released the same way, with their own scenario.

    Parameters
    ----------
    name : str
        Named in every message.
    scenario : path, dict or Scenario
        The release's profile and materials (a Scenario must have been loaded from its TOML file).
    x_stop_m : array
        Observed horizontal stop positions [m] in the profile's coordinates (one per observed block); for a
        3-D release (a scenario with a ``[terrain]`` table), the plan runout [m] of each stop from the release
        point.
    mass_kg : float, optional
        Block mass [kg]; the scenario's seeder mass distribution when None.
    radius_m : float, optional
        Block radius [m]; with the mass it sets the density used for this release (else the seeder's density
        gives the radius).
    x_m, height_m, vx_ms, vz_ms, downslope_speed_ms : float, optional
        Release position [m], height above the ground [m], velocity [m/s] and push down the ground [m/s];
        the scenario's seeder values when None.
    shape : str, optional
        "sphere", "cylinder" or "disc".
    aspect_ratio : float, optional
        Length of a cylinder (or thickness of a disc) over its diameter [-]; the scenario's seeder value when None.
        :func:`simulation.units.box_rolling_cylinder` gives radius and aspect ratio from a block's measured sizes.
    source : str
        The file (or other origin) the release was read from, named in errors.
    """

    name: str
    scenario: object
    x_stop_m: object
    mass_kg: float | None = None
    radius_m: float | None = None
    x_m: float | None = None
    height_m: float | None = None
    vx_ms: float | None = None
    vz_ms: float | None = None
    downslope_speed_ms: float | None = None
    shape: str | None = None
    aspect_ratio: float | None = None
    source: str = "<releases>"

    def __repr__(self) -> str:
        x = np.asarray(self.x_stop_m, dtype=float).ravel()
        return short_repr(self, repr(self.name), f"{x.size} stops", scenario=_scenario_name(self.scenario),
                          mass_kg=self.mass_kg, radius_m=self.radius_m)

    def summary(self) -> pd.DataFrame:
        """The release as one row: its scenario, release state (None: the scenario's seeder value) and observed
        stops.

        Returns
        -------
        pandas.DataFrame
            ``release``, ``scenario``, ``n_observed``, ``stop_min_m``/``stop_median_m``/``stop_max_m`` (stop
            positions, or plan runouts of a 3-D release [m]), ``mass_kg``, ``radius_m``, ``x_m``, ``height_m``,
            ``vx_ms``, ``vz_ms``, ``downslope_speed_ms``, ``shape``, ``aspect_ratio`` and ``source``.
        """
        x = np.asarray(self.x_stop_m, dtype=float).ravel()
        ok = x[np.isfinite(x)]
        stats_ = np.quantile(ok, [0.0, 0.5, 1.0]) if ok.size else [np.nan] * 3
        return pd.DataFrame([{"release": self.name, "scenario": _scenario_name(self.scenario), "n_observed": x.size,
                              "stop_min_m": stats_[0], "stop_median_m": stats_[1], "stop_max_m": stats_[2],
                              "mass_kg": self.mass_kg, "radius_m": self.radius_m, "x_m": self.x_m,
                              "height_m": self.height_m, "vx_ms": self.vx_ms, "vz_ms": self.vz_ms,
                              "downslope_speed_ms": self.downslope_speed_ms, "shape": self.shape,
                              "aspect_ratio": self.aspect_ratio, "source": self.source}])


def _scenario_name(scenario) -> str:
    """A short name of a release's scenario: the file name of a path or of a loaded Scenario, a dict's name."""
    if isinstance(scenario, (str, Path)):
        return Path(scenario).name
    if isinstance(scenario, dict):
        return str(scenario.get("name", "<dict>"))
    src = getattr(scenario, "source", None)
    if src and not str(src).startswith("<"):
        return Path(str(src)).name
    return str(getattr(scenario, "name", type(scenario).__name__))


@dataclass(frozen=True)
class ReachConstraint(Displayed):
    """A published far limit of deposition, used as one more term of a pooled likelihood.

    Some data sets give no stop positions but the **shadow angle** of the farthest deposits below a talus: the
    angle, from the horizontal, of the line from the top of the talus (the apex) to the distal limit of the
    boulders' shadow (Evans & Hungr 1993, Can. Geotech. J. 30:620, abstract: "an empirical minimum shadow
    angle of 27.5 deg").  The term is a Gaussian log-density of the simulated shadow angle of the stop quantile
    ``quantile`` (the far limit of ``n_blocks`` simulated blocks) about ``shadow_angle_deg`` with standard
    deviation ``sd_deg``.

    Parameters
    ----------
    name : str
        Named in every message and table.
    scenario : path, dict or Scenario
        The slope (a cliff over a talus) whose materials share the calibrated parameters.
    apex_x_m, apex_z_m : float
        Top of the talus [m] in the scenario's profile coordinates.
    shadow_angle_deg : float
        Observed shadow angle of the far limit [deg].
    sd_deg : float
        Its standard deviation [deg] (the spread between sites and the reading of the limit; an assumption the
        caller states).
    quantile : float
        Quantile of the simulated stops read as the far limit (default 0.99).
    n_blocks : int
        Simulated blocks per parameter set (default 200).
    source : str
        Where the numbers come from, named in errors.
    """

    name: str
    scenario: object
    apex_x_m: float
    apex_z_m: float
    shadow_angle_deg: float
    sd_deg: float
    quantile: float = 0.99
    n_blocks: int = 200
    source: str = "<constraint>"

    def shadow_angle(self, x_stop_m, z_stop_m):
        """Shadow angle [deg] of stops at (x, z) [m] seen from the apex (90 deg for stops above or behind it).

        Parameters
        ----------
        x_stop_m : array_like
            Horizontal positions of the stops along the profile [m].
        z_stop_m : array_like
            Elevations of the stops [m] (broadcast with ``x_stop_m``).

        Returns
        -------
        numpy.ndarray
            ``degrees(arctan2(apex_z_m - z, max(x - apex_x_m, 1e-9)))`` [deg], one per stop.
        """
        dx = np.asarray(x_stop_m, float) - self.apex_x_m
        dz = self.apex_z_m - np.asarray(z_stop_m, float)
        return np.degrees(np.arctan2(dz, np.maximum(dx, 1e-9)))

    def __repr__(self) -> str:
        return short_repr(self, repr(self.name), shadow_angle_deg=self.shadow_angle_deg, sd_deg=self.sd_deg,
                          quantile=self.quantile, scenario=_scenario_name(self.scenario))

    def summary(self) -> pd.DataFrame:
        """The constraint as one row.

        Returns
        -------
        pandas.DataFrame
            ``constraint``, ``scenario``, ``apex_x_m``/``apex_z_m`` [m], ``shadow_angle_deg`` and ``sd_deg``
            [deg], ``quantile``, ``n_blocks`` and ``source``.
        """
        return pd.DataFrame([{"constraint": self.name, "scenario": _scenario_name(self.scenario),
                              "apex_x_m": self.apex_x_m, "apex_z_m": self.apex_z_m,
                              "shadow_angle_deg": self.shadow_angle_deg, "sd_deg": self.sd_deg,
                              "quantile": self.quantile, "n_blocks": self.n_blocks, "source": self.source}])

    def _release(self):
        return Release(name=self.name, scenario=self.scenario, x_stop_m=[self.apex_x_m], source=self.source)


def _check_constraints(constraints) -> list:
    constraints = list(constraints or ())
    for c in constraints:
        if not isinstance(c, ReachConstraint):
            raise TypeError(f"constraints must be simulation.pooled.ReachConstraint objects; got {type(c).__name__}")
        where = f"{c.source}: constraint {c.name!r}"
        if not (np.isfinite(c.shadow_angle_deg) and 0.0 < c.shadow_angle_deg < 90.0):
            raise ValueError(f"{where}: shadow_angle_deg = {c.shadow_angle_deg!r} must lie in (0, 90) deg")
        if not (np.isfinite(c.sd_deg) and c.sd_deg > 0.0):
            raise ValueError(f"{where}: sd_deg = {c.sd_deg!r} must be a finite number > 0 deg")
        if not 0.5 <= c.quantile < 1.0:
            raise ValueError(f"{where}: quantile = {c.quantile!r} must lie in [0.5, 1)")
        if isinstance(c.n_blocks, bool) or not isinstance(c.n_blocks, (int, np.integer)) or c.n_blocks < 20:
            raise ValueError(f"{where}: n_blocks = {c.n_blocks!r} must be a whole number >= 20")
    return constraints


class _ConstraintPool:
    """The reach constraints' scenarios, with the parameters each defines swapped in per parameter set."""

    def __init__(self, constraints, parameters: dict):
        self.constraints = constraints
        self.pools = []
        self.materials = set()          # every material the constraints' scenarios define
        for c in constraints:
            data, _ = scenario_dict(c.scenario)
            mats = data.get("materials", {})
            self.materials.update(mats)
            own = {k: b for k, b in parameters.items() if parameter_sets_any(k, mats)}
            # a shared parameter needs only one of its materials here (calibrate_pooled checks all of them)
            listed = {m for k in own for m in parameter_materials(k)}
            self.pools.append((_Pool([c._release()], own, extra_materials=listed) if own else None, own))

    def simulate(self, values: dict, seed) -> list:
        """(x, z) of the simulated stops [m] per constraint."""
        from .engine import run
        out = []
        for g, (c, (pool, own)) in enumerate(zip(self.constraints, self.pools)):
            if pool is not None:
                sc = pool.scenarios({k: v for k, v in values.items() if k in own})[pool.rel_key[0]]
            else:
                data, src = scenario_dict(c.scenario)
                sc = scenario_from_dict(data, source=src)
            res = run(sc, n=int(c.n_blocks), seed=[int(seed), 7919, g], record_paths=0)
            out.append((np.asarray(res.per_block["x"], float), np.asarray(sc.profile.x, float),
                        np.asarray(sc.profile.z, float)))
        return out

    def far_angles(self, sims) -> list:
        """Shadow angle [deg] of each constraint's simulated far limit (its ``quantile`` of the stops)."""
        out = []
        for c, (x, px, pz) in zip(self.constraints, sims):
            far = float(np.quantile(x, c.quantile))
            out.append(float(c.shadow_angle(far, np.interp(far, px, pz))))
        return out

    def log_likelihood(self, sims) -> float:
        """Sum of the Gaussian log-densities of the simulated far-limit shadow angles about the observed ones."""
        return float(sum(stats.norm.logpdf(a, c.shadow_angle_deg, c.sd_deg)
                         for c, a in zip(self.constraints, self.far_angles(sims))))

    def table(self, angles_per_draw) -> pd.DataFrame:
        """Per constraint: the observed angle and the posterior-predictive shadow angle of the far limit [deg]."""
        cols = ["constraint", "observed_deg", "sd_deg", "predicted_median_deg", "predicted_q05_deg",
                "predicted_q95_deg"]
        rows = []
        for i, c in enumerate(self.constraints):
            a = np.asarray([d[i] for d in angles_per_draw], float)
            q = np.quantile(a, [0.5, 0.05, 0.95]) if a.size else [np.nan] * 3
            rows.append(dict(zip(cols, [c.name, c.shadow_angle_deg, c.sd_deg, *map(float, q)])))
        return pd.DataFrame(rows, columns=cols).set_index("constraint")


# ---- reading and checking releases ----------------------------------------------------------------------------------
def read_releases(path, scenarios: dict, *, release_column="release", scenario_column: str = "scenario") -> list[Release]:
    """Releases from a CSV file: one row per observed block.

    Columns: ``release`` (name; rows sharing it form one release), ``scenario`` (a key of ``scenarios``, the
    mapping of names to scenario paths, dicts or Scenarios), ``x_stop_m`` [m]; optionally ``mass_kg``,
    ``radius_m``, ``x_m``, ``height_m``, ``vx_ms``, ``vz_ms``, ``downslope_speed_ms``, ``shape``,
    ``aspect_ratio`` -- one value per release (rows of a release must agree).  A column given for some releases
    must be given for all.  Errors name the file, the release (and line) and the field.

    Parameters
    ----------
    path : str or pathlib.Path
        The CSV file of observed stops.
    scenarios : dict
        Scenario name (as in the ``scenario`` column) -> scenario path, dict or :class:`Scenario`.
    release_column : str or list of str, optional
        Column that names the release (default ``"release"``), or several whose values together name it (joined
        by "-", e.g. ``["profile", "block"]`` gives "P1-3").
    scenario_column : str, optional
        Column that holds the scenario name (default ``"scenario"``).

    Returns
    -------
    list of Release
        One per release name, in file order, checked by :func:`check_releases`; ``x_stop_m`` [m], ``mass_kg``
        [kg], ``radius_m`` [m], release state in [m] and [m/s].

    Raises
    ------
    FileNotFoundError
        When ``path`` does not exist.
    ValueError
        A missing column, an unknown scenario, a non-numeric stop or a field that differs between a release's rows.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"releases file not found: {path}")
    name_cols = [release_column] if isinstance(release_column, str) else list(release_column)
    df = pd.read_csv(path, dtype={c: str for c in name_cols + [scenario_column]})     # names as written
    df.index = df.index + 2                       # CSV line numbers (line 1 is the header)
    for col in name_cols + [scenario_column, "x_stop_m"]:
        if col not in df.columns:
            raise ValueError(f"{path}: no column {col!r} (columns: {list(df.columns)})")
    for col in name_cols + [scenario_column]:
        empty = df[col].isna() | (df[col].str.strip() == "")
        if empty.any():
            raise ValueError(f"{path}: line {empty.idxmax()}: column {col!r} is empty (every row names its release "
                             "and scenario)")
    names = df[name_cols].agg("-".join, axis=1)
    out = []
    for name, rows in df.groupby(names, sort=False):
        key = rows[scenario_column].iloc[0]
        if (rows[scenario_column] != key).any():
            raise ValueError(f"{path}: release {name!r} names several scenarios "
                             f"{sorted(set(rows[scenario_column]))}")
        if key not in scenarios:
            raise ValueError(f"{path}: release {name!r} (line {rows.index[0]}): {scenario_column} = {key!r} is not "
                             f"one of {sorted(scenarios)}")
        kw = {}
        for col in ("mass_kg", "radius_m") + _RELEASE_FIELDS:
            if col not in rows.columns:
                continue
            vals = rows[col].dropna().unique()
            if len(vals) > 1:
                raise ValueError(f"{path}: release {name!r}: field {col} differs between its rows ({list(vals)}); "
                                 "one value per release")
            if len(vals) == 1:
                kw[col] = vals[0] if col == "shape" else float(vals[0])
        x = pd.to_numeric(rows["x_stop_m"], errors="coerce")
        if x.isna().any():
            line = x.index[int(np.argmax(x.isna().to_numpy()))]
            raise ValueError(f"{path}: release {name!r} (line {line}): x_stop_m = {rows['x_stop_m'].loc[line]!r} is not "
                             "a number")
        out.append(Release(name=str(name), scenario=scenarios[key], x_stop_m=x.to_numpy(float), source=str(path),
                           **kw))
    return check_releases(out)


def check_releases(releases) -> list[Release]:
    """The releases checked before any simulation: observed stops and release points inside each release's
    profile, positive finite masses and radii, and mass / radius given for all releases or none.  Errors name
    the file, the release and the field.

    Parameters
    ----------
    releases : iterable of Release
        The releases to pool (names unique).

    Returns
    -------
    list of Release
        The same releases, as a list, when all checks pass.

    Raises
    ------
    ValueError
        Empty input, repeated names, a release without observed stops or with stops [m] not finite, a mass [kg] or
        radius [m] not finite and > 0, or a mass / radius given for only some releases.
    TypeError
        An item that is not a :class:`Release`.
    """
    releases = list(releases)
    if not releases:
        raise ValueError("no releases given")
    if not all(isinstance(r, Release) for r in releases):
        bad = next(r for r in releases if not isinstance(r, Release))
        raise TypeError(f"releases must be simulation.Release objects; got {type(bad).__name__}")
    names = [r.name for r in releases]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})
        raise ValueError(f"{releases[0].source}: release names must be unique; repeated: {dup}")
    for fld in ("mass_kg", "radius_m"):
        given = [r for r in releases if getattr(r, fld) is not None]
        if given and len(given) < len(releases):
            missing = [r.name for r in releases if getattr(r, fld) is None]
            raise ValueError(f"{releases[0].source}: field {fld} is given for {len(given)} releases and missing for "
                             f"{len(missing)}: {missing[:10]}{' ...' if len(missing) > 10 else ''}; give it for every "
                             "release or for none (the scenario's seeder then decides)")
    for r in releases:
        where = f"{r.source}: release {r.name!r}"
        for fld in ("mass_kg", "radius_m", "aspect_ratio"):
            v = getattr(r, fld)
            if v is not None and not (np.isfinite(v) and v > 0):
                raise ValueError(f"{where}: {fld} = {v!r} must be a finite number > 0")
        x = np.asarray(r.x_stop_m, dtype=float).ravel()
        if x.size == 0:
            raise ValueError(f"{where}: no observed stops (x_stop_m)")
        if not np.isfinite(x).all():
            raise ValueError(f"{where}: x_stop_m holds {x[~np.isfinite(x)][0]!r}; stops must be finite [m]")
    return releases


# ---- the simulator for many releases --------------------------------------------------------------------------------
class _Pool:
    """Every release's scenario parsed once; new material values swapped in per parameter set."""

    def __init__(self, releases, parameters: dict, extra_materials=()):
        self.releases = releases
        self.bases = {}          # key -> (data, source, Scenario)
        self.rel_key = []
        for r in releases:
            key = r.scenario if isinstance(r.scenario, (str, Path)) else id(r.scenario)
            key = str(key)
            if key not in self.bases:
                data, src = scenario_dict(r.scenario)
                self.bases[key] = (data, src, _build_scenario(data, src, r))
            self.rel_key.append(key)
        self._check_geometry()
        self.names = list(parameters)
        check_material_names(self.names)
        self.bounds = {}
        for name, b in parameters.items():
            mats = parameter_materials(name)
            if not mats:
                raise ValueError(f"parameter {name!r}: a pooled calibration fits material fields shared by the "
                                 "releases: 'materials.NAME.FIELD' (e.g. 'materials.talus.ground_friction_angle_deg'; "
                                 "'materials.A+B.FIELD' shares one value between materials A and B)")
            for m in mats:                   # every listed material, so a misspelt one is not dropped
                if m not in extra_materials and not any(m in data.get("materials", {})
                                                        for data, _, _ in self.bases.values()):
                    files = sorted({src for _, src, _ in self.bases.values()})
                    raise ValueError(f"parameter {name!r}: no release's scenario defines material {m!r} "
                                     f"(scenarios: {files})")
            try:
                lo, hi = (float(v) for v in b)
            except (TypeError, ValueError):
                raise ValueError(f"parameter {name!r}: bounds must be (low, high) numbers; got {b!r}") from None
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError(f"parameter {name!r}: bounds must be finite with low < high; got ({lo:g}, {hi:g})")
            self.bounds[name] = (lo, hi)
        for name, (lo, hi) in self.bounds.items():      # both bounds must give valid materials
            for v in (lo, hi):
                try:
                    self.scenarios({name: v})
                except ScenarioError as exc:
                    raise ValueError(f"parameter {name!r} = {v:g} (a bound): {exc}") from None
        # releases sharing a scenario and a release state run together (one kernel call, masses per block)
        self.groups = {}
        for i, r in enumerate(releases):
            gkey = (self.rel_key[i],) + tuple(getattr(r, f) for f in _RELEASE_FIELDS) + (
                None if r.radius_m is None else (r.radius_m, r.mass_kg),)
            self.groups.setdefault(gkey, []).append(i)

    def is_terrain(self, i: int) -> bool:
        """True when release ``i`` runs on a DEM (3-D kernel)."""
        return not isinstance(self.bases[self.rel_key[i]][2], Scenario)

    def support_lengths(self) -> list[float]:
        """Per release, the length [m] the defensive mixture spreads over: the profile's length in 2-D, the DEM's
        plan diagonal (the longest possible plan runout) in 3-D."""
        out = []
        for key in self.rel_key:
            sc = self.bases[key][2]
            if isinstance(sc, Scenario):
                out.append(float(sc.profile.x[-1] - sc.profile.x[0]))
            else:
                x0, y0, x1, y1 = sc.terrain.bounds
                out.append(float(math.hypot(x1 - x0, y1 - y0)))
        return out

    def _check_geometry(self):
        for i, (r, key) in enumerate(zip(self.releases, self.rel_key)):
            sc = self.bases[key][2]
            if self.is_terrain(i):
                _check_terrain_release(r, sc)
                continue
            lo, hi = sc.profile.x[0], sc.profile.x[-1]
            where = f"{r.source}: release {r.name!r}"
            x = np.asarray(r.x_stop_m, dtype=float).ravel()
            out = (x < lo) | (x > hi)
            if out.any():
                raise ValueError(f"{where}: x_stop_m = {x[out][0]:g} m is outside the profile of {sc.source} "
                                 f"[{lo:g}, {hi:g}] m")
            if r.x_m is not None and not (lo <= r.x_m < hi):
                raise ValueError(f"{where}: x_m = {r.x_m:g} m (the release point) is outside the profile of "
                                 f"{sc.source} [{lo:g}, {hi:g}) m")
            if r.shape is not None and r.shape not in ("sphere", "cylinder", "disc"):
                raise ValueError(f"{where}: shape = {r.shape!r} is not 'sphere', 'cylinder' or 'disc'")
            if r.radius_m is not None:
                shape = r.shape or sc.seeder.shape
                aspect = r.aspect_ratio or sc.seeder.aspect_ratio
                rho = _density(r.mass_kg, r.radius_m, shape, aspect)
                body = shape if shape == "sphere" else f"{shape} of aspect ratio {aspect:g}"
                lo, hi = DENSITY_RANGE_KG_M3
                if not lo <= rho <= hi:
                    raise ValueError(f"{where}: mass_kg = {r.mass_kg:g} and radius_m = {r.radius_m:g} give a "
                                     f"density of {rho:,.0f} kg/m^3 for a {body}, outside [{lo:g}, {hi:g}]")

    def scenarios(self, values: dict) -> dict:
        """Scenario per base key with the parameter values put into its materials."""
        out = {}
        for key, (data, src, sc) in self.bases.items():
            mats = list(sc.materials)
            names = [m.name for m in mats]
            touched = {}
            for pname, v in values.items():
                for mat in parameter_materials(pname):
                    if mat not in names:
                        continue
                    spec = touched.setdefault(mat, {"materials": {mat: copy.deepcopy(data["materials"][mat])}})
                    set_parameter(spec, material_parameter(pname, mat), v, source=src)
            for mat, spec in touched.items():
                mats[names.index(mat)] = Material.parse(mat, spec["materials"][mat], src)
            out[key] = replace(sc, materials=tuple(mats)) if touched else sc
        return out

    def simulate(self, values: dict, n_per: int, seed) -> list[np.ndarray]:
        """Simulated stops [m] per release (n_per blocks each) for one parameter set."""
        from .engine import run
        scs = self.scenarios(values)
        out = [None] * len(self.releases)
        for g, (gkey, idx) in enumerate(self.groups.items()):
            r0 = self.releases[idx[0]]
            if self.is_terrain(idx[0]):
                runout = _simulate_terrain(scs[gkey[0]], [self.releases[i] for i in idx], n_per, [int(seed), g])
                for j, i in enumerate(idx):
                    out[i] = runout[j * n_per:(j + 1) * n_per]
                continue
            sc = _with_release_state(scs[gkey[0]], r0)
            masses = None
            if r0.mass_kg is not None:
                masses = np.repeat([self.releases[i].mass_kg for i in idx], n_per)
                res = run(sc, seed=[int(seed), g], masses_kg=masses, record_paths=0)
            else:
                res = run(sc, n=n_per * len(idx), seed=[int(seed), g], record_paths=0)
            x = res.per_block["x"]
            for j, i in enumerate(idx):
                out[i] = x[j * n_per:(j + 1) * n_per]
        return out


def _build_scenario(data: dict, src: str, r: Release):
    """The checked scenario of release ``r``: a 2-D :class:`Scenario`, or a ``TerrainScenario`` when ``data`` has a
    ``[terrain]`` table (its files relative to the scenario file).  A 3-D scenario's errors (a source outside
    the DEM, ...) are raised naming the release."""
    if "terrain" not in data:
        return scenario_from_dict(data, source=src)
    from .scenario3d import terrain_scenario_from_dict
    base = Path(src).parent if Path(src).is_file() else None
    try:
        return terrain_scenario_from_dict(data, source=src, base_dir=base)
    except ScenarioError as exc:
        raise ValueError(f"{r.source}: release {r.name!r} (3-D scenario): {exc}") from None


def _check_terrain_release(r: Release, sc) -> None:
    """A 3-D release: plan runouts >= 0 and within the DEM's plan diagonal, and no 2-D-only release field."""
    where = f"{r.source}: release {r.name!r}"
    for fld in _PROFILE_ONLY_FIELDS:
        if getattr(r, fld) is not None:
            raise ValueError(f"{where}: field {fld} = {getattr(r, fld)!r} applies to a 2-D profile only; a 3-D "
                             f"release ({sc.source}) takes its release state from the scenario's [sources] table "
                             "(set mass_kg and height_m at most)")
    x0, y0, x1, y1 = sc.terrain.bounds
    diag = math.hypot(x1 - x0, y1 - y0)
    x = np.asarray(r.x_stop_m, dtype=float).ravel()
    bad = (x < 0) | (x > diag)
    if bad.any():
        raise ValueError(f"{where}: x_stop_m = {x[bad][0]:g} m is not a plan runout on the DEM of {sc.source} "
                         f"([0, {diag:.1f}] m: from the release point to the DEM's plan diagonal)")
    if r.height_m is not None and not (np.isfinite(r.height_m) and r.height_m >= 0):
        raise ValueError(f"{where}: height_m = {r.height_m!r} must be a finite number >= 0 m")


def _simulate_terrain(sc, rels: list, n_per: int, seed) -> np.ndarray:
    """Plan runouts [m] of ``n_per`` blocks per release in ``rels`` (one 3-D scenario and release state)."""
    from .engine3d import run_terrain
    r0 = rels[0]
    if r0.height_m is not None:
        height = Distribution("constant", {"value": float(r0.height_m)})
        sc = replace(sc, sources=replace(sc.sources, height_m=height))
    if r0.mass_kg is not None:
        res = run_terrain(sc, seed=seed, masses_kg=np.repeat([r.mass_kg for r in rels], n_per), record_paths=0)
    else:
        res = run_terrain(sc, n=n_per * len(rels), seed=seed, record_paths=0)
    pb, b = res.per_block, res.blocks
    return np.hypot(pb["x"] - b["x"], pb["y"] - b["y"])


def _density(mass, radius, shape, aspect):
    if shape in ("cylinder", "disc"):
        return mass / (2.0 * np.pi * aspect * radius ** 3)
    return 3.0 * mass / (4.0 * np.pi * radius ** 3)


def _with_release_state(sc: Scenario, r: Release) -> Scenario:
    sd = sc.seeder
    const = lambda v: Distribution("constant", {"value": float(v)})  # noqa: E731
    kw = {}
    if r.x_m is not None:
        kw.update(x_low=float(r.x_m), x_high=float(r.x_m))
    for fld, attr in (("height_m", "height_m"), ("vx_ms", "vx_ms"), ("vz_ms", "vz_ms"),
                      ("downslope_speed_ms", "downslope_speed_ms")):
        if getattr(r, fld) is not None:
            kw[attr] = const(getattr(r, fld))
    if r.shape is not None:
        kw["shape"] = r.shape
    if r.aspect_ratio is not None:
        kw["aspect_ratio"] = float(r.aspect_ratio)
    if r.radius_m is not None:
        kw["density_kg_m3"] = float(_density(r.mass_kg, r.radius_m, r.shape or sd.shape,
                                             r.aspect_ratio or sd.aspect_ratio))
    return replace(sc, seeder=replace(sd, **kw)) if kw else sc


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


# ---- the result ---------------------------------------------------------------------------------------------------
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
        from . import plotting
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


# ---- the fit ----------------------------------------------------------------------------------------------------------
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
