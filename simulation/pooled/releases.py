"""The observations of a pooled calibration: releases and reach constraints, read and checked.

:class:`Release` holds the observed stops of blocks released one way, with their own scenario;
:func:`read_releases` reads releases from a CSV file (one row per observed block) and :func:`check_releases`
makes the checks done before any simulation.  :class:`ReachConstraint` is a published far limit of deposition
(a shadow angle), checked by :func:`_check_constraints`.  Simulating them is :mod:`simulation.pooled.simulator`.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .._display import Displayed, short_repr

_RELEASE_FIELDS = ("x_m", "height_m", "vx_ms", "vz_ms", "downslope_speed_ms", "shape", "aspect_ratio")


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
