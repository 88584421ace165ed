"""The generated rock cut of a corridor section: profile, materials, seeder and collectors as a scenario dict.

A section that names no scenario file is simulated on a cut built from its geometry columns
(:func:`cut_scenario_dict`): crest, face (optionally with a catch bench), ditch, shoulder, road and verge.
x increases towards the road, z up, metres; masses kg, density kg/m3.
"""
from __future__ import annotations

import math

from ...core.units import DEFAULT_DENSITY_KG_M3

#: Crest plateau [m] behind the cut and verge [m] beyond the road of a generated profile (room for
#: the seeder and for blocks crossing the road to come to rest).
CREST_M = 5.0
VERGE_M = 10.0


def cut_scenario_dict(materials: dict, settings: dict, *, cut_height_m, face_angle_deg, ditch_width_m, ditch_depth_m,
                      runout_to_road_m, road_width_m, face_material, ditch_material, road_material, seeder_mass,
                      release_zone_share=0.3, density_kg_m3=DEFAULT_DENSITY_KG_M3, name="cut", bench_width_m=0.0,
                      bench_height_m=0.0) -> dict:
    """Scenario dictionary of a generated rock cut (x increases towards the road, z up, metres).

    crest plateau (CREST_M) -> rock face of ``cut_height_m`` at ``face_angle_deg`` -> ditch of
    ``ditch_width_m`` x ``ditch_depth_m`` at the toe (walls 0.25H:1V on the face side and 1H:1V on the road
    side, as :mod:`riskrf.risk.measures`) -> flat shoulder ``runout_to_road_m`` -> road ``road_width_m`` -> verge.
    With ``bench_width_m`` > 0 the face is interrupted at ``bench_height_m`` above the toe by a horizontal catch
    bench of that width (surface of ``ditch_material``: debris collects on it as in a ditch), both faces at
    ``face_angle_deg``.  Blocks are released from the upper ``release_zone_share`` of the (upper) face.
    Collectors: ``barrier`` at the middle of the shoulder (at the ditch's outer rim without a shoulder), ``road``
    0.01 m onto the road.

    Parameters
    ----------
    materials : dict
        Scenario materials table (name -> material).
    settings : dict
        Scenario settings (time step, stop criteria, ...).
    cut_height_m : float
        Height of the rock face [m].
    face_angle_deg : float
        Angle of the face [deg].
    ditch_width_m, ditch_depth_m : float
        Width and depth of the ditch at the toe [m].
    runout_to_road_m : float
        Width of the flat shoulder between the ditch and the road [m].
    road_width_m : float
        Width of the road [m].
    face_material, ditch_material, road_material : str
        Names of the materials of the face, the ditch (and bench) and the road.
    seeder_mass : dict
        The seeder's ``mass_kg`` distribution [kg].
    release_zone_share : float, optional
        Upper share of the face from which blocks are released [-].
    density_kg_m3 : float, optional
        Rock density [kg/m3].
    name : str, optional
        Scenario name.
    bench_width_m : float, optional
        Width of a catch bench [m] (0: none).
    bench_height_m : float, optional
        Height of the bench above the toe [m].

    Returns
    -------
    dict
        Scenario dictionary for :func:`simulation.scenario_from_dict`.
    """
    from ...risk.measures import DITCH_INNER_SLOPE_HV, DITCH_OUTER_SLOPE_HV
    h, ang = float(cut_height_m), math.radians(float(face_angle_deg))
    wb, hb = float(bench_width_m), float(bench_height_m)
    if wb > 0 and not 0 < hb < h:
        raise ValueError(f"bench_height_m = {hb:g} must lie strictly between 0 and cut_height_m = {h:g}")
    if wb > 0:
        x_upper = CREST_M + (h - hb) / math.tan(ang)
        x_toe = x_upper + wb + hb / math.tan(ang)
        xs, zs = [0.0, CREST_M, x_upper, x_upper + wb, x_toe], [h, h, hb, hb, 0.0]
        mats = [face_material, face_material, ditch_material, face_material]
    else:
        x_toe = x_upper = CREST_M + h / math.tan(ang)
        xs, zs, mats = [0.0, CREST_M, x_toe], [h, h, 0.0], [face_material, face_material]
    w, d = float(ditch_width_m), float(ditch_depth_m)
    if w > 0 and d > 0:
        a, c = DITCH_INNER_SLOPE_HV * d, DITCH_OUTER_SLOPE_HV * d
        xs += [x_toe + a, x_toe + w - c, x_toe + w]
        zs += [-d, -d, 0.0]
        mats += [face_material, ditch_material, ditch_material]
    elif w > 0:
        xs.append(x_toe + w)
        zs.append(0.0)
        mats.append(ditch_material)
    x_rim = xs[-1]
    r = float(runout_to_road_m)
    if r > 0:
        xs.append(x_rim + r)
        zs.append(0.0)
        mats.append(ditch_material)
    x_road = xs[-1]
    xs += [x_road + float(road_width_m), x_road + float(road_width_m) + VERGE_M]
    zs += [0.0, 0.0]
    mats += [road_material, ditch_material]
    barrier_x = x_rim + r / 2 if r > 0 else x_rim + 0.005
    face_top = CREST_M + 0.02 * (x_upper - CREST_M)
    face_low = CREST_M + float(release_zone_share) * (x_upper - CREST_M)
    return {"name": name, "description": "generated rock cut (riskrf.app.corridor)",
            "profile": {"x": xs, "z": zs, "materials": mats}, "materials": materials,
            "seeder": {"type": "line", "x": [face_top, face_low], "height_m": 0.5, "mass_kg": seeder_mass,
                       "density_kg_m3": density_kg_m3, "vx_ms": {"dist": "uniform", "low": 0.2, "high": 1.0}},
            "collectors": [{"name": "barrier", "x": barrier_x}, {"name": "road", "x": x_road + 0.01}],
            "settings": settings}
