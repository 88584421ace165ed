"""Measures that change the slope itself: catch bench, bund (embankment) and drape, re-simulated like a ditch.

Each returns a copy of the scenario with a changed profile or surface; the mitigation study derives its effect
(the share of the falls that would reach the road that it stops, by block mass) by re-simulating the scenario
with common random numbers, exactly as for a ditch (:mod:`riskrf.risk.measures`).  Lengths in m.

* **catch bench** (``x_m``, ``width_m``): a flat bench cut into the slope at the elevation of the ground at
  ``x_m + width_m``; its back wall rises ``inner_slope_hv`` m horizontally per m (default 0.25H:1V) to the ground
  at ``x_m``.  Floor material: ``material`` (default: that of the ground under the bench).
* **bund / embankment** (``x_m``, ``width_m``, ``height_m``): a mound on the ground from ``x_m`` to ``x_m +
  width_m``, its crest ``height_m`` above the ground, its upslope face ``inner_slope_hv`` (default 0.5H:1V, a
  reinforced face) and its downslope face ``outer_slope_hv`` (default 1.5H:1V); material ``material`` (default:
  the ground's).
* **drape** (``zone_x_m`` = [x_lo, x_hi] on the rock face): the option (:class:`riskrf.risk.options.slope.Drape`) is
  NOT re-simulated with a changed surface.  What the simulation can tell is which of the falls reaching the road
  start under the mesh (their release point in the zone, :func:`drape_release_share`); a drape keeps a share of
  those on the face (its containment efficiency, an ASSUMPTION) and does nothing for falls from above or beside
  it (Badger & Duffy 2012: unsecured drapery addresses rockfall that originates from the covered slope area;
  a hybrid drapery or attenuator intercepts falls from upslope).  The zone must lie on the face
  (:func:`check_drape_zone`: every profile segment under it steeper than :data:`DRAPE_MIN_FACE_DIP_DEG`).
  :func:`drape_scenario` (the surface under the mesh given the ASSUMED material :data:`DRAPE_MATERIAL`) is kept
  for what-if runs from Python; its result rests wholly on that assumed material and it is not an option's
  effect.

References
----------
Badger, T. C. & Duffy, J. D. (2012).  Drapery systems.  In Turner, A. K. & Schuster, R. L. (eds), *Rockfall:
Characterization and Control*, chapter 16.  Transportation Research Board, Washington DC.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .measures import Ditch, MeasureError, ditch_profile, ground_z

#: Drape / secured mesh as a slope material (ASSUMED): restitution e_N 0.1 +- 0.03, Coulomb friction 40 deg at
#: impacts, no roughness, sliding contact with a 45-degree friction angle (the mesh presses the block on the face).
DRAPE_MATERIAL = {"normal_restitution": {"law": "constant", "mean": 0.1, "std": 0.03},
                  "tangential": {"law": "friction", "friction_angle_deg": 40.0}, "roughness_m": 0.0,
                  "ground_motion": "slide", "ground_friction_angle_deg": 45.0}
#: A drape hangs on a rock face: every profile segment under its zone must dip more steeply than this [deg]
#: (riskrf's rule; ground flatter than about 40 degrees is talus or an apron, where a mesh does not hang).
DRAPE_MIN_FACE_DIP_DEG = 40.0
BENCH_INNER_SLOPE_HV = 0.25
BUND_INNER_SLOPE_HV = 0.5
BUND_OUTER_SLOPE_HV = 1.5


@dataclass(frozen=True)
class SlopeMeasure:
    """One bench, bund or drape: ``kind`` and its geometry [m] (see the module docstring)."""

    kind: str
    option: str
    x_m: float | None = None
    width_m: float | None = None
    height_m: float | None = None
    zone_x_m: tuple | None = None
    inner_slope_hv: float | None = None
    outer_slope_hv: float | None = None
    material: str | None = None

    @property
    def span(self) -> tuple:
        """(start, end) along x [m]."""
        if self.kind == "drape":
            return float(self.zone_x_m[0]), float(self.zone_x_m[1])
        return float(self.x_m), float(self.x_m) + float(self.width_m)


def _segment(profile, x) -> int:
    return int(np.clip(np.searchsorted(profile.x, x, side="right") - 1, 0, profile.material_index.size - 1))


def _check_inside_closed(profile, x0, x1, where):
    if not (profile.x[0] <= x0 < x1 <= profile.x[-1]):
        raise MeasureError(f"{where} spans {x0:g}-{x1:g} m, outside the profile ({profile.x[0]:g}, "
                           f"{profile.x[-1]:g}) m")


def _check_inside(profile, x0, x1, where):
    if not (profile.x[0] < x0 < x1 < profile.x[-1]):
        raise MeasureError(f"{where}: spans {x0:g}-{x1:g} m, outside the profile ({profile.x[0]:g}, "
                           f"{profile.x[-1]:g}) m or empty")


def bench_profile(profile, x_m, width_m, *, inner_slope_hv=BENCH_INNER_SLOPE_HV, material=None, where="bench"):
    """A copy of ``profile`` with a catch bench cut from ``x_m`` to ``x_m + width_m`` (see the module docstring).

    Parameters
    ----------
    profile : simulation.slope.Profile
        The slope profile.
    x_m : float
        Upslope edge of the bench [m].
    width_m : float
        Width of the bench along x [m].
    inner_slope_hv : float, optional
        Back wall, horizontal run per unit drop [m/m].
    material : int, optional
        Material index of the new surface; the neighbouring ground's by default.
    where : str, optional
        What to name in error messages.

    Returns
    -------
    simulation.slope.Profile
        The new profile.

    Raises
    ------
    MeasureError
        When the measure leaves the profile or does not fit the ground.
    """
    from simulation.slope import Profile
    x0, x1 = float(x_m), float(x_m) + float(width_m)
    _check_inside(profile, x0, x1, where)
    z0, z1 = float(ground_z(profile, x0)), float(ground_z(profile, x1))
    if z0 <= z1:
        raise MeasureError(f"{where}: the ground at x = {x0:g} m ({z0:g} m) is not above the ground at x = {x1:g} m "
                           f"({z1:g} m): a bench is cut into a slope falling towards the road")
    a = inner_slope_hv * (z0 - z1)
    if a >= x1 - x0:
        raise MeasureError(f"{where}: width_m = {x1 - x0:g} m is too narrow for a back wall of {inner_slope_hv:g}H:1V "
                           f"over {z0 - z1:.3g} m (needs more than {a:.3g} m)")
    seg0, seg1 = _segment(profile, x0), _segment(profile, x1)
    floor = profile.material_index[seg1] if material is None else int(material)
    lo, hi = profile.x < x0, profile.x > x1
    xs = np.concatenate([profile.x[lo], [x0, x0 + a, x1], profile.x[hi]])
    zs = np.concatenate([profile.z[lo], [z0, z1, z1], profile.z[hi]])
    mats = np.concatenate([profile.material_index[:int(lo.sum())], [profile.material_index[seg0], floor],
                           profile.material_index[profile.material_index.size - int(hi.sum()):]])
    return Profile.build(xs, zs, mats, profile.material_names, source=where)


def bund_profile(profile, x_m, width_m, height_m, *, inner_slope_hv=BUND_INNER_SLOPE_HV,
                 outer_slope_hv=BUND_OUTER_SLOPE_HV, material=None, where="bund"):
    """A copy of ``profile`` with a bund of crest ``height_m`` above the ground between ``x_m`` and ``x_m +
    width_m`` (see the module docstring).

    Parameters
    ----------
    profile : simulation.slope.Profile
        The slope profile.
    x_m : float
        Upslope toe of the bund [m].
    width_m : float
        Base width of the bund along x [m].
    height_m : float
        Crest height above the ground [m], > 0.
    inner_slope_hv, outer_slope_hv : float, optional
        Slope-side and road-side faces, horizontal run per unit rise [m/m].
    material : int, optional
        Material index of the new surface; the neighbouring ground's by default.
    where : str, optional
        What to name in error messages.

    Returns
    -------
    simulation.slope.Profile
        The new profile.

    Raises
    ------
    MeasureError
        When the measure leaves the profile or does not fit the ground.
    """
    from simulation.slope import Profile
    x0, x1, h = float(x_m), float(x_m) + float(width_m), float(height_m)
    _check_inside(profile, x0, x1, where)
    if h <= 0:
        raise MeasureError(f"{where}: height_m = {h:g} must be > 0 m")
    a, c = inner_slope_hv * h, outer_slope_hv * h
    if a + c >= x1 - x0:
        raise MeasureError(f"{where}: width_m = {x1 - x0:g} m is too narrow for a {h:g} m bund with faces of "
                           f"{inner_slope_hv:g}H:1V and {outer_slope_hv:g}H:1V (needs more than {a + c:.3g} m)")
    z0, z1 = float(ground_z(profile, x0)), float(ground_z(profile, x1))
    xa, xc = x0 + a, x1 - c
    za, zc = float(ground_z(profile, xa)) + h, float(ground_z(profile, xc)) + h
    seg0 = _segment(profile, x0)
    fill = profile.material_index[seg0] if material is None else int(material)
    lo, hi = profile.x < x0, profile.x > x1
    xs = np.concatenate([profile.x[lo], [x0, xa, xc, x1], profile.x[hi]])
    zs = np.concatenate([profile.z[lo], [z0, za, zc, z1], profile.z[hi]])
    mats = np.concatenate([profile.material_index[:int(lo.sum())], [fill, fill, fill],
                           profile.material_index[profile.material_index.size - int(hi.sum()):]])
    return Profile.build(xs, zs, mats, profile.material_names, source=where)


def drape_scenario(scenario, zone_x_m, where="drape"):
    """A copy of ``scenario`` whose surface between ``zone_x_m`` takes the drape material (added once).

    Parameters
    ----------
    scenario : simulation.scenario.Scenario
        The slope scenario.
    zone_x_m : tuple of float
        (x_lo, x_hi) of the draped zone [m].
    where : str, optional
        What to name in error messages.

    Returns
    -------
    simulation.scenario.Scenario
        The new scenario, with the material ``drape`` (:data:`DRAPE_MATERIAL`, an ASSUMPTION).

    Raises
    ------
    MeasureError
        When the zone leaves the profile.
    """
    from simulation.scenario import Material
    from simulation.slope import Profile
    prof = scenario.profile
    x0, x1 = float(zone_x_m[0]), float(zone_x_m[1])
    _check_inside(prof, x0, x1, where)
    names = list(prof.material_names)
    mats = list(scenario.materials)
    if "drape" not in names:
        names.append("drape")
        mats.append(Material.parse("drape", DRAPE_MATERIAL, where))
    k = names.index("drape")
    inner = prof.x[(prof.x > x0) & (prof.x < x1)]
    xs = np.concatenate([prof.x[prof.x < x0], [x0], inner, [x1], prof.x[prof.x > x1]])
    zs = np.interp(xs, prof.x, prof.z)
    mid = 0.5 * (xs[:-1] + xs[1:])
    mi = np.array([k if x0 <= m <= x1 else prof.material_index[_segment(prof, m)] for m in mid], dtype=np.int64)
    profile = Profile.build(xs, zs, mi, tuple(names), source=where)
    return replace(scenario, profile=profile, materials=tuple(mats))


def face_spans(profile, min_dip_deg: float = DRAPE_MIN_FACE_DIP_DEG) -> list:
    """The rock faces of ``profile``: runs of consecutive segments dipping more steeply than ``min_dip_deg``.

    Parameters
    ----------
    profile : simulation.slope.Profile
        The slope profile (x, z in m).
    min_dip_deg : float, optional
        Smallest dip of a face segment [deg].

    Returns
    -------
    list of tuple
        (x_start, x_end) of each face [m], upslope first; empty when the profile has no face.
    """
    x, z = np.asarray(profile.x, dtype=float), np.asarray(profile.z, dtype=float)
    dip = np.degrees(np.arctan2(np.abs(np.diff(z)), np.diff(x)))
    spans = []
    for i, steep in enumerate(dip > min_dip_deg):
        if not steep:
            continue
        if spans and spans[-1][1] == x[i]:
            spans[-1] = (spans[-1][0], float(x[i + 1]))
        else:
            spans.append((float(x[i]), float(x[i + 1])))
    return spans


def check_drape_zone(scenario, zone_x_m, where: str = "drape") -> float:
    """Check that a drape's zone lies inside the profile, on a rock face, over part of the release zone; the share
    of the release line under it.

    Parameters
    ----------
    scenario : simulation.scenario.Scenario
        The slope scenario (2-D profile and line seeder).
    zone_x_m : tuple of float
        (x_lo, x_hi) of the draped zone [m].
    where : str, optional
        What to name in error messages (file, option and field).

    Returns
    -------
    float
        Share of the releases whose release point lies under the mesh [-]
        (:func:`riskrf.risk.measures.seeder_share`).

    Raises
    ------
    MeasureError
        When the zone is empty or leaves the profile, the scenario has no face (no segment steeper than
        :data:`DRAPE_MIN_FACE_DIP_DEG`), part of the zone lies on flatter ground, or no block is released under it.
    """
    from .measures import seeder_share
    prof = scenario.profile
    x0, x1 = float(zone_x_m[0]), float(zone_x_m[1])
    if not x1 > x0:
        raise MeasureError(f"{where}: zone_x_m = {list(zone_x_m)} must be [low, high] with low < high")
    _check_inside_closed(prof, x0, x1, f"{where}: zone_x_m")
    faces = face_spans(prof)
    if not faces:
        raise MeasureError(f"{where}: zone_x_m = [{x0:g}, {x1:g}]: scenario {scenario.name!r} has no rock face to "
                           f"drape (no profile segment steeper than {DRAPE_MIN_FACE_DIP_DEG:g} deg); a drape "
                           "hangs on a face")
    if not any(a <= x0 and x1 <= b for a, b in faces):
        where_faces = ", ".join(f"{a:g}-{b:g} m" for a, b in faces)
        raise MeasureError(f"{where}: zone_x_m = [{x0:g}, {x1:g}] is not on a rock face: a drape hangs on a face "
                           f"(segments steeper than {DRAPE_MIN_FACE_DIP_DEG:g} deg), and the faces of scenario "
                           f"{scenario.name!r} span x = {where_faces}")
    sd = scenario.seeder
    share = 0.0 if (x1 < sd.x_low or x0 > sd.x_high) else seeder_share(scenario, (x0, x1), where)
    if share <= 0:
        raise MeasureError(f"{where}: zone_x_m = [{x0:g}, {x1:g}]: no block is released under the mesh (release "
                           f"zone {sd.x_low:g}-{sd.x_high:g} m); a drape contains the falls that start under it")
    return share


def drape_release_share(result, road_blocks, zone_x_m, max_mass_kg=None) -> tuple:
    """Of the simulated blocks reaching the road, those released under the mesh and small enough for it.

    Parameters
    ----------
    result : simulation.SimulationResult
        A simulation of the unmitigated slope (release points ``blocks["x"]`` [m], masses ``blocks["mass"]`` [kg]).
    road_blocks : numpy.ndarray of int
        Indices of the blocks that cross the road line.
    zone_x_m : tuple of float
        (x_lo, x_hi) of the draped zone [m].
    max_mass_kg : float, optional
        Largest block the mesh contains [kg]; heavier blocks are not credited.  None: every block.

    Returns
    -------
    share : float
        Share of the road blocks released under the mesh (and not heavier than ``max_mass_kg``) [-].
    beta : tuple
        (a, b) of its Monte Carlo Beta law (Jeffreys prior: k + 0.5, n - k + 0.5).
    under : numpy.ndarray of bool
        Per road block, released under the mesh and containable.
    """
    x0 = np.asarray(result.blocks["x"], dtype=float)[road_blocks]
    m = np.asarray(result.blocks["mass"], dtype=float)[road_blocks]
    under = (x0 >= zone_x_m[0]) & (x0 <= zone_x_m[1])
    if max_mass_kg is not None:
        under &= m <= max_mass_kg
    n, k = int(road_blocks.size), int(under.sum())
    if n == 0:
        return 0.0, (0.5, 0.5), under
    return k / n, (k + 0.5, n - k + 0.5), under


def scenario_with_measures(scenario, measures, where: str = "measures", road_collector: str | None = "road"):
    """A copy of ``scenario`` carrying every ditch (:class:`~riskrf.risk.measures.Ditch`) and slope measure
    (:class:`SlopeMeasure`) of ``measures``; spans must not overlap and must not cross the road line.

    Parameters
    ----------
    scenario : simulation.scenario.Scenario
        The slope scenario.
    measures : iterable
        Ditches and :class:`SlopeMeasure` objects (lengths [m]).
    where : str, optional
        What to name in error messages.
    road_collector : str or None, optional
        Name of the road collector no measure may cover.

    Returns
    -------
    simulation.scenario.Scenario
        The new scenario (named ``<name>+measures``).

    Raises
    ------
    MeasureError
        When measures overlap, a material is unknown, a measure covers the road line or does not fit the ground.
    """
    ms = sorted(measures, key=lambda m: m.span[0])
    for a, b in zip(ms[:-1], ms[1:]):
        if b.span[0] < a.span[1]:
            raise MeasureError(f"{where}: options {a.option!r} ({a.span[0]:g}-{a.span[1]:g} m) and {b.option!r} "
                               f"({b.span[0]:g}-{b.span[1]:g} m) overlap")
    sc = scenario
    for m in ms:
        w = f"{where}: option {m.option!r}"
        names = list(sc.profile.material_names)
        mat = None
        if m.material is not None:
            if m.material not in names:
                raise MeasureError(f"{w}: material = {m.material!r} is not a material of scenario {scenario.name!r} "
                                   f"({', '.join(names)})")
            mat = names.index(m.material)
        for c in sc.collectors:
            if c.name == road_collector and m.span[0] <= c.x <= m.span[1]:
                raise MeasureError(f"{w}: it ({m.span[0]:g}-{m.span[1]:g} m) would cover the road line (collector "
                                   f"{c.name!r} at x = {c.x:g} m)")
        if isinstance(m, Ditch):
            kw = {"inner_slope_hv": m.inner_slope_hv, "outer_slope_hv": m.outer_slope_hv}
            sc = replace(sc, profile=ditch_profile(sc.profile, m.x_m, m.width_m, m.depth_m, material=mat, where=w,
                                                   **kw))
        elif m.kind == "bench":
            sc = replace(sc, profile=bench_profile(sc.profile, m.x_m, m.width_m, material=mat, where=w,
                                                   inner_slope_hv=m.inner_slope_hv or BENCH_INNER_SLOPE_HV))
        elif m.kind == "bund":
            sc = replace(sc, profile=bund_profile(sc.profile, m.x_m, m.width_m, m.height_m, material=mat, where=w,
                                                  inner_slope_hv=m.inner_slope_hv or BUND_INNER_SLOPE_HV,
                                                  outer_slope_hv=m.outer_slope_hv or BUND_OUTER_SLOPE_HV))
        elif m.kind == "drape":
            sc = drape_scenario(sc, m.zone_x_m, where=w)
        else:
            raise MeasureError(f"{w}: kind {m.kind!r} is not a slope measure")
    return replace(sc, name=scenario.name + "+measures")


__all__ = ["DRAPE_MATERIAL", "DRAPE_MIN_FACE_DIP_DEG", "SlopeMeasure", "bench_profile", "bund_profile",
           "check_drape_zone", "drape_release_share", "drape_scenario", "face_spans", "scenario_with_measures"]
