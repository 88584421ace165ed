"""The simulator of a pooled calibration: every release, and every reach constraint, for one parameter set.

:class:`_Pool` parses each release's scenario once, checks the releases against their profiles (or DEMs),
swaps a parameter set's values into the materials and simulates the stops of every release: on a 2-D profile
with :func:`simulation.run` (releases that share a scenario and a release state in one kernel call, masses per
block), on a DEM with :func:`simulation.run_terrain` (the plan runout from the release point).
:class:`_ConstraintPool` does the same for the reach constraints' slopes and reads their far-limit shadow angles.
"""
from __future__ import annotations

import copy
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from ..parameters import check_material_names, scenario_dict, set_parameter
from ..materials import material_parameter, parameter_materials, parameter_sets_any
from ..scenario import Distribution, Material, Scenario, ScenarioError, scenario_from_dict
from ..units import DENSITY_RANGE_KG_M3
from .releases import _RELEASE_FIELDS, Release

#: Release fields a 3-D release may not set (its scenario's [sources] table gives them).
_PROFILE_ONLY_FIELDS = ("x_m", "vx_ms", "vz_ms", "downslope_speed_ms", "shape", "aspect_ratio", "radius_m")


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
        from ..engine import run
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
    from ..scenario3d import terrain_scenario_from_dict
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
    from ..engine3d import run_terrain
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
        from ..engine import run
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
