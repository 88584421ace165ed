"""One row of a corridor's sections table read and checked: values, rate, scenario, RHRS rating, the Section.

:func:`_read_section_row` builds a :class:`~riskrf.app.corridor.model.Section` from one row against the
corridor-wide inputs (:class:`_RowContext`); the cross-row checks (overlapping chainage, ids sharing a seed)
and the sharing of a corridor-wide rate run once all rows are read.  Every error names the file, the row,
the section id, the column and the value.  Chainage m, rates per year.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from ...core.units import M_PER_KM
from ...risk import rhrs
from .cut import cut_scenario_dict
from .model import (
    _RHRS_SOURCE_COLUMNS,
    ALL_COLUMNS,
    BENCH_COLUMNS,
    GEOMETRY_COLUMNS,
    MAX_SECTION_FALLS_PER_YEAR,
    NUMBER_COLUMNS,
    RATE_COLUMNS,
    RHRS_COLUMNS,
    CorridorError,
    Section,
    _section_key,
)
from .rates import _face_area, inventory_rate


@dataclass
class _RowContext:
    """What every row of a sections table is checked against (corridor-wide inputs and running state).

    ``inv_cache`` (rate and note per inventory file) and ``fallback`` (corridor-wide fallbacks that at least one
    section used) are filled as the rows are read.
    """

    path: Path
    columns: object
    defaults: dict
    scale: float
    unit: str
    shared: object
    m_min_kg: float
    materials: dict
    settings: dict
    template_path: Path
    default_seeder: dict
    option_names: list
    exposure: object
    variant: str
    rhrs_cap: float | None
    centreline: object
    inv_cache: dict = field(default_factory=dict)
    fallback: set = field(default_factory=set)


def _row_values(ctx: _RowContext, raw, where: str) -> tuple[dict, dict]:
    """A row's cells with ``[defaults]`` filled in, and its numbers checked.

    Parameters
    ----------
    ctx : _RowContext
        The corridor-wide inputs.
    raw : pandas.Series
        The row, as text.
    where : str
        File, row and section id for messages.

    Returns
    -------
    vals : dict
        Every column of :data:`ALL_COLUMNS`: the cell, else the default, else ``""``.
    num : dict
        The non-empty number columns as float (an RHRS class name stays text).
    """
    vals = {}
    for c in ALL_COLUMNS:
        v = str(raw[c]).strip() if c in ctx.columns else ""
        if v == "" and c in ctx.defaults:
            v = ctx.defaults[c]
        vals[c] = v
    num = {}
    for c in NUMBER_COLUMNS + RHRS_COLUMNS:
        v = vals[c]
        if v == "" or v is None:
            continue
        if isinstance(v, bool):
            raise CorridorError(f"{where}: column {c!r} = {v!r} must be a number, not true/false")
        if isinstance(v, (int, float)):
            num[c] = float(v)
            continue
        try:
            num[c] = float(v)
        except (TypeError, ValueError):
            if c in RHRS_COLUMNS and c.removeprefix("rhrs_") in rhrs.CLASSES:
                num[c] = v          # a class name
                continue
            raise CorridorError(f"{where}: column {c!r} = {v!r} is not a number") from None
        if not math.isfinite(num[c]):
            raise CorridorError(f"{where}: column {c!r} = {v!r} must be finite")
    return vals, num


def _row_rate(ctx: _RowContext, vals: dict, num: dict, c0: float, c1: float, where: str):
    """A section's rate of falls [1/yr] from its own column or inventory, or its weight in the shared rate.

    Parameters
    ----------
    ctx : _RowContext
        The corridor-wide inputs (``inv_cache`` is filled).
    vals, num : dict
        The row's cells and numbers (:func:`_row_values`).
    c0, c1 : float
        The section's chainage [m].
    where : str
        File, row and section id for messages.

    Returns
    -------
    rate : float
        Falls per year (NaN for a share of the corridor-wide ``[rates]`` inventory, set once all rows are read).
    rate_source : str
        The column that gave the rate, the inventory's note, or ``"shared"``.
    weight : float or None
        The section's weight in the shared rate (km of road or m2 of face); None for its own rate.
    """
    given_rates = [c for c in RATE_COLUMNS if c in num] + (["inventory"] if vals["inventory"] else [])
    if len(given_rates) > 1 or (not given_rates and ctx.shared is None):
        raise CorridorError(f"{where}: give exactly one of falls_per_year, falls_per_km_year, "
                            f"falls_per_m2_year or inventory (own rate or inventory, or a corridor rate per km "
                            f"of road or per m2 of rock face; or a corridor-wide [rates] inventory); got "
                            f"{given_rates or 'none'}")
    rate_source = given_rates[0] if given_rates else "shared"
    weight = None
    if "falls_per_year" in num:
        rate = num["falls_per_year"]
    elif "falls_per_km_year" in num:
        rate = num["falls_per_km_year"] * (c1 - c0) / M_PER_KM
    elif "falls_per_m2_year" in num:
        rate = num["falls_per_m2_year"] * _face_area(num, c1 - c0, where, "falls_per_m2_year")
    elif vals["inventory"]:
        inv_path = (ctx.path.parent / str(vals["inventory"])).resolve()
        if inv_path not in ctx.inv_cache:
            ctx.inv_cache[inv_path] = inventory_rate(inv_path, ctx.m_min_kg,
                                                     f"{where}: column 'inventory' = {vals['inventory']!r}")
        rate, rate_source = ctx.inv_cache[inv_path]
    else:                                  # a share of the corridor-wide inventory, set once all rows are read
        weight = _face_area(num, c1 - c0, where, "rates.share = 'm2'") if ctx.shared.share == "m2" \
            else (c1 - c0) / M_PER_KM
        rate = math.nan
    if rate_source != "shared" and not rate > 0:
        raise CorridorError(f"{where}: the section's rate of falls is {rate:g} per year; a section without "
                            "falls needs no assessment (remove it or give a rate > 0)")
    if rate_source != "shared" and rate > MAX_SECTION_FALLS_PER_YEAR:
        raise CorridorError(f"{where}: column {rate_source!r} gives {rate:,.4g} falls a year on this section, "
                            f"more than {MAX_SECTION_FALLS_PER_YEAR:,.0f} "
                            f"({MAX_SECTION_FALLS_PER_YEAR / 365.25:.0f} a day): a slope that active closes "
                            "its road rather than being screened; check the value and its unit (per year, "
                            "per km of road, per m2 of face)")
    return rate, rate_source, weight


def _row_scenario(ctx: _RowContext, vals: dict, num: dict, sid: str, where: str):
    """A section's scenario: its own scenario file, or a cut generated from its geometry columns.

    Parameters
    ----------
    ctx : _RowContext
        The corridor-wide inputs (``fallback`` is updated when the default seeder mass is used).
    vals, num : dict
        The row's cells and numbers (:func:`_row_values`).
    sid : str
        The section id.
    where : str
        File, row and section id for messages.

    Returns
    -------
    scenario : simulation.Scenario
        The checked scenario, with collectors ``barrier`` and ``road``.
    geometry : str
        A one-line description of the geometry for the outputs.
    """
    import simulation
    from simulation.scenario import ScenarioError, scenario_from_dict

    if vals["scenario"]:
        sp = (ctx.path.parent / str(vals["scenario"])).resolve()
        if not sp.exists():
            raise CorridorError(f"{where}: column 'scenario' = {vals['scenario']!r}: file not found ({sp})")
        sc = simulation.load_scenario(sp)
        for cname in ("barrier", "road"):
            if cname not in [c.name for c in sc.collectors]:
                raise CorridorError(f"{where}: scenario {sp.name} needs collectors named 'barrier' and 'road'")
        return sc, f"scenario {sp.name}"
    missing = [c for c in GEOMETRY_COLUMNS if c not in num]
    if missing:
        raise CorridorError(f"{where}: columns {missing} are empty (a generated cut needs "
                            f"{list(GEOMETRY_COLUMNS)}, or give a scenario file)")
    g = {c: num[c] for c in GEOMETRY_COLUMNS}
    if not 1 <= g["cut_height_m"] <= 500:
        raise CorridorError(f"{where}: column 'cut_height_m' = {g['cut_height_m']:g} must lie in [1, 500] m")
    if not 20 <= g["face_angle_deg"] <= 89:
        raise CorridorError(f"{where}: column 'face_angle_deg' = {g['face_angle_deg']:g} must lie in "
                            "[20, 89] degrees (vertical faces are not supported)")
    for c in ("ditch_width_m", "ditch_depth_m", "runout_to_road_m"):
        if g[c] < 0:
            raise CorridorError(f"{where}: column {c!r} = {g[c]:g} must be >= 0")
    if g["road_width_m"] <= 0:
        raise CorridorError(f"{where}: column 'road_width_m' = {g['road_width_m']:g} must be > 0")
    if g["ditch_depth_m"] > 0 and g["ditch_width_m"] <= 1.25 * g["ditch_depth_m"]:
        raise CorridorError(f"{where}: column 'ditch_width_m' = {g['ditch_width_m']:g} is too narrow for "
                            f"ditch_depth_m = {g['ditch_depth_m']:g} (walls 0.25H:1V and 1H:1V need more "
                            f"than {1.25 * g['ditch_depth_m']:g} m)")
    bench = {c: num.get(c, 0.0) for c in BENCH_COLUMNS}
    if bench["bench_width_m"] < 0:
        raise CorridorError(f"{where}: column 'bench_width_m' = {bench['bench_width_m']:g} must be >= 0")
    if bench["bench_width_m"] > 0 and not 0 < bench["bench_height_m"] < g["cut_height_m"]:
        raise CorridorError(f"{where}: column 'bench_height_m' = {bench['bench_height_m']:g} must lie "
                            f"strictly between 0 and cut_height_m = {g['cut_height_m']:g} (a bench "
                            f"{bench['bench_width_m']:g} m wide is given)")
    share = num.get("release_zone_share", 0.3)
    if not 0 < share <= 1:
        raise CorridorError(f"{where}: column 'release_zone_share' = {share:g} must lie in (0, 1]")
    mats = {c: str(vals[c] or d) for c, d in (("face_material", "bedrock"), ("ditch_material", "soil"),
                                             ("road_material", "asphalt"))}
    for c, m in mats.items():
        if m not in ctx.materials:
            raise CorridorError(f"{where}: column {c!r} = {m!r} is not a material of {ctx.template_path.name} "
                                f"({', '.join(ctx.materials)})")
    seeder_mass = ctx.defaults.get("seeder_mass_kg", ctx.default_seeder)
    if "seeder_mass_kg" not in ctx.defaults:
        ctx.fallback.add("seeder_mass_kg")
    try:
        sc = scenario_from_dict(cut_scenario_dict(ctx.materials, ctx.settings, **g, **mats, **bench,
                                                  seeder_mass=seeder_mass, release_zone_share=share,
                                                  name=f"section {sid}"), source=where)
    except ScenarioError as exc:
        raise CorridorError(str(exc)) from exc
    geometry = (f"generated cut {g['cut_height_m']:g} m at {g['face_angle_deg']:g} deg, ditch "
                f"{g['ditch_width_m']:g} x {g['ditch_depth_m']:g} m, {g['runout_to_road_m']:g} m to a "
                f"{g['road_width_m']:g} m road"
                + (f", bench {bench['bench_width_m']:g} m wide at {bench['bench_height_m']:g} m"
                   if bench["bench_width_m"] > 0 else ""))
    return sc, geometry


def _row_rating(ctx: _RowContext, num: dict, c0: float, c1: float, vpd: float, speed: float, where: str):
    """A section's RHRS rating from its ``rhrs_*`` columns (and what its other columns already say).

    Parameters
    ----------
    ctx : _RowContext
        The corridor-wide inputs (RHRS variant and cap).
    num : dict
        The row's numbers (:func:`_row_values`).
    c0, c1 : float
        The section's chainage [m].
    vpd : float
        Vehicles per day.
    speed : float
        Speed [km/h].
    where : str
        File, row and section id for messages.

    Returns
    -------
    riskrf.risk.rhrs.RHRSRating or None
        None when the row gives no ``rhrs_*`` column.
    """
    given = {c.removeprefix("rhrs_"): num[c] for c in RHRS_COLUMNS if c in num}
    if not given:
        return None
    # what the section's own columns already say; rhrs_* columns override
    derived = {"slope_height_m": num.get("cut_height_m"), "roadway_width_m": num.get("road_width_m")}
    if "avr_percent" not in given:
        derived.update(slope_length_m=num.get("cut_length_m", c1 - c0), adt_vehicles_per_day=vpd,
                       speed_kmh=speed)
    attrs = {k: v for k, v in derived.items() if v is not None}
    attrs.update(given)
    try:
        return rhrs.rate(variant=ctx.variant, cap_points=ctx.rhrs_cap, **attrs)
    except rhrs.RHRSError as exc:
        if exc.missing:        # name the columns that would give what is missing
            cols = [_RHRS_SOURCE_COLUMNS.get(m, f"'rhrs_{m}'") for m in exc.missing]
            raise CorridorError(f"{where}: RHRS ({ctx.variant}) needs column(s) {', '.join(cols)}, empty "
                                "in this row and in [defaults]") from exc
        raise CorridorError(f"{where}: RHRS: {exc}") from exc
    except TypeError as exc:
        raise CorridorError(f"{where}: RHRS: {exc}") from exc


def _read_section_row(ctx: _RowContext, raw, row: int, sid: str, where: str) -> tuple[Section, float | None]:
    """Check one row of the sections table and build its :class:`Section`.

    Parameters
    ----------
    ctx : _RowContext
        The corridor-wide inputs and running state.
    raw : pandas.Series
        The row, as text.
    row : int
        The file line / spreadsheet row.
    sid : str
        The section id (checked non-empty and unique by the caller).
    where : str
        File, row and section id for messages.

    Returns
    -------
    section : Section
        The checked section (a shared rate is NaN until all rows are read).
    weight : float or None
        The section's weight in the corridor-wide ``[rates]`` inventory; None for its own rate.

    Raises
    ------
    CorridorError
        The first problem found in the row.
    """
    vals, num = _row_values(ctx, raw, where)
    for c in ("chainage_from", "chainage_to"):
        if c not in num:
            raise CorridorError(f"{where}: column {c!r} is empty")
    c0, c1 = num["chainage_from"] * ctx.scale, num["chainage_to"] * ctx.scale
    if c1 <= c0:
        raise CorridorError(f"{where}: chainage_to = {num['chainage_to']:g} must exceed chainage_from = "
                            f"{num['chainage_from']:g} ({ctx.unit})")
    for c in RATE_COLUMNS + ("vehicles_per_day", "speed_kmh"):
        if c in num and num[c] < 0 or (c == "speed_kmh" and c in num and num[c] == 0):
            raise CorridorError(f"{where}: column {c!r} = {num[c]:g} must be > 0" if c == "speed_kmh" else
                                f"{where}: column {c!r} = {num[c]:g} must be >= 0")
    rate, rate_source, weight = _row_rate(ctx, vals, num, c0, c1, where)
    sc, geometry = _row_scenario(ctx, vals, num, sid, where)
    opts = tuple(ctx.option_names)
    if vals["options"]:
        opts = tuple(o.strip() for o in str(vals["options"]).split(";") if o.strip())
        unknown = [o for o in opts if o not in ctx.option_names]
        if unknown:
            raise CorridorError(f"{where}: column 'options' names {unknown}, not options of the corridor "
                                f"({ctx.option_names})")
        if len(opts) < 2:
            raise CorridorError(f"{where}: column 'options' must name at least two options to compare")
    vpd = num.get("vehicles_per_day", ctx.exposure.vehicles_per_day)
    speed = num.get("speed_kmh", ctx.exposure.speed_kmh)
    ctx.fallback.update(c for c in ("vehicles_per_day", "speed_kmh") if c not in num)
    rating = _row_rating(ctx, num, c0, c1, vpd, speed, where)
    cut_len = num.get("cut_length_m", num.get("rhrs_slope_length_m"))
    if cut_len is not None and not 0 < cut_len <= (c1 - c0) * (1 + 1e-12):
        raise CorridorError(f"{where}: column 'cut_length_m' (or rhrs_slope_length_m) = {cut_len:g} m must lie "
                            f"in (0, {c1 - c0:g}] (the section's length along the chainage)")
    line = None
    if ctx.centreline is not None:
        lo, hi = ctx.centreline.chainage_range_m
        if c0 < lo - 1e-6 or c1 > hi + 1e-6:
            raise CorridorError(f"{where}: chainage {c0:g}-{c1:g} m lies beyond the centreline "
                                f"{ctx.centreline.source} ({lo:g} to {hi:g} m)")
        line = tuple(map(tuple, ctx.centreline.cut(c0, c1)))
    section = Section(id=sid, row=row, chainage_from_m=c0, chainage_to_m=c1, scenario=sc,
                      geometry=geometry, falls_per_year=float(rate), vehicles_per_day=float(vpd),
                      speed_kmh=float(speed), options=opts, rating=rating,
                      notes=str(vals["notes"] or ""), rate_source=rate_source,
                      cut_length_m=None if cut_len is None else float(cut_len), line=line)
    return section, (weight if rate_source == "shared" else None)


def _share_corridor_rate(sections: list, weights: dict, shared, src: str) -> list:
    """Give the sections without a rate of their own their share of the corridor-wide ``[rates]`` inventory.

    Parameters
    ----------
    sections : list of Section
        The sections read.
    weights : dict
        Section id -> weight (km of road or m2 of rock face) of the sharing sections.
    shared : SharedRate
        The corridor-wide rate (:func:`riskrf.app.corridor.rates._shared_rate`).
    src : str
        The corridor file's name for messages.

    Returns
    -------
    list of Section
        The sections, the sharing ones with ``falls_per_year`` = rate / covered x weight [1/yr].
    """
    unit = "km" if shared.share == "km" else "m2 of face"
    covered = shared.covered if shared.covered is not None else sum(weights.values())
    if covered < sum(weights.values()) * (1 - 1e-9):
        raise CorridorError(f"{src}: rates.covered_{'length_km' if shared.share == 'km' else 'face_area_m2'} "
                            f"= {covered:g} is less than the sharing sections' {sum(weights.values()):g} {unit}")
    per = shared.rate / covered
    return [replace(s, falls_per_year=per * weights[s.id],
                    rate_source=f"share of the corridor {shared.note}: {per:.4g}/yr per {unit} x "
                                f"{weights[s.id]:.4g} {unit}") if s.id in weights else s for s in sections]


def _cross_row_errors(sections: list, tsrc: str, errors: list, bad_rows: set) -> list:
    """Check the sections against each other: overlapping chainages and ids sharing a crc32 checksum.

    Parameters
    ----------
    sections : list of Section
        The sections read.
    tsrc : str
        The sections table's name for messages.
    errors : list of str
        The errors found so far; extended in place.
    bad_rows : set of int
        The rows with errors; extended in place.

    Returns
    -------
    list of Section
        The sections ordered by chainage (bad ones included).
    """
    ordered = sorted(sections, key=lambda s: s.chainage_from_m)
    for a, b in zip(ordered[:-1], ordered[1:]):
        if b.chainage_from_m < a.chainage_to_m:
            errors.append(f"{tsrc}: row {b.row} (section {b.id!r}): chainage {b.chainage_from_m:g}-{b.chainage_to_m:g} "
                          f"m overlaps row {a.row} (section {a.id!r}, {a.chainage_from_m:g}-{a.chainage_to_m:g} m)")
            bad_rows.add(b.row)
    # a section's seed and partition file are keyed by crc32(id): two ids with one checksum would share both
    by_key = {}
    for sec in sorted(sections, key=lambda s: s.row):
        k = _section_key(sec.id)
        if k in by_key:
            first = by_key[k]
            errors.append(f"{tsrc}: row {sec.row} (section {sec.id!r}): column 'id' = {sec.id!r} has the same crc32 "
                          f"checksum ({k:08x}) as row {first.row} (section {first.id!r}), so the two would share a "
                          "seed and a partition file; rename one of them")
            bad_rows.add(sec.row)
        else:
            by_key[k] = sec
    return ordered
