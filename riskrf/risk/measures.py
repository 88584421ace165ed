"""Mitigation measures as transformations of the site, and the effects derived from simulation.

CLIMADA's "measures" are the model (Aznar-Siguan & Bresch 2019, GMD 12:3085, section 2.4):
a measure changes the hazard, the exposure or the vulnerability, and one engine
computes the losses.  Here a measure changes the slope scenario (a ditch is a new
profile), the release (scaling removes blocks of a size range in a source zone), a
barrier line (fence, attenuator, shed) or the exposed line (realignment), and its
effect is computed by re-simulating the scenario with common random numbers (the same
seed and block count as the reference run), never typed.

Geometry template: the Oregon DOT / FHWA rock fall catchment (Pierson, Gullixson &
Chassie 2001, FHWA-OR-RD-02-04): a catchment of width W at the toe of the cut, its
floor D below the ground, a steep wall on the slope side and a foreslope towards the
road.  Lengths in m, masses in kg, energies in kJ.
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace

import numpy as np

from ..core.validation import RiskrfError
from ..hazard.annual_hazard import effective_speeds

#: Horizontal run per unit drop of the ditch wall on the slope side (steep, 0.25H:1V) and of the
#: foreslope on the road side (1H:1V); defaults of :func:`ditch_profile` [assumption, ODOT-style shape].
DITCH_INNER_SLOPE_HV = 0.25
DITCH_OUTER_SLOPE_HV = 1.0


class MeasureError(RiskrfError, ValueError):
    """An option's geometry does not fit the site; the message names the option and field."""


def ground_z(profile, x):
    """Ground elevation [m] of a profile at x [m] (linear between vertices).

    Parameters
    ----------
    profile : simulation.slope.Profile
        The slope profile.
    x : float or array_like
        Horizontal positions [m].

    Returns
    -------
    float or numpy.ndarray
        Ground elevation [m], shaped as ``x``.
    """
    return np.interp(x, profile.x, profile.z)


def ditch_profile(profile, x_m: float, width_m: float, depth_m: float, *, inner_slope_hv: float = DITCH_INNER_SLOPE_HV,
                  outer_slope_hv: float = DITCH_OUTER_SLOPE_HV, material: int | None = None, where: str = "ditch"):
    """A copy of ``profile`` with a catchment ditch dug into it.

    The ditch spans ``x_m`` to ``x_m + width_m``; its flat floor lies ``depth_m``
    below the lower of the two rims; the slope-side wall runs ``inner_slope_hv`` m
    horizontally per m of drop, the road-side foreslope ``outer_slope_hv``.  The
    floor takes material index ``material`` (default: the material under the
    ditch's upslope rim).  Vertices inside the ditch are replaced.

    Parameters
    ----------
    profile : simulation.slope.Profile
        The slope profile.
    x_m : float
        Upslope rim of the ditch [m].
    width_m : float
        Width of the ditch along x [m], > 0.
    depth_m : float
        Depth of the floor below the lower rim [m], > 0.
    inner_slope_hv : float, optional
        Slope-side wall, horizontal run per unit drop [m/m].
    outer_slope_hv : float, optional
        Road-side foreslope, horizontal run per unit drop [m/m].
    material : int, optional
        Material index of the floor; the material under the upslope rim by default.
    where : str, optional
        What to name in error messages (file and option).

    Returns
    -------
    simulation.slope.Profile
        The new profile.

    Raises
    ------
    MeasureError
        When the ditch leaves the profile or is too narrow for its depth and walls.

    References
    ----------
    Pierson, L. A., Gullixson, C. F. and Chassie, R. G. (2001). Rockfall catchment area design guide.
    FHWA-OR-RD-02-04, Oregon Department of Transportation / Federal Highway Administration.
    """
    from simulation.slope import Profile

    x0, w, d = float(x_m), float(width_m), float(depth_m)
    x1 = x0 + w
    if w <= 0 or d <= 0:
        raise MeasureError(f"{where}: width_m = {w:g} and depth_m = {d:g} must be > 0")
    if not (profile.x[0] < x0 and x1 < profile.x[-1]):
        raise MeasureError(f"{where}: x_m = {x0:g} m with width_m = {w:g} m spans {x0:g}-{x1:g} m, outside the "
                           f"profile ({profile.x[0]:g}, {profile.x[-1]:g}) m")
    z0, z1 = float(ground_z(profile, x0)), float(ground_z(profile, x1))
    zb = min(z0, z1) - d
    a, c = inner_slope_hv * (z0 - zb), outer_slope_hv * (z1 - zb)
    if a + c >= w:
        raise MeasureError(f"{where}: width_m = {w:g} m is too narrow for depth_m = {d:g} m with walls of "
                           f"{inner_slope_hv:g}H:1V and {outer_slope_hv:g}H:1V (needs more than {a + c:.3g} m)")
    seg = int(np.clip(np.searchsorted(profile.x, x0, side="right") - 1, 0, profile.material_index.size - 1))
    seg_after = int(np.clip(np.searchsorted(profile.x, x1, side="right") - 1, 0, profile.material_index.size - 1))
    floor = profile.material_index[seg] if material is None else int(material)
    keep_lo = profile.x < x0
    keep_hi = profile.x > x1
    xs = np.concatenate([profile.x[keep_lo], [x0, x0 + a, x1 - c, x1], profile.x[keep_hi]])
    zs = np.concatenate([profile.z[keep_lo], [z0, zb, zb, z1], profile.z[keep_hi]])
    mats = np.concatenate([profile.material_index[:int(keep_lo.sum())],
                           [profile.material_index[seg], floor, profile.material_index[seg_after]],
                           profile.material_index[profile.material_index.size - int(keep_hi.sum()):]])
    return Profile.build(xs, zs, mats, profile.material_names, source=where)


@dataclass(frozen=True)
class Ditch:
    """Geometry of one ditch: start ``x_m``, ``width_m``, ``depth_m`` [m], wall slopes, floor material name."""

    x_m: float
    width_m: float
    depth_m: float
    inner_slope_hv: float = DITCH_INNER_SLOPE_HV
    outer_slope_hv: float = DITCH_OUTER_SLOPE_HV
    material: str | None = None
    option: str = ""

    @property
    def span(self):
        """(start, end) of the ditch along x [m]."""
        return self.x_m, self.x_m + self.width_m


def check_ditches_disjoint(ditches, where: str):
    """Overlapping ditches are an error naming both.

    Parameters
    ----------
    ditches : iterable of Ditch
        The ditches of an option.
    where : str
        What to name in error messages.

    Raises
    ------
    MeasureError
        When two ditches overlap.
    """
    ds = sorted(ditches, key=lambda d: d.x_m)
    for a, b in zip(ds[:-1], ds[1:]):
        if b.x_m < a.span[1]:
            raise MeasureError(f"{where}: ditches {a.option!r} ({a.span[0]:g}-{a.span[1]:g} m) and {b.option!r} "
                               f"({b.span[0]:g}-{b.span[1]:g} m) overlap")


def scenario_with_ditches(scenario, ditches, where: str = "ditch", road_collector: str | None = "road"):
    """A copy of ``scenario`` whose profile carries every ditch in ``ditches`` (they must not overlap and
    must not cut through the ``road_collector`` line).

    Parameters
    ----------
    scenario : simulation.scenario.Scenario
        The slope scenario.
    ditches : iterable of Ditch
        The ditches, not overlapping.
    where : str, optional
        What to name in error messages (file and option).
    road_collector : str or None, optional
        Name of the road collector a ditch must not cut through.

    Returns
    -------
    simulation.scenario.Scenario
        The new scenario (named ``<name>+ditch``).

    Raises
    ------
    MeasureError
        When ditches overlap, a material is unknown or a ditch cuts the road line.
    """
    check_ditches_disjoint(ditches, where)
    prof = scenario.profile
    names = list(prof.material_names)
    for d in ditches:
        w = f"{where}: option {d.option!r}"
        mat = None
        if d.material is not None:
            if d.material not in names:
                raise MeasureError(f"{w}: material = {d.material!r} is not a material of scenario "
                                   f"{scenario.name!r} ({', '.join(names)})")
            mat = names.index(d.material)
        for c in scenario.collectors:
            if d.span[0] <= c.x <= d.span[1] and c.name == road_collector:
                raise MeasureError(f"{w}: the ditch ({d.span[0]:g}-{d.span[1]:g} m) would cut through the road "
                                   f"line (collector {c.name!r} at x = {c.x:g} m)")
        prof = ditch_profile(prof, d.x_m, d.width_m, d.depth_m, inner_slope_hv=d.inner_slope_hv,
                             outer_slope_hv=d.outer_slope_hv, material=mat, where=w)
    return replace(scenario, profile=prof, name=scenario.name + "+ditch")


def seeder_share(scenario, zone, where: str) -> float:
    """Share of released blocks whose release point lies in ``zone`` = (x_lo, x_hi) [m] (uniform line seeder).

    Parameters
    ----------
    scenario : simulation.scenario.Scenario
        The slope scenario.
    zone : tuple of float
        (x_lo, x_hi) of the zone [m], x_lo < x_hi.
    where : str
        What to name in error messages.

    Returns
    -------
    float
        Share of the releases in the zone [-], in [0, 1].

    Raises
    ------
    MeasureError
        When the zone is empty or outside the release zone.
    """
    s = scenario.seeder
    lo, hi = float(zone[0]), float(zone[1])
    if hi <= lo:
        raise MeasureError(f"{where}: zone_x_m = {list(zone)} must be [low, high] with low < high")
    if hi <= s.x_low or lo >= s.x_high and s.x_high > s.x_low:
        raise MeasureError(f"{where}: zone_x_m = {list(zone)} lies outside the release zone of scenario "
                           f"{scenario.name!r} ({s.x_low:g}-{s.x_high:g} m)")
    if s.x_high == s.x_low:
        return 1.0 if lo <= s.x_low <= hi else 0.0
    return float((min(hi, s.x_high) - max(lo, s.x_low)) / (s.x_high - s.x_low))


@dataclass(frozen=True)
class SimulationContext:
    """The slope model behind the options: scenario, collectors, and how re-simulations are run.

    ``n_blocks`` blocks with ``seed`` for each re-simulation; the reference run uses
    the same blocks (common random numbers), so a difference between an option and
    the reference is the option's effect, not Monte Carlo noise.
    """

    scenario: object
    barrier_collector: str = "barrier"
    road_collector: str = "road"
    n_blocks: int = 20_000
    seed: int = 1

    threads: int = 0              # simulations run at once by run_many (0: one per core); corridor workers use 1

    def run(self, scenario, seed: int | None = None, n_blocks: int | None = None):
        """Simulate ``scenario`` with this context's number of blocks and seed (no recorded paths); a
        :class:`simulation.SimulationResult`.

        Parameters
        ----------
        scenario : simulation.scenario.Scenario
            The slope scenario.
        seed : int, optional
            Seed of this run (default the context's ``seed``: common random numbers).
        n_blocks : int, optional
            Blocks of this run (default the context's ``n_blocks``).

        Returns
        -------
        simulation.SimulationResult
            The simulated run of ``n_blocks`` blocks with ``seed``.
        """
        import simulation
        return simulation.run(scenario, n=self.n_blocks if n_blocks is None else int(n_blocks),
                              seed=self.seed if seed is None else seed, record_paths=0)

    def run_many(self, scenarios, seeds=None, n_blocks=None) -> list:
        """:meth:`run` for each scenario, several at once on threads (the kernel releases the GIL); the results
        are those of one-by-one runs, in order.

        Parameters
        ----------
        scenarios : iterable of simulation.scenario.Scenario
            The scenarios to simulate.
        seeds : sequence of int or None, optional
            One seed per scenario (None entries, or no sequence: the context's seed).
        n_blocks : sequence of int or None, optional
            Blocks per scenario (None entries, or no sequence: the context's ``n_blocks``).

        Returns
        -------
        list of simulation.SimulationResult
            One result per scenario, in order.
        """
        scenarios = list(scenarios)
        seeds = [None] * len(scenarios) if seeds is None else list(seeds)
        blocks = [None] * len(scenarios) if n_blocks is None else list(n_blocks)
        threads = min(self.threads or os.cpu_count() or 1, len(scenarios))
        if threads <= 1:
            return [self.run(sc, s, n) for sc, s, n in zip(scenarios, seeds, blocks)]
        with ThreadPoolExecutor(threads) as pool:
            return list(pool.map(self.run, scenarios, seeds, blocks))


def road_crossings(result, road: str) -> np.ndarray:
    """Indices of blocks that cross the road line (first crossings).

    Parameters
    ----------
    result : simulation.SimulationResult
        A simulated run.
    road : str
        Name of the road collector.

    Returns
    -------
    numpy.ndarray of int
        Sorted block indices.
    """
    return np.unique(result.collector(road, first_only=True)["block"].to_numpy())


def runout_beyond(result, x_m: float) -> np.ndarray:
    """Boolean per block: did it travel past x [m] (stopped beyond it or left the profile)?

    Parameters
    ----------
    result : simulation.SimulationResult
        A simulated run.
    x_m : float
        Horizontal position [m].

    Returns
    -------
    numpy.ndarray of bool
        One value per block.
    """
    ro = result.runout
    return (ro["x_stop_m"].to_numpy() > x_m) | (ro["reason"].astype(str).to_numpy() == "left profile")


#: Material parameters that can be uncertain, as written in a scenario file -> field of simulation.scenario.Material.
MATERIAL_FIELDS = {"normal_restitution.mean": "en_mean", "normal_restitution.std": "en_std",
                   "tangential.mean": "et_mean", "tangential.friction_angle_deg": "friction_deg",
                   "tangential.normal_scale_ms": "et_normal_scale_ms",
                   "roughness_m": "roughness_m", "ground_friction_angle_deg": "ground_friction_deg"}


def _material_path(scenario, path: str, where: str):
    name, _, fld = path.partition(".")
    names = [m.name for m in scenario.materials]
    if name not in names:
        raise MeasureError(f"{where}: {path!r}: no material {name!r} in scenario {scenario.name!r} "
                           f"({', '.join(names)})")
    if fld not in MATERIAL_FIELDS:
        raise MeasureError(f"{where}: {path!r}: {fld!r} is not one of {', '.join(MATERIAL_FIELDS)}")
    from simulation.contact import ET_FRICTION
    if fld == "tangential.normal_scale_ms" and scenario.materials[names.index(name)].et_law == ET_FRICTION:
        raise MeasureError(f"{where}: {path!r}: material {name!r} uses Stronge's 'friction' law, which the "
                           "Pfeiffer & Bowen scale does not act on (it scales the 'constant' and 'coulomb' laws)")
    return names.index(name), MATERIAL_FIELDS[fld]


def material_value(scenario, path: str, where: str = "materials"):
    """Current value of a material parameter "material.field" (e.g. "talus.ground_friction_angle_deg").

    Parameters
    ----------
    scenario : simulation.scenario.Scenario
        The slope scenario.
    path : str
        ``"material.field"``, the field one of :data:`MATERIAL_FIELDS`.
    where : str, optional
        What to name in error messages (file and option).

    Returns
    -------
    float
        The value, in the field's units (restitution [-], angles [deg], roughness [m]).

    Raises
    ------
    MeasureError
        When the material or field is unknown.
    """
    i, attr = _material_path(scenario, path, where)
    return float(getattr(scenario.materials[i], attr))


def scenario_with_materials(scenario, values: dict, where: str = "materials"):
    """A copy of ``scenario`` with material parameters {"material.field": value} replaced.

    Parameters
    ----------
    scenario : simulation.scenario.Scenario
        The slope scenario.
    values : dict
        ``"material.field"`` -> new value (the field's units: restitution [-], angles [deg], roughness [m]).
    where : str, optional
        What to name in error messages (file and option).

    Returns
    -------
    simulation.scenario.Scenario
        The new scenario.

    Raises
    ------
    MeasureError
        When a material or field is unknown.
    """
    mats = list(scenario.materials)
    for path, v in values.items():
        i, attr = _material_path(scenario, path, where)
        if attr == "et_normal_scale_ms" and not float(v) > 0.0:
            raise MeasureError(f"{where}: {path!r} = {v!r}: the Pfeiffer & Bowen scale must be > 0 m/s")
        mats[i] = replace(mats[i], **{attr: float(v)})
    return replace(scenario, materials=tuple(mats))


def effective_samples(result, collector: str):
    """Effective speeds [m/s] (rotation included: v^2 + k (w r)^2) and bounce heights [m] of the first
    crossings of ``collector``.

    Parameters
    ----------
    result : simulation.SimulationResult
        A simulated run.
    collector : str
        Name of the collector.

    Returns
    -------
    speed : numpy.ndarray
        Effective speed of each first crossing [m/s].
    height : numpy.ndarray
        Bounce height of each first crossing [m].
    """
    df = result.collector(collector, first_only=True)
    return effective_speeds(df), df["height_m"].to_numpy()
