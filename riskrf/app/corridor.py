"""Corridor scale: many rock cuts along a road, screened with the RHRS and assessed quantitatively in parallel.

A corridor file (TOML) holds corridor-wide defaults (mass law, traffic, consequences, economics,
options, simulation size, seed) and names a sections table (CSV, Excel or Parquet) with one row per
section.  Everything is read and checked by :func:`load_corridor` before any work starts; every error
names the file, the row, the section id, the column and the value.

Each section's chain is one task on a ``dask.distributed`` client (:func:`run_corridor`):

    generated cut profile (or a scenario file)
      -> mass-coupled EnergyHazard at the barrier line, as ``riskrf assess`` (n blocks with masses log-uniform
         over the mass law, reach and speed by mass class; rate of the section; P(reach road) from the same run)
      -> simulation.run of the scenario's own seeder (n blocks): the reference of the option effects
      -> MitigationStudy: road-user risk of every option, ranking by expected total cost
      -> one result row (RHRS score, risk of doing nothing, best option, its cost)

The seed of each section is ``SeedSequence(seed, spawn_key=(crc32(section id),))``: the child that
``SeedSequence(seed).spawn`` would give at that key, fixed by the section id, so results are identical
for any number of workers, any order of completion and any subset of sections (``--resume``).

Units: lengths m, chainage m, rates per year, money in the corridor currency.
"""
from __future__ import annotations

import difflib
import math
import os
import time
import tomllib
import uuid
import zlib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd

from ..core.validation import RiskrfError
from ..risk import rhrs
from ..risk.mitigation_inputs import MitigationError, parse_mitigation
from ..core.units import DEFAULT_DENSITY_KG_M3, M_PER_KM

BUNDLED_MATERIALS = Path(__file__).resolve().parents[2] / "simulation" / "scenarios" / "road_cut_barrier.toml"

#: Columns of the sections table (units in the names); ``rhrs_*`` columns are the RHRS attributes of
#: :data:`riskrf.risk.rhrs.RATE_FIELDS` prefixed with ``rhrs_``.
GEOMETRY_COLUMNS = ("cut_height_m", "face_angle_deg", "ditch_width_m", "ditch_depth_m", "runout_to_road_m",
                    "road_width_m")
#: Optional geometry of a generated cut: a horizontal catch bench in the face (width 0: no bench).
BENCH_COLUMNS = ("bench_width_m", "bench_height_m")
NUMBER_COLUMNS = GEOMETRY_COLUMNS + BENCH_COLUMNS + ("chainage_from", "chainage_to", "falls_per_year", "falls_per_km_year",
                                     "falls_per_m2_year", "vehicles_per_day", "speed_kmh", "release_zone_share",
                                     "cut_length_m")
RATE_COLUMNS = ("falls_per_year", "falls_per_km_year", "falls_per_m2_year")
#: Ways to give a section's rate: one of the rate columns, or ``inventory`` (the section's own inventory file).
RATE_SOURCES = RATE_COLUMNS + ("inventory",)
TEXT_COLUMNS = ("id", "scenario", "face_material", "ditch_material", "road_material", "options", "inventory",
                "notes")
RHRS_COLUMNS = tuple("rhrs_" + f for f in rhrs.RATE_FIELDS)
#: Sections-table columns that give an RHRS attribute when its ``rhrs_*`` column is empty (named in errors).
_RHRS_SOURCE_COLUMNS = {"slope_height_m": "'rhrs_slope_height_m' (or 'cut_height_m')",
                        "roadway_width_m": "'rhrs_roadway_width_m' (or 'road_width_m')",
                        "sight_distance_m": "'rhrs_sight_distance_m' (or 'rhrs_percent_dsd')",
                        "decision_sight_distance_m": "'rhrs_decision_sight_distance_m' (or 'rhrs_percent_dsd')",
                        "block_size_m or volume_m3": "'rhrs_block_size_m' or 'rhrs_volume_m3'"}
ALL_COLUMNS = TEXT_COLUMNS + NUMBER_COLUMNS + RHRS_COLUMNS
#: Most falls a year one section may be given.  A deliberately loose bound against unit and typing mistakes
#: (per m2 read as per km, 10^6 for 10^-6): 10,000 a year is 27 falls a day reaching one road section, a
#: slope that closes its road rather than one a corridor screening ranks.
MAX_SECTION_FALLS_PER_YEAR = 10_000.0
#: Per-metre cost fields of corridor options, multiplied by the section's cut length (``cut_length_m``: the length
#: of rock cut along the road that the works treat; default ``rhrs_slope_length_m``, else the section length).
PER_M_FIELDS = ("capital_cost_per_m", "annual_maintenance_per_m", "replacement_cost_per_m")
#: Crest plateau [m] behind the cut and verge [m] beyond the road of a generated profile (room for
#: the seeder and for blocks crossing the road to come to rest).
CREST_M = 5.0
VERGE_M = 10.0


class CorridorError(RiskrfError, ValueError):
    """A corridor file or sections table is invalid; the message lists every bad field found."""


@dataclass(frozen=True)
class Section:
    """One validated section: id, chainage [m], its scenario (generated or read), rate and traffic."""

    id: str
    row: int
    chainage_from_m: float
    chainage_to_m: float
    scenario: object = field(repr=False)
    geometry: str
    falls_per_year: float
    vehicles_per_day: float
    speed_kmh: float
    options: tuple
    rating: rhrs.RHRSRating | None = None
    notes: str = ""
    rate_source: str = ""
    cut_length_m: float | None = None
    line: tuple | None = field(default=None, repr=False)

    @property
    def works_length_m(self) -> float:
        """Length [m] that per-metre option costs are paid on: the cut length, else the section length."""
        return self.length_m if self.cut_length_m is None else self.cut_length_m

    @property
    def length_m(self) -> float:
        """Length of the section along the chainage [m]."""
        return self.chainage_to_m - self.chainage_from_m


@dataclass(frozen=True)
class Corridor:
    """A validated corridor: sections, mass law, study inputs, simulation size and seed."""

    name: str
    path: Path
    sections: tuple
    mass: object
    mass_note: str
    rate_basis: str
    study: dict = field(repr=False)
    options: tuple = ()
    n_blocks: int = 2000
    option_blocks: int = 1000
    seed: int = 1
    currency: str = "CHF"
    errors: tuple = ()
    defaults_used: tuple = ()
    crs: str | None = None
    centreline: object = field(default=None, repr=False)
    rhrs_variant: str = "fhwa"

    def section(self, sid: str) -> Section:
        """The section with id ``sid`` (StopIteration when there is none).

        Parameters
        ----------
        sid : str
            Section id.

        Returns
        -------
        Section
            The section with that id.
        """
        return next(s for s in self.sections if s.id == sid)


# ---------------------------------------------------------------------------------------------------------
# reading and validation
# ---------------------------------------------------------------------------------------------------------
def _read_table(path: Path, reader: dict | None = None) -> tuple[pd.DataFrame, np.ndarray]:
    """The sections table as text cells, with the file line of each row (rules of :mod:`riskrf.io.tables`).

    Number columns are converted by the decimal-mark rule of :func:`riskrf.io.tables.parse_numbers`
    (decided per column: ``1,5`` and ``1.192,5`` read as in a European export); cells that are
    not numbers stay text so that each row's error names its value.  Wholly empty rows and
    ``#`` comment lines of a text file are skipped (their lines still count).
    """
    from ..io.tables import is_blank, parse_numbers, read_table
    if not path.exists():
        raise CorridorError(f"sections table not found: {path}")
    reader = dict(reader or {})
    decimal = reader.pop("decimal", None)
    try:
        table, first, _ = read_table(path, what="sections table",
                                     comment="#" if path.suffix.lower() in (".csv", ".txt", ".tsv") else None,
                                     **reader)
    except ValueError as exc:
        raise CorridorError(str(exc)) from None
    rows = np.arange(len(table)) + first
    keep = ~is_blank(table).to_numpy() if len(table) else np.ones(0, bool)
    table, rows = table[keep].reset_index(drop=True), rows[keep]
    table = table.astype(object)
    for c in [c for c in table.columns if c in NUMBER_COLUMNS + RHRS_COLUMNS]:
        cells = table[c]
        is_class = cells.astype(str).str.contains(r"[A-DF-Za-df-z]", regex=True)    # words (RHRS classes, typos)
        try:
            values = parse_numbers(cells.where(~is_class, ""), path, c, rows, decimal=decimal, errors="coerce")
        except ValueError as exc:          # a column mixing decimal marks: a property of the file
            raise CorridorError(str(exc)) from None
        good = values.notna().to_numpy()
        table[c] = [float(v) if g else cell for v, g, cell in zip(values, good, cells)]
    return table, rows


def _section_key(sid: str) -> int:
    """crc32 of a section id: the key of its seed and of its partition file (ids must not share one)."""
    return zlib.crc32(sid.encode("utf-8"))


def _section_seed(seed: int, sid: str) -> int:
    """Seed of one section: the SeedSequence(seed) child at spawn key crc32(id), as an integer."""
    child = np.random.SeedSequence(int(seed), spawn_key=(_section_key(sid),))
    return int(child.generate_state(1, dtype=np.uint64)[0]) >> 1          # < 2**63: fits int64 columns


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
    from ..risk.measures import DITCH_INNER_SLOPE_HV, DITCH_OUTER_SLOPE_HV
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


def _unknown(keys, allowed, where, source):
    for key in keys:
        if key not in allowed:
            close = difflib.get_close_matches(str(key), list(allowed), n=1)
            raise CorridorError(f"{source}: unknown field {where}{key!r}" + (f"; did you mean {close[0]!r}?" if close
                                                                           else f"; allowed: {sorted(allowed)}"))


def _face_area(num: dict, length_m: float, where: str, what: str) -> float:
    """Rock-face area [m2] of a section: length x the face's slope length (height / sin angle)."""
    if "cut_height_m" not in num or "face_angle_deg" not in num:
        raise CorridorError(f"{where}: {what} needs cut_height_m and face_angle_deg (the face area is the section "
                            "length x the face's slope length)")
    return length_m * num["cut_height_m"] / math.sin(math.radians(num["face_angle_deg"]))


def _shared_rate(table, base: Path, m_min_kg: float, source: str):
    """``[rates]``: a corridor-wide inventory shared among the sections that give no rate of their own, in
    proportion to their length (``share = "km"``) or rock-face area (``share = "m2"``).  ``covered_length_km`` /
    ``covered_face_area_m2``: what the inventory covers (default: the sharing sections together).
    Returns None or dict(rate, share, covered, note)."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise CorridorError(f"{source}: rates = {table!r} must be a table ([rates] with inventory = ...)")
    _unknown(table, {"inventory", "share", "covered_length_km", "covered_face_area_m2"}, "rates.", source)
    if "inventory" not in table:
        raise CorridorError(f"{source}: [rates] needs inventory = \"file\" (the corridor-wide inventory)")
    share = table.get("share")
    if share not in ("km", "m2"):
        raise CorridorError(f"{source}: rates.share = {share!r} must be 'km' (by section length) or 'm2' (by "
                            "rock-face area)")
    key = "covered_length_km" if share == "km" else "covered_face_area_m2"
    other = "covered_face_area_m2" if share == "km" else "covered_length_km"
    if other in table:
        raise CorridorError(f"{source}: rates.{other} does not apply with share = {share!r} (give {key})")
    cov = table.get(key)
    if cov is not None and (isinstance(cov, bool) or not isinstance(cov, (int, float)) or not cov > 0):
        raise CorridorError(f"{source}: rates.{key} = {cov!r} must be a number > 0")
    inv_path = (base / str(table["inventory"])).resolve()
    rate, note = inventory_rate(inv_path, m_min_kg, f"{source}: rates.inventory = {table['inventory']!r}")
    return {"rate": rate, "share": share, "covered": None if cov is None else float(cov), "note": note}


def _mass_law(table: dict, base: Path, source: str):
    """The corridor's mass law: fitted to an inventory file, or typed (b, m_min_kg, m_max_kg; an ASSUMPTION)."""
    from ..frequency.power_law import GutenbergRichterFit, fit_gutenberg_richter
    _unknown(table, {"inventory", "m_min_kg", "m_max_kg", "b"}, "mass.", source)
    for k in ("m_min_kg", "m_max_kg", "b"):
        v = table.get(k)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0):
            raise CorridorError(f"{source}: mass.{k} = {v!r} must be a number > 0")
    if "inventory" in table:
        if "b" in table:
            raise CorridorError(f"{source}: give mass.inventory (fitted) or mass.b (typed), not both")
        from ..frequency.inventory import read_inventory
        inv_path = (base / table["inventory"]).resolve()
        if not inv_path.exists():
            raise CorridorError(f"{source}: mass.inventory = {table['inventory']!r}: file not found ({inv_path})")
        inv = read_inventory(inv_path)
        gr = fit_gutenberg_richter(inv.masses, inv.duration_years, m_min=table.get("m_min_kg"),
                                   m_max=table.get("m_max_kg"))
        note = (f"mass law fitted to {inv_path.name}: b = {gr.b:.3g} +- {gr.b_stderr:.2g}, m_min = {gr.m_min:.4g} kg "
                f"({gr.n_tail} falls)")
        return gr, note
    if "b" not in table or "m_min_kg" not in table:
        raise CorridorError(f"{source}: [mass] needs inventory = \"file\" (fitted) or b and m_min_kg (typed)")
    b, m_min, m_max = float(table["b"]), float(table["m_min_kg"]), table.get("m_max_kg")
    if m_max is not None and m_max <= m_min:
        raise CorridorError(f"{source}: mass.m_max_kg = {m_max!r} must exceed mass.m_min_kg = {m_min!r}")
    gr = GutenbergRichterFit(a=0.0, b=b, b_stderr=0.0, b_ci=(b, b), level=0.95, b_ci_method="typed", m_min=m_min,
                             m_max=None if m_max is None else float(m_max), rate_min=1.0, n_tail=10 ** 9,
                             n_total=10 ** 9, duration_years=1.0, method="typed", m_min_method="given", ks_distance=0.0)
    note = (f"ASSUMPTION: typed mass law b = {b:g}, m_min = {m_min:g} kg"
            + (f", m_max = {float(m_max):g} kg" if m_max is not None else "")
            + " (no inventory fitted; no sampling uncertainty of b)")
    return gr, note


def inventory_rate(path: Path, m_min_kg: float, where: str) -> tuple[float, str]:
    """Falls >= ``m_min_kg`` per year of an inventory file: :func:`riskrf.read_inventory` (its sidecar gives the
    record period) and the power law fitted above the corridor's m_min (:func:`riskrf.fit_gutenberg_richter`,
    whose rate_min is the falls >= m_min over the record length; its b is reported, the corridor's mass law is
    unchanged).  Falls without a size are left out, as in every size fit.  Returns (rate [1/yr], note).

    Parameters
    ----------
    path : pathlib.Path
        Inventory file.
    m_min_kg : float
        The corridor's smallest mass of the rate [kg].
    where : str
        Where the path was given (section and column), for error messages.

    Returns
    -------
    rate : float
        Falls >= ``m_min_kg`` per year [1/yr].
    note : str
        How the rate was obtained (falls, record length, fitted b).
    """
    import warnings

    from ..frequency.inventory import read_inventory
    from ..frequency.power_law import fit_gutenberg_richter
    if not path.exists():
        raise CorridorError(f"{where}: file not found ({path})")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            inv = read_inventory(path)
        n = int(np.sum(inv.masses >= m_min_kg))
        if n == 0:
            raise ValueError(f"no fall of {inv.masses.size} with a size is >= m_min = {m_min_kg:g} kg")
        fit = fit_gutenberg_richter(inv.masses, inv.duration_years, m_min=m_min_kg)
    except ValueError as exc:
        raise CorridorError(f"{where}: {exc}") from None
    return float(fit.rate_min), (f"inventory {path.name}: {fit.n_tail} falls >= {m_min_kg:g} kg in "
                                 f"{inv.duration_years:.4g} yr (power law b = {fit.b:.3g}), {fit.rate_min:.4g}/yr")


def _read_corridor_toml(path: Path) -> tuple[dict, str]:
    """Read a corridor file and check its top-level tables.

    Parameters
    ----------
    path : pathlib.Path
        The corridor file (TOML).

    Returns
    -------
    data : dict
        The parsed TOML.
    src : str
        The file's name as errors give it.

    Raises
    ------
    CorridorError
        The file is missing, is not valid TOML or has an unknown top-level table.
    """
    if not path.exists():
        raise CorridorError(f"corridor file not found: {path}")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:   # a binary file: named, not a bare codec error
        raise CorridorError(f"{path}: not valid TOML: {exc}") from exc
    src = str(path)
    _unknown(data, {"corridor", "defaults", "mass", "materials", "traffic", "consequences", "economics", "criteria",
                    "uncertainty", "options", "rates"}, "", src)
    return data, src


def _corridor_settings(cor: dict, path: Path, src: str, sheet, header_row, decimal, encoding) -> dict:
    """Check the ``[corridor]`` table and read its centreline, in the order the errors are raised.

    Parameters
    ----------
    cor : dict
        The ``[corridor]`` table.
    path : pathlib.Path
        The corridor file (paths in it are relative to its folder).
    src : str
        The corridor file's name for messages.
    sheet, header_row, decimal, encoding
        Reader options of the sections table given as arguments (they win over ``sections_*`` fields).

    Returns
    -------
    dict
        ``variant`` (RHRS variant), ``centreline`` (:class:`riskrf.io.gis` centreline or None), ``reader``
        (options of :func:`_read_table`), ``rhrs_cap`` (points or None), ``unit`` (chainage unit, 'm' or 'km')
        and ``basis`` (rate basis, 'road' or 'release').

    Raises
    ------
    CorridorError
        An unknown or invalid field, or a centreline that cannot be read.
    """
    from ..core.file_schemas import CORRIDOR_SCHEMA
    cor_table = CORRIDOR_SCHEMA.table("corridor")          # one declaration of the [corridor] fields
    _unknown(cor, {f.name for f in cor_table.fields}, "corridor.", src)
    variant = cor.get("rhrs_variant", "fhwa")
    why = rhrs.variant_problem(variant)
    if why:
        raise CorridorError(f"{src}: corridor.rhrs_variant = {variant!r} {why}")
    for k in [k for k in cor if k.startswith("centreline")]:     # checked before the line is read
        why = cor_table.field(k).problem(cor[k])
        if why:
            raise CorridorError(f"{src}: corridor.{k} = {cor[k]!r} {why}")
    centreline = None
    if "centreline" in cor:
        from ..io.gis import GISError, read_centreline
        try:
            centreline = read_centreline(
                (path.parent / str(cor["centreline"])).resolve(), layer=cor.get("centreline_layer"),
                calibration_layer=cor.get("centreline_calibration_layer"),
                calibration_field=cor.get("centreline_calibration_field", "chainage_m"),
                chainage_start_m=float(cor.get("centreline_chainage_start_m", 0.0)))
        except GISError as exc:
            raise CorridorError(f"{src}: corridor.centreline = {cor['centreline']!r}: {exc}") from None
    elif any(k.startswith("centreline_") for k in cor):
        raise CorridorError(f"{src}: centreline_* fields need corridor.centreline = \"road.gpkg\" (the road's line)")
    reader = {"sheet": sheet if sheet is not None else cor.get("sections_sheet"),
              "header_row": header_row if header_row is not None else cor.get("sections_header_row"),
              "decimal": decimal if decimal is not None else cor.get("sections_decimal"),
              "encoding": encoding if encoding is not None else cor.get("sections_encoding")}
    if reader["decimal"] not in (None, ".", ","):
        raise CorridorError(f"{src}: corridor.sections_decimal = {reader['decimal']!r} must be '.' or ','")
    rhrs_cap = cor.get("rhrs_cap_points")
    if rhrs_cap is not None and (isinstance(rhrs_cap, bool) or not isinstance(rhrs_cap, (int, float))
                                 or rhrs_cap < 81):
        raise CorridorError(f"{src}: corridor.rhrs_cap_points = {rhrs_cap!r} must be a number >= 81")
    if "sections" not in cor:
        raise CorridorError(f"{src}: [corridor] needs sections = \"table.csv\" (CSV, Excel or Parquet)")
    for k in ("seed", "n_blocks", "option_blocks"):
        v = cor.get(k)
        if v is not None and (isinstance(v, bool) or not isinstance(v, int) or v < (0 if k == "seed" else 100)):
            raise CorridorError(f"{src}: corridor.{k} = {v!r} must be a whole number"
                                + (" >= 0" if k == "seed" else " >= 100"))
    unit = cor.get("chainage_unit", "m")
    if unit not in ("m", "km"):
        raise CorridorError(f"{src}: corridor.chainage_unit = {unit!r} must be 'm' or 'km'")
    basis = cor.get("rate_basis", "road")
    if basis not in ("road", "release"):
        raise CorridorError(f"{src}: corridor.rate_basis = {basis!r} must be 'road' (rates count falls reaching "
                            "the road, as a road maintenance record does) or 'release' (falls >= m_min released)")
    return {"variant": variant, "centreline": centreline, "reader": reader, "rhrs_cap": rhrs_cap, "unit": unit,
            "basis": basis}


def _materials_template(mat: dict, path: Path, src: str) -> tuple[dict, dict, Path]:
    """The materials and settings that generated cuts use, from ``materials.scenario`` or the bundled file.

    Parameters
    ----------
    mat : dict
        The ``[materials]`` table (``scenario``: a scenario TOML relative to the corridor file).
    path : pathlib.Path
        The corridor file.
    src : str
        The corridor file's name for messages.

    Returns
    -------
    materials : dict
        The template's ``[materials]`` table.
    settings : dict
        The template's ``[settings]`` table (empty when it has none).
    template_path : pathlib.Path
        The template file read.
    """
    _unknown(mat, {"scenario"}, "materials.", src)
    template_path = (path.parent / mat["scenario"]).resolve() if "scenario" in mat else BUNDLED_MATERIALS
    if not template_path.exists():
        raise CorridorError(f"{src}: materials.scenario = {mat.get('scenario')!r}: file not found ({template_path})")
    template = tomllib.loads(template_path.read_text(encoding="utf-8"))
    return template["materials"], template.get("settings", {}), template_path


def _corridor_options(data: dict, src: str) -> tuple[tuple, dict, list]:
    """Parse the corridor's ``[[options]]`` and study tables, setting per-metre costs aside per option.

    Parameters
    ----------
    data : dict
        The parsed corridor file.
    src : str
        The corridor file's name for messages.

    Returns
    -------
    options : tuple
        ``(option, per_m)`` pairs: the parsed option (costs per metre replaced by placeholders) and its
        per-metre costs ``{capital_cost, annual_maintenance, replacement_cost}`` [money/m].
    study : dict
        ``exposure``, ``consequences``, ``economics``, ``uncertainty`` and ``criteria`` of the study.
    used : list of str
        The defaults the mitigation parser used (as :func:`riskrf.risk.mitigation_inputs.parse_mitigation`).
    """
    opt_specs = data.get("options", [])
    if not isinstance(opt_specs, list):
        raise CorridorError(f"{src}: [[options]] must be an array of tables")
    per_m = []
    clean = []
    for i, spec in enumerate(opt_specs):
        spec = dict(spec)
        pm = {}
        for k in PER_M_FIELDS:
            if k in spec:
                v = spec.pop(k)
                if isinstance(v, bool) or not isinstance(v, (int, float)) or v < 0:
                    raise CorridorError(f"{src}: options[{i}] ({spec.get('name')!r}): {k} = {v!r} must be a number "
                                        ">= 0")
                base_k = k.removesuffix("_per_m")
                if base_k in spec:
                    raise CorridorError(f"{src}: options[{i}] ({spec.get('name')!r}): give {base_k} or {k}, not both")
                pm[base_k] = float(v)
                spec[base_k] = 0.0 if base_k != "replacement_cost" else 1.0      # placeholder for parsing only
        if spec.get("kind") == "ditch" and spec.get("retention") is None:
            raise CorridorError(f"{src}: options[{i}] ({spec.get('name')!r}): a corridor ditch option needs a typed "
                                "retention (ditch geometry differs per section; give the ditch in the section's "
                                "generated profile instead)")
        if "x_m" in spec or "road_x_m" in spec or "zone_x_m" in spec:
            raise CorridorError(f"{src}: options[{i}] ({spec.get('name')!r}): positions (x_m, road_x_m, zone_x_m) "
                                "differ per section and cannot be given corridor-wide")
        per_m.append(pm)
        clean.append(spec)
    mit = {k: data[k] for k in ("traffic", "consequences", "economics", "criteria", "uncertainty") if k in data}
    mit["options"] = clean
    try:
        options, exposure, consequences, economics, used, uncertainty, criteria = parse_mitigation(mit, src)
    except MitigationError as exc:
        raise CorridorError(str(exc)) from exc
    options = tuple(zip(options, per_m))
    study = {"exposure": exposure, "consequences": consequences, "economics": economics,
             "uncertainty": uncertainty, "criteria": criteria}
    return options, study, used


def _read_sections_table(table_path: Path, reader: dict) -> tuple[pd.DataFrame, np.ndarray, str]:
    """Read the sections table and check its columns and that it has rows.

    Parameters
    ----------
    table_path : pathlib.Path
        The sections table (CSV, Excel or Parquet).
    reader : dict
        Reader options of :func:`_read_table`.

    Returns
    -------
    df : pandas.DataFrame
        The table, as text.
    file_rows : numpy.ndarray
        The file line / spreadsheet row of each table row.
    tsrc : str
        The table's name as errors give it.
    """
    df, file_rows = _read_table(table_path, reader)
    tsrc = str(table_path)
    bad_cols = [c for c in df.columns if c not in ALL_COLUMNS]
    if bad_cols:
        c = bad_cols[0]
        close = difflib.get_close_matches(c, ALL_COLUMNS, n=1)
        raise CorridorError(f"{tsrc}: unknown column {c!r}" + (f"; did you mean {close[0]!r}?" if close else
                                                              f"; allowed: {list(ALL_COLUMNS)}"))
    for c in ("id", "chainage_from", "chainage_to"):
        if c not in df.columns:
            raise CorridorError(f"{tsrc}: missing column {c!r}")
    if df.empty:
        raise CorridorError(f"{tsrc}: the sections table has no rows")
    return df, file_rows, tsrc


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
    shared: dict | None
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
        weight = _face_area(num, c1 - c0, where, "rates.share = 'm2'") if ctx.shared["share"] == "m2" \
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


def _share_corridor_rate(sections: list, weights: dict, shared: dict, src: str) -> list:
    """Give the sections without a rate of their own their share of the corridor-wide ``[rates]`` inventory.

    Parameters
    ----------
    sections : list of Section
        The sections read.
    weights : dict
        Section id -> weight (km of road or m2 of rock face) of the sharing sections.
    shared : dict
        The corridor-wide rate (:func:`_shared_rate`).
    src : str
        The corridor file's name for messages.

    Returns
    -------
    list of Section
        The sections, the sharing ones with ``falls_per_year`` = rate / covered x weight [1/yr].
    """
    unit = "km" if shared["share"] == "km" else "m2 of face"
    covered = shared["covered"] if shared["covered"] is not None else sum(weights.values())
    if covered < sum(weights.values()) * (1 - 1e-9):
        raise CorridorError(f"{src}: rates.covered_{'length_km' if shared['share'] == 'km' else 'face_area_m2'} "
                            f"= {covered:g} is less than the sharing sections' {sum(weights.values()):g} {unit}")
    per = shared["rate"] / covered
    return [replace(s, falls_per_year=per * weights[s.id],
                    rate_source=f"share of the corridor {shared['note']}: {per:.4g}/yr per {unit} x "
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


def _check_corridor_gdf(gdf, where: str) -> float:
    """The programme's gross-disproportion factor (>= 1), or a :class:`CorridorError` naming ``where`` and the value.

    Parameters
    ----------
    gdf : float
        Gross-disproportion factor [-].
    where : str
        File and field (``corridor.toml: criteria.disproportion_factor``) or the CLI argument (``--gdf``).

    Returns
    -------
    float
        The factor.
    """
    from ..risk.programme import check_gdf
    try:
        return check_gdf(gdf, where)
    except ValueError as exc:
        raise CorridorError(str(exc)) from None


def load_corridor(path, *, keep_going: bool = False, sheet=None, header_row: int | None = None,
                  decimal: str | None = None, encoding: str | None = None) -> Corridor:
    """Read and check a corridor file and its sections table before any work.

    The sections table is read by the rules of :mod:`riskrf.io.tables` (separator, decimal comma,
    UTF-8 or cp1252, Excel ``sheet`` and ``header_row``, Parquet); ``sheet``, ``header_row``,
    ``decimal`` and ``encoding`` may also be given in the ``[corridor]`` table (``sections_sheet``,
    ``sections_header_row``, ``sections_decimal``, ``sections_encoding``); arguments win.
    Every bad row is reported (file, row, section id, column, value; rows are the file's lines
    as an editor or spreadsheet numbers them, comment lines ``#`` of a CSV included).  With ``keep_going`` the bad rows
    are left out and listed in :attr:`Corridor.errors`; otherwise any bad row raises :class:`CorridorError`
    listing all of them.  Errors in the corridor file itself always raise.

    Parameters
    ----------
    path : str or pathlib.Path
        Corridor TOML file.
    keep_going : bool, optional
        Leave bad section rows out (listed in :attr:`Corridor.errors`) instead of raising.
    sheet : str or int, optional
        Excel sheet of the sections table.
    header_row : int, optional
        Header row of the sections table.
    decimal : str, optional
        Decimal separator of the sections table.
    encoding : str, optional
        Text encoding of the sections table.

    Returns
    -------
    Corridor
        The checked corridor with its sections.
    """
    path = Path(path)
    data, src = _read_corridor_toml(path)
    from ..core.file_schemas import CORRIDOR_SCHEMA
    from ..core.schema import check as check_schema
    cor = data.get("corridor", {})
    cs = _corridor_settings(cor, path, src, sheet, header_row, decimal, encoding)
    centreline, variant = cs["centreline"], cs["variant"]
    defaults = data.get("defaults", {})
    _unknown(defaults, [c for c in ALL_COLUMNS if c not in ("id", "chainage_from", "chainage_to", "inventory")]
             + ["seeder_mass_kg"],
             "defaults.", src)
    check_schema(data, CORRIDOR_SCHEMA, src, error=CorridorError)      # every declared type and range
    gr, mass_note = _mass_law(data.get("mass", {}), path.parent, src)
    shared = _shared_rate(data.get("rates"), path.parent, float(gr.m_min), src)
    materials, settings, template_path = _materials_template(data.get("materials", {}), path, src)
    # study inputs: the mitigation tables, with per-metre costs set aside per option
    options, study, used = _corridor_options(data, src)
    _check_corridor_gdf(study["criteria"].disproportion_factor, f"{src}: criteria.disproportion_factor")

    df, file_rows, tsrc = _read_sections_table((path.parent / cor["sections"]).resolve(), cs["reader"])
    default_seeder = {"dist": "lognormal", "median": float(gr.m_min) * 2, "sigma": 1.0,
                      "max": float(gr.m_max or gr.m_min * 1e4)}
    ctx = _RowContext(path=path, columns=df.columns, defaults=defaults,
                      scale=M_PER_KM if cs["unit"] == "km" else 1.0, unit=cs["unit"], shared=shared,
                      m_min_kg=float(gr.m_min), materials=materials, settings=settings, template_path=template_path,
                      default_seeder=default_seeder, option_names=[o.name for o, _ in options],
                      exposure=study["exposure"], variant=variant, rhrs_cap=cs["rhrs_cap"], centreline=centreline)
    errors, sections, bad_rows = [], [], set()
    weights, seen = {}, {}
    for i, raw in df.iterrows():
        row = int(file_rows[i])  # file line / spreadsheet row (header row 1 unless header_row says otherwise)
        sid = str(raw["id"]).strip()
        where = f"{tsrc}: row {row} (section {sid!r})"
        try:
            if not sid:
                raise CorridorError(f"{tsrc}: row {row}: column 'id' is empty")
            if sid in seen:
                raise CorridorError(f"{where}: column 'id' = {sid!r} duplicates row {seen[sid]}")
            seen[sid] = row
            section, weight = _read_section_row(ctx, raw, row, sid, where)
            if weight is not None:
                weights[sid] = weight
            sections.append(section)
        except CorridorError as exc:
            errors.append(str(exc))
            bad_rows.add(row)
    if weights:
        sections = _share_corridor_rate(sections, weights, shared, src)
    ordered = _cross_row_errors(sections, tsrc, errors, bad_rows)
    if errors and not keep_going:
        raise CorridorError(f"{len(errors)} bad section row(s) (use --keep-going to run the others):\n  "
                            + "\n  ".join(errors))
    ordered = [s for s in ordered if s.row not in bad_rows]
    if not ordered:
        raise CorridorError(f"{tsrc}: no valid section to assess:\n  " + "\n  ".join(errors))
    # a default is listed only where a section uses it: traffic per section falls back on [traffic] only when
    # neither the row nor [defaults] gives it; the exposed length is always the section's length
    fallback = ctx.fallback
    used = [u for u in used if not u.startswith("traffic.exposed_length_m")
            and not any(u.startswith(f"traffic.{c} ") and c not in fallback for c in ("vehicles_per_day", "speed_kmh"))]
    if "seeder_mass_kg" in fallback:
        used.append(f"defaults.seeder_mass_kg = {default_seeder!r} (default; ASSUMPTION: masses [kg] of the "
                    "generated cuts' own seeder, used only for the option effects (the reference run of the "
                    "mitigation study); the hazard is mass-coupled over the mass law)")
    return Corridor(name=str(cor.get("name", path.stem)), path=path, sections=tuple(ordered), mass=gr,
                    mass_note=mass_note, rate_basis=cs["basis"], study=study, options=options,
                    n_blocks=int(cor.get("n_blocks", 2000)), option_blocks=int(cor.get("option_blocks", 1000)),
                    seed=int(cor.get("seed", 1)), currency=study["consequences"].currency, errors=tuple(errors),
                    defaults_used=tuple(used), crs=None if centreline is None else centreline.crs,
                    centreline=centreline, rhrs_variant=variant)


# ---------------------------------------------------------------------------------------------------------
# one section (a task)
# ---------------------------------------------------------------------------------------------------------
def rhrs_columns(rating) -> dict:
    """RHRS columns of a section's result row: ``rhrs_<category>`` whole-point score of every category and
    ``rhrs_total`` (their sum, as a rating sheet prints it); empty (NaN) without a rating.  The category set is
    the union of both geologic cases, so every section's row has the same columns.

    Parameters
    ----------
    rating : RHRSRating or None
        The section's RHRS rating.

    Returns
    -------
    dict
        ``rhrs_<category>`` and ``rhrs_total`` scores [points] (NaN without a rating).
    """
    cats = ("slope_height", "ditch_effectiveness", "average_vehicle_risk", "percent_decision_sight_distance",
            "roadway_width", "structural_condition", "rock_friction", "difference_in_erosion_rates",
            "block_size_or_volume", "climate_and_water", "rockfall_history")
    if rating is None:
        return {**{f"rhrs_{c}": np.nan for c in cats}, "rhrs_total": np.nan}
    pts = rating.integer_scores
    return {**{f"rhrs_{c}": float(pts[c]) if c in pts else np.nan for c in cats},
            "rhrs_total": float(rating.integer_total)}


#: Per-option fields kept in a result row (``options_json``) for the budget programme.
OPTION_FIELDS = ("option", "kind", "capital", "pv_renewals", "pv_maintenance", "deaths_per_year", "individual_risk",
                 "expected_total_cost", "meets_criteria")


def _options_json(rk: pd.DataFrame, base) -> str:
    """Every option of a section's ranking as a JSON list (plain numbers): what the programme chooses among."""
    import json
    recs = []
    for _, r in rk.iterrows():
        recs.append({k: (bool(r[k]) if k == "meets_criteria" else str(r[k]) if k in ("option", "kind")
                         else float(r[k])) for k in OPTION_FIELDS})
    return json.dumps(recs, sort_keys=True)
def _road_reach(hazard, result, mm) -> float:
    """P(a fall of mass model ``mm`` reaches the road line) from the mass-coupled run ``result`` behind ``hazard``
    (the same blocks and mass classes as the hazard's barrier samples, reach counted per class)."""
    from ..hazard.mass_coupling import MassCoupledSamples
    s = hazard.velocity
    road = np.full(result.n, np.nan)
    road[np.unique(result.collector("road", first_only=True)["block"].to_numpy())] = 1.0
    return float(MassCoupledSamples(s.mass_kg, road, road, s.edges_kg, "road").reach_probability(mm))


def _section_row(section: Section, corridor: Corridor, n: int, s_seed: int) -> dict:
    """The columns of a section's result row known before any simulation.

    Parameters
    ----------
    section : Section
        The section.
    corridor : Corridor
        Its corridor.
    n : int
        Blocks simulated per run.
    s_seed : int
        The section's seed.

    Returns
    -------
    dict
        Id, chainage [m], lengths [m], geometry, RHRS columns, given rate [1/yr] and its source, rate basis,
        ``n_blocks`` and ``seed``.
    """
    return {"id": section.id, "chainage_from_m": section.chainage_from_m, "chainage_to_m": section.chainage_to_m,
            "length_m": section.length_m, "cut_length_m": section.works_length_m, "geometry": section.geometry,
            "rhrs_score": section.rating.total if section.rating is not None else np.nan,
            **rhrs_columns(section.rating),
            "rate_given_per_year": section.falls_per_year, "rate_source": section.rate_source,
            "rate_basis": corridor.rate_basis, "n_blocks": n,
            "seed": s_seed}


def _section_hazard(section: Section, corridor: Corridor, mm, n: int, s_seed: int):
    """The section's mass-coupled hazard at the barrier line, at its release rate, and the reach probabilities.

    Parameters
    ----------
    section : Section
        The section.
    corridor : Corridor
        Its corridor (mass law, rate basis).
    mm : MassModel
        The corridor's mass model (for the share reaching the road).
    n : int
        Blocks simulated.
    s_seed : int
        The section's seed.

    Returns
    -------
    hazard : EnergyHazard or None
        The hazard at the release rate [1/yr]; None when no simulated block reaches the barrier line
        (``rate_basis = "release"`` only).
    reach : dict
        ``reach_barrier`` and ``reach_road`` [-] and ``release_falls_per_year`` [1/yr] (empty with no hazard).

    Raises
    ------
    ValueError
        For ``rate_basis = "road"`` when no simulated block reaches the road line.
    """
    from ..hazard.mass_coupling import NoArrivalsError
    from ..hazard.simulated import simulate_energy_hazard
    try:
        # the simulated mass range is chosen at the given rate (for a truncated law, as the corridors ship, it is
        # m_min-m_max whatever the rate; beyond it the hazard's notes state the extrapolated share)
        hazard, coupled = simulate_energy_hazard(corridor.mass, section.scenario, "barrier",
                                                 rate_per_year=section.falls_per_year, n=n, seed=s_seed)
    except NoArrivalsError:
        if corridor.rate_basis == "road":
            raise ValueError(f"section {section.id!r}: no simulated block of {n:,} reached the barrier line (nor the "
                             "road), so the release rate behind the recorded road falls cannot be derived; check "
                             "the geometry or use rate_basis = 'release'") from None
        return None, {}
    reach_barrier = float(hazard.reach_probability)
    reach_road = min(_road_reach(hazard, coupled, mm), reach_barrier)
    if corridor.rate_basis == "road":
        if reach_road == 0:
            raise ValueError(f"section {section.id!r}: no simulated block of {n:,} reached the road, so the release "
                             "rate behind the recorded road falls cannot be derived; check the geometry or use "
                             "rate_basis = 'release'")
        release = section.falls_per_year / reach_road
    else:
        release = section.falls_per_year
    reach = {"reach_barrier": reach_barrier, "reach_road": reach_road, "release_falls_per_year": release}
    return replace(hazard, rate_per_year=release), reach


def _no_arrival_values(section: Section) -> dict:
    """The result columns of a section whose simulated blocks never reach the barrier line: nothing to mitigate.

    Parameters
    ----------
    section : Section
        The section (its given rate is the release rate).

    Returns
    -------
    dict
        Zero reach, road falls, risks and costs; doing nothing as the best option.
    """
    return {"reach_barrier": 0.0, "reach_road": 0.0, "release_falls_per_year": section.falls_per_year,
            "road_falls_per_year": 0.0, "deaths_per_year": 0.0, "individual_risk": 0.0,
            "expected_annual_loss": 0.0, "best_option": "do nothing (no block reaches the barrier line)",
            "best_option_capital": 0.0, "best_option_total_cost": 0.0, "best_deaths_per_year": 0.0,
            "best_individual_risk": 0.0, "meets_criteria": True, "note": "no simulated block reached the line",
            "options_json": "[]"}


def _section_options(section: Section, corridor: Corridor) -> tuple:
    """The corridor's options offered on a section, per-metre costs paid on its cut length.

    Parameters
    ----------
    section : Section
        The section (its option names and cut length [m]).
    corridor : Corridor
        Its corridor (options with their per-metre costs).

    Returns
    -------
    tuple
        The section's options; a shed covers the whole cut length.
    """
    works = section.works_length_m           # per-metre costs are paid on the cut, not on the whole section
    opts = []
    for o, pm in corridor.options:
        if o.name not in section.options:
            continue
        upd = {k: v * works for k, v in pm.items()}
        if o.kind == "shed":
            upd["covered_length_m"] = works
        opts.append(replace(o, **upd))
    return tuple(opts)


def _section_study(section: Section, corridor: Corridor, hazard, reach: dict, n: int, s_seed: int):
    """The section's mitigation study; a run of ``n`` blocks with the scenario's own seeder is its reference.

    Parameters
    ----------
    section : Section
        The section (scenario, traffic, options).
    corridor : Corridor
        Its corridor (consequences, economics, uncertainty, criteria).
    hazard : EnergyHazard
        The hazard at the barrier line at the release rate [1/yr].
    reach : dict
        ``reach_barrier`` and ``reach_road`` [-] of the hazard's run.
    n : int
        Blocks of the reference run.
    s_seed : int
        The section's seed.

    Returns
    -------
    MitigationStudy
        The road-user risk of every option of the section.
    """
    import simulation

    from ..risk.measures import SimulationContext
    from ..risk.mitigation import MitigationStudy

    result = simulation.run(section.scenario, n=n, seed=s_seed, record_paths=0)    # the seeder's run: option effects
    opts = _section_options(section, corridor)
    exposure = replace(corridor.study["exposure"], vehicles_per_day=section.vehicles_per_day,
                       speed_kmh=section.speed_kmh, exposed_length_m=section.length_m)
    unc = replace(corridor.study["uncertainty"], seed=s_seed % (2 ** 32))
    return MitigationStudy(hazard=hazard, options=opts, exposure=exposure,
                           consequences=corridor.study["consequences"], economics=corridor.study["economics"],
                           road_share=reach["reach_road"] / reach["reach_barrier"], source=str(corridor.path),
                           context=SimulationContext(section.scenario, "barrier", "road",
                                                     n_blocks=corridor.option_blocks, seed=s_seed % (2 ** 32),
                                                     threads=1),     # parallel across sections, not within
                           reference=result, uncertainty=unc, criteria=corridor.study["criteria"])


def _ranking_values(rk: pd.DataFrame, corridor: Corridor) -> dict:
    """The result columns of a section's option ranking: doing nothing, the best option and what it buys.

    Parameters
    ----------
    rk : pandas.DataFrame
        The study's ranking (cheapest expected total cost first).
    corridor : Corridor
        Its corridor (criteria, economics).

    Returns
    -------
    dict
        Road falls [1/yr], risks [deaths/yr], costs in the corridor currency; the best option is the cheapest
        that meets the criteria (the cheapest of all, with a note, when none does).
    """
    lim = corridor.study["criteria"].individual_risk_per_year
    none = rk[rk["kind"] == "none"]
    base = none.iloc[0] if len(none) else rk.iloc[-1]
    ok = rk[rk["meets_criteria"]]
    best = ok.iloc[0] if len(ok) else rk.iloc[0]
    years = corridor.study["economics"].horizon_years
    spend = best["capital"] + best["pv_renewals"] + best["pv_maintenance"] \
        - (base["capital"] + base["pv_renewals"] + base["pv_maintenance"])
    avoided = float(base["deaths_per_year"] - best["deaths_per_year"])
    return {
        "road_falls_per_year": float(base["road_falls_per_year"]), "deaths_per_year": float(base["deaths_per_year"]),
        "individual_risk": float(base["individual_risk"]),
        "expected_annual_loss_pv": float(base["pv_expected_loss"]),
        "do_nothing_total_cost": float(base["expected_total_cost"]),
        "best_option": str(best["option"]), "best_option_kind": str(best["kind"]),
        "best_option_capital": float(best["capital"]), "best_option_total_cost": float(best["expected_total_cost"]),
        "best_option_spend": float(spend), "best_deaths_per_year": float(best["deaths_per_year"]),
        "best_individual_risk": float(best["individual_risk"]), "deaths_avoided_per_year": avoided,
        "deaths_avoided_per_million": avoided * years / spend * 1e6 if spend > 0 else np.nan,
        "meets_criteria": bool(best["meets_criteria"]),
        "cheapest_option": str(rk.iloc[0]["option"]),
        "options_json": _options_json(rk, base),
        "note": "" if len(ok) else f"no option meets the criteria (individual risk <= {lim:g}/yr and F-N); "
                                   "cheapest shown"}


def assess_section(section: Section, corridor: Corridor, n_blocks: int | None = None, seed: int | None = None) -> dict:
    """The whole chain for one section; returns one row of the corridor table (plain numbers and strings).

    The hazard at the barrier line is mass-coupled exactly as in ``riskrf assess``
    (:func:`riskrf.hazard.simulated.simulate_energy_hazard`: ``n`` blocks with masses log-uniform over the corridor's
    mass law, reach and speed by mass class).  The share of falls reaching the road and, for ``rate_basis = "road"``,
    the release rate behind the recorded road falls (given / P(reach road)) come from the same mass-coupled run.
    A second run of ``n`` blocks with the scenario's own seeder is the reference of the option effects
    (:class:`~riskrf.risk.mitigation.MitigationStudy` ``reference`` and ``context``), as in ``riskrf assess``.
    Deterministic given the corridor seed and the section id (see the module docstring).

    Parameters
    ----------
    section : Section
        The section to assess.
    corridor : Corridor
        The corridor it belongs to (mass law, traffic, consequences, economics, criteria).
    n_blocks : int, optional
        Blocks simulated per run (default: the corridor's).
    seed : int, optional
        Corridor seed (default: the corridor's).

    Returns
    -------
    dict
        One row of the corridor table: rates [1/yr], risks [deaths/yr], costs in the corridor currency, the best
        option and the RHRS columns.
    """
    from ..hazard.impact_energy import mass_model

    n = int(n_blocks or corridor.n_blocks)
    s_seed = _section_seed(corridor.seed if seed is None else seed, section.id)
    t0 = time.perf_counter()
    mm = mass_model(corridor.mass)
    row = _section_row(section, corridor, n, s_seed)
    hazard, reach = _section_hazard(section, corridor, mm, n, s_seed)
    if hazard is None:
        row.update(_no_arrival_values(section))
    else:
        row.update(reach)
        row.update(_ranking_values(_section_study(section, corridor, hazard, reach, n, s_seed).ranking(), corridor))
    row["seconds"] = time.perf_counter() - t0
    return row


# ---------------------------------------------------------------------------------------------------------
# the whole corridor on a dask client
# ---------------------------------------------------------------------------------------------------------
def connect(scheduler: str | None = None, n_workers: int | None = None, *, timeout_s: float = 10.0,
            processes: bool = True):
    """A ``dask.distributed`` client: to ``scheduler`` (or ``DASK_SCHEDULER_ADDRESS``) if given, used unchanged;
    else a new LocalCluster of ``n_workers`` single-threaded workers (default: one per core).

    Returns (client, cluster or None).  An unreachable scheduler raises ConnectionError within ``timeout_s``.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running dask scheduler.
    n_workers : int, optional
        Workers of a new LocalCluster (default: one per core).
    timeout_s : float, optional
        Time allowed to reach the scheduler [s].
    processes : bool, optional
        Workers as processes (True) or threads.

    Returns
    -------
    client : distributed.Client
        The client.
    cluster : distributed.LocalCluster or None
        The cluster started here (None when connected to ``scheduler``).
    """
    from distributed import Client, LocalCluster
    address = scheduler or os.environ.get("DASK_SCHEDULER_ADDRESS")
    if address:
        try:
            return Client(address, timeout=f"{timeout_s}s"), None
        except (OSError, TimeoutError) as exc:
            raise ConnectionError(f"cannot reach the dask scheduler at {address!r} within {timeout_s:g} s: {exc}") \
                from None
    n = int(n_workers or os.cpu_count() or 1)
    import logging
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=processes, dashboard_address=":0",
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


#: Loggers of dask.distributed that report a cluster's shutdown ("Worker process still alive ... killing",
#: cancelled futures): silenced while riskrf closes its own cluster, on success, error or Ctrl-C alike.
_DASK_LOGGERS = ("distributed", "distributed.nanny", "distributed.worker", "distributed.scheduler",
                 "distributed.core", "distributed.comm", "distributed.batched", "distributed.client", "tornado",
                 "asyncio")


def _shutdown(client, cluster, timeout_s: float = 10.0) -> None:
    """Close the client and (when riskrf started it) the local cluster without tracebacks or shutdown noise.

    Runs in a ``finally``: errors while closing (a cancelled future, a worker that will not stop) are not the
    user's concern and must not hide the run's own outcome, so they are dropped; the workers are killed by
    the cluster when they do not stop within ``timeout_s``."""
    import asyncio
    import logging
    loggers = [logging.getLogger(n) for n in _DASK_LOGGERS]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        for thing in (client, cluster):
            if thing is None:
                continue
            try:
                thing.close(timeout=timeout_s)
            except (Exception, asyncio.CancelledError):     # noqa: BLE001 (see above)
                pass
    finally:
        for lg, level in zip(loggers, levels):
            lg.setLevel(level)


def _task(section, corridor, n_blocks):
    return assess_section(section, corridor, n_blocks)


@dataclass(frozen=True)
class CorridorResult:
    """Results of a corridor run: one row per section (``table``), the failures, and how it ran."""

    corridor: Corridor
    table: pd.DataFrame = field(repr=False)
    failures: tuple = ()
    workers: int = 0
    seconds: float = 0.0
    n_blocks: int = 0

    def summary(self) -> pd.DataFrame:
        """Sections ranked by quantitative risk (deaths per year of doing nothing) with the RHRS rank beside it,
        the best option and its cost; ``rank_difference`` = RHRS rank - risk rank (large: they disagree).

        Returns
        -------
        pandas.DataFrame
            One row per section, ranked by risk [deaths/yr], with ``rank_rhrs``, ``rank_risk`` and ``rank_difference``.
        """
        t = self.table.copy()
        # ranks of values rounded to 12 significant digits: risks equal but for float noise share a rank, stably
        t["rank_risk"] = _sig12(t["deaths_per_year"]).rank(ascending=False, method="min").astype(int)
        t["rank_rhrs"] = _sig12(t["rhrs_score"]).rank(ascending=False, method="min").astype("Int64")
        t["rank_difference"] = t["rank_rhrs"] - t["rank_risk"]
        t["expected_annual_cost_per_km"] = t["expected_annual_loss_pv"] / _pv(self.corridor) / (t["length_m"] / M_PER_KM)
        cols = ["rank_risk", "rank_rhrs", "rank_difference", "id", "chainage_from_m", "chainage_to_m", "rhrs_score",
                "rhrs_total",
                "road_falls_per_year", "deaths_per_year", "individual_risk", "expected_annual_cost_per_km",
                "best_option", "best_option_capital", "best_option_total_cost", "best_individual_risk",
                "deaths_avoided_per_million", "meets_criteria", "note"]
        return t.sort_values(["rank_risk", "id"])[[c for c in cols if c in t]].reset_index(drop=True)

    def budget_curve(self) -> pd.DataFrame:
        """Sections in order of deaths avoided per unit spent (best option of each): cumulative spend and
        cumulative deaths avoided per year (how much risk a budget buys).

        Returns
        -------
        pandas.DataFrame
            One row per section: ``id``, ``option``, cumulative spend (corridor currency) and cumulative deaths avoided
            [1/yr].
        """
        t = self.table[self.table["best_option_spend"] > 0].copy() if "best_option_spend" in self.table else \
            self.table.iloc[0:0].copy()
        t["avoided_per_spend"] = t["deaths_avoided_per_year"] / t["best_option_spend"]
        t = t.sort_values(["avoided_per_spend", "id"], ascending=[False, True])
        return pd.DataFrame({"id": t["id"].to_numpy(), "option": t["best_option"].to_numpy(),
                             "spend": t["best_option_spend"].to_numpy(),
                             "cumulative_spend": t["best_option_spend"].cumsum().to_numpy(),
                             "deaths_avoided_per_year": t["deaths_avoided_per_year"].to_numpy(),
                             "cumulative_deaths_avoided_per_year": t["deaths_avoided_per_year"].cumsum().to_numpy()})

    def figure(self):
        """Along chainage: RHRS score, individual risk and deaths per year per km (see
        :func:`riskrf.report.corridor_report.plot_corridor`).

        Returns
        -------
        matplotlib.figure.Figure
            The chainage figure.
        """
        from ..report.corridor_report import plot_corridor
        return plot_corridor(self)

    def options_table(self) -> pd.DataFrame:
        """Every option that could be built on every section (one row each; "do nothing" left out: not funding a
        section is doing nothing there), with what it costs and what it buys against doing nothing.

        Money in the corridor currency: ``capital`` (paid now), ``present_value`` (capital + renewals +
        maintenance discounted at the corridor's rate over its horizon), ``equivalent_annual_cost``
        (present_value / annuity factor (1 - (1 + r)^-n) / r: the same money as a level cost per year);
        ``deaths_avoided_per_year`` and ``expected_total_cost_saving`` against the section's do-nothing option;
        ``loss_avoided`` (present value of the expected losses avoided, deaths at the VSL included: saving +
        present_value) and ``benefit_cost_ratio`` (loss_avoided / present_value [-],
        :func:`riskrf.risk.programme.benefit_cost_ratio`).

        Returns
        -------
        pandas.DataFrame
            One row per (section, option), with the columns above.
        """
        import json
        pv = _pv(self.corridor)
        rows = []
        for _, r in self.table.iterrows():
            for o in json.loads(r.get("options_json", "[]") or "[]"):
                if o["kind"] == "none":
                    continue
                present = o["capital"] + o["pv_renewals"] + o["pv_maintenance"]
                rows.append({"id": r["id"], "option": o["option"], "kind": o["kind"], "capital": o["capital"],
                             "present_value": present, "equivalent_annual_cost": present / pv,
                             "deaths_per_year": o["deaths_per_year"],
                             "deaths_avoided_per_year": r["deaths_per_year"] - o["deaths_per_year"],
                             "expected_total_cost": o["expected_total_cost"],
                             "expected_total_cost_saving": r["do_nothing_total_cost"] - o["expected_total_cost"],
                             "individual_risk": o["individual_risk"], "meets_criteria": o["meets_criteria"]})
        cols = ["id", "option", "kind", "capital", "present_value", "equivalent_annual_cost", "deaths_per_year",
                "deaths_avoided_per_year", "expected_total_cost", "expected_total_cost_saving", "individual_risk",
                "meets_criteria"]
        t = pd.DataFrame(rows, columns=cols)
        from ..risk.programme import benefit_cost_ratio
        t["loss_avoided"] = t["expected_total_cost_saving"] + t["present_value"]
        t["benefit_cost_ratio"] = benefit_cost_ratio(t["expected_total_cost_saving"], t["present_value"])
        return t

    @property
    def gdf(self) -> float:
        """The corridor's ALARP gross-disproportion factor [-] (``[criteria] disproportion_factor``, default 1)."""
        return float(self.corridor.study["criteria"].disproportion_factor)

    def required_sections(self) -> dict:
        """Sections above the intolerable individual-risk line, and the options that bring each below it.

        The line is the criteria's ``individual_risk_per_year`` (the limit in force, e.g. 1e-4 /yr for an existing
        slope under Hong Kong GEO Report 75 (1998)).  A section whose do-nothing individual risk exceeds it must be
        funded whatever it costs, by an option whose individual risk is at most the limit; where no option reaches
        it, by the options of least individual risk (the best it can be made).

        Returns
        -------
        dict
            ``{section id: [option names]}``, by chainage.
        """
        lim = float(self.corridor.study["criteria"].individual_risk_per_year)
        opts = self.options_table()
        out = {}
        for _, r in self.table.iterrows():
            if not float(r.get("individual_risk", 0.0) or 0.0) > lim:
                continue
            o = opts[opts["id"] == r["id"]]
            if not len(o):
                continue
            ok = o[o["individual_risk"] <= lim]
            if not len(ok):
                ok = o[o["individual_risk"] <= o["individual_risk"].min() * (1 + 1e-12)]
            out[r["id"]] = list(ok["option"])
        return out

    def programme(self, budget: float, *, basis: str = "total", objective: str = "alarp", gdf: float | None = None):
        """The best programme within ``budget`` (:func:`riskrf.risk.programme.optimise_programme`, exact MILP).

        ``basis``: ``"total"`` -- the budget caps the summed capital of the chosen options (money paid now);
        ``"year"`` -- it caps their summed equivalent annual cost (present value of capital, renewals and
        maintenance spread as a level yearly cost at the discount rate).

        ``objective``: ``"alarp"`` (default) first funds the sections above the intolerable individual-risk line
        whatever they cost (:meth:`required_sections`), then maximises the net benefit at the corridor's VSL with
        the gross-disproportion factor ``gdf`` (:func:`riskrf.risk.programme.alarp_net_benefit`): every other
        funded option is worth at least 1/GDF of its present value.  ``"risk"`` maximises deaths avoided per year
        and ``"cost"`` minimises the corridor's expected total cost (both as before, without the tolerability step).

        Parameters
        ----------
        budget : float
            Budget in the corridor currency.
        basis : str, optional
            ``"total"`` (capital) or ``"year"`` (equivalent annual cost).
        objective : str, optional
            ``"alarp"``, ``"risk"`` or ``"cost"``.
        gdf : float, optional
            Gross-disproportion factor [-], >= 1 (default: the corridor's, :attr:`gdf`).

        Returns
        -------
        Programme
            The chosen option of each funded section and the programme's cost and benefit.

        References
        ----------
        HSE (2001) Reducing risks, protecting people. HSE Books, para 140 and Appendix 3.
        """
        from ..risk.programme import optimise_programme
        gdf = self.gdf if gdf is None else _check_corridor_gdf(gdf, "gdf")
        return optimise_programme(self.options_table(), budget, objective=objective,
                                  cost_column=BUDGET_BASES[basis] if basis in BUDGET_BASES else _bad_basis(basis),
                                  gdf=gdf, required=self.required_sections() if objective == "alarp" else None)

    def frontier(self, *, basis: str = "total", objective: str = "alarp", points: int = 25, budgets=None,
                 gdf: float | None = None):
        """Efficient frontier: the best programme's benefit at each budget (exact at every point).

        Parameters
        ----------
        basis : str, optional
            ``"total"`` (capital) or ``"year"`` (equivalent annual cost).
        objective : str, optional
            ``"alarp"``, ``"risk"`` or ``"cost"`` (see :meth:`programme`).
        points : int, optional
            Number of budgets (when ``budgets`` is not given).
        budgets : sequence of float, optional
            Budgets to solve at, in the corridor currency.
        gdf : float, optional
            Gross-disproportion factor [-] of ``"alarp"`` (default: the corridor's).

        Returns
        -------
        Frontier
            The best benefit at each budget.
        """
        from ..risk.programme import efficient_frontier
        gdf = self.gdf if gdf is None else _check_corridor_gdf(gdf, "gdf")
        return efficient_frontier(self.options_table(), budgets, objective=objective, points=points,
                                  cost_column=BUDGET_BASES[basis] if basis in BUDGET_BASES else _bad_basis(basis),
                                  gdf=gdf, required=self.required_sections() if objective == "alarp" else None)

    def compare_programmes(self, programme, other) -> dict:
        """Where two programmes of the same budget differ, in numbers and in one line.

        Parameters
        ----------
        programme : Programme
            The programme recommended (e.g. objective ``"alarp"``).
        other : Programme
            The other objective's programme.

        Returns
        -------
        dict
            ``only_programme``, ``only_other`` and ``other_option`` (section ids funded by one only, or by both
            with different options), the median benefit/cost [-] of each programme's funded options, and
            ``line``: one sentence saying where they disagree.
        """
        a = programme.chosen.set_index("id")["option"]
        b = other.chosen.set_index("id")["option"]
        only_a = [i for i in self.table["id"] if i in a.index and i not in b.index]
        only_b = [i for i in self.table["id"] if i in b.index and i not in a.index]
        diff = [i for i in self.table["id"] if i in a.index and i in b.index and a[i] != b[i]]
        name = {"alarp": f"net benefit at the VSL (GDF {programme.gdf:g})", "risk": "deaths avoided",
                "cost": "expected total cost"}

        def median_bc(p):
            v = p.chosen["benefit_cost_ratio"] if "benefit_cost_ratio" in p.chosen else pd.Series(dtype=float)
            return float(np.nanmedian(v)) if len(v.dropna()) else float("nan")

        def ids(x):
            return ", ".join(x[:6]) + (f" and {len(x) - 6} more" if len(x) > 6 else "")
        bc_b = other.chosen.set_index("id")["benefit_cost_ratio"] if "benefit_cost_ratio" in other.chosen else {}
        parts = []
        if only_b:
            worth = np.nanmedian([bc_b[i] for i in only_b]) if len(bc_b) else float("nan")
            parts.append(f"the {name[other.objective]} programme also funds {len(only_b)} section(s) ({ids(only_b)}) "
                         f"worth a median {worth:.2g} of their cost")
        if only_a:
            parts.append(f"only the {name[programme.objective]} programme funds {ids(only_a)}")
        if diff:
            parts.append(f"they choose different options on {ids(diff)}")
        line = ("The two programmes agree." if not parts else
                f"Where they disagree: {'; '.join(parts)}.")
        return {"only_programme": only_a, "only_other": only_b, "other_option": diff,
                "median_benefit_cost": median_bc(programme), "other_median_benefit_cost": median_bc(other),
                "line": line}

    def programme_table(self, programme) -> pd.DataFrame:
        """Every section with the programme's choice: ``programme_option`` ("" = not funded: do nothing), its
        capital, present value and equivalent annual cost, deaths per year before and after.

        Parameters
        ----------
        programme : Programme
            A programme from :meth:`programme`.

        Returns
        -------
        pandas.DataFrame
            One row per section with the programme's choice, its costs and deaths per year before and after.
        """
        t = self.table[["id", "chainage_from_m", "chainage_to_m", "rhrs_total", "deaths_per_year",
                        "do_nothing_total_cost"]].copy()
        ch = programme.chosen.set_index("id")
        t["programme_option"] = [ch.loc[i, "option"] if i in ch.index else "" for i in t["id"]]
        for c in ("capital", "present_value", "equivalent_annual_cost"):
            t[f"programme_{c}"] = [float(ch.loc[i, c]) if i in ch.index else 0.0 for i in t["id"]]
        t["programme_deaths_per_year"] = [float(ch.loc[i, "deaths_per_year"]) if i in ch.index else d
                                          for i, d in zip(t["id"], t["deaths_per_year"])]
        t["programme_expected_total_cost"] = [float(ch.loc[i, "expected_total_cost"]) if i in ch.index else d
                                              for i, d in zip(t["id"], t["do_nothing_total_cost"])]
        if "benefit_cost_ratio" in ch:
            t["programme_benefit_cost_ratio"] = [float(ch.loc[i, "benefit_cost_ratio"]) if i in ch.index else np.nan
                                                 for i in t["id"]]
        req = set(getattr(programme, "required", ()))
        t["programme_required_by_tolerability"] = [i in req for i in t["id"]]
        return t

    def sections_table(self, programme=None) -> pd.DataFrame:
        """The result rows by chainage as written to sections.csv and sections.gpkg (same columns): everything
        but the per-option list (the text ``geometry`` of the cut renamed ``cut_geometry``), with the programme's
        choice when one is given.

        Parameters
        ----------
        programme : Programme, optional
            Add the programme's choice of each section.

        Returns
        -------
        pandas.DataFrame
            One row per section by chainage [m].
        """
        t = self.table.drop(columns=[c for c in ("options_json",) if c in self.table]).rename(
            columns={"geometry": "cut_geometry"})          # text: a GIS reserves "geometry" for the line itself
        if programme is not None:
            p = self.programme_table(programme)
            t = t.merge(p[["id"] + [c for c in p.columns if c.startswith("programme_")]], on="id", how="left")
        return t

    def lines(self) -> list | None:
        """Line geometry (k x 2 vertices, metres in :attr:`Corridor.crs`) of every row of :attr:`table`, or None
        when the corridor has no centreline.

        Returns
        -------
        list of numpy.ndarray or None
            One (k, 2) vertex array [m] per row of :attr:`table`.
        """
        if self.corridor.centreline is None:
            return None
        return self.corridor.centreline.cuts(self.table["chainage_from_m"], self.table["chainage_to_m"])

    def to_json(self) -> dict:
        """The run as a JSON-ready dict (``corridor_summary.json``): counts, failures, rejected rows, seed, blocks,
        workers, seconds, units (chainage m, rates 1/yr, money in the corridor's currency) and totals.

        Returns
        -------
        dict
            The run summary.
        """
        s = self.summary()
        return {"corridor": self.corridor.name, "sections": int(len(self.table)), "failures": list(self.failures),
                "rejected_rows": list(self.corridor.errors), "seed": self.corridor.seed, "n_blocks": self.n_blocks,
                "workers": self.workers, "seconds": round(self.seconds, 2), "rate_basis": self.corridor.rate_basis,
                "mass_law": self.corridor.mass_note, "currency": self.corridor.currency,
                "units": {"chainage": "m", "rate": "1/yr", "individual_risk": "1/yr", "money": self.corridor.currency},
                "total_deaths_per_year_do_nothing": float(self.table["deaths_per_year"].sum()),
                "total_deaths_per_year_best_options": float(self.table["best_deaths_per_year"].sum()),
                "total_capital_best_options": float(self.table["best_option_capital"].sum()),
                "top": s.head(10).replace({np.nan: None}).to_dict(orient="records"),
                "defaults_used": list(self.corridor.defaults_used)}


#: Points of the efficient frontier written with a programme: (up to the section count given, above it).
FRONTIER_POINTS = (25, 10, 500)

#: What a budget caps, by ``--budget-basis``: capital paid now, or the equivalent annual cost.
BUDGET_BASES = {"total": "capital", "year": "equivalent_annual_cost"}


def _bad_basis(basis):
    raise ValueError(f"budget basis = {basis!r} must be 'total' (capital paid now) or 'year' (equivalent annual "
                     "cost: present value of capital, renewals and maintenance as a level yearly cost)")


def _sig12(values: pd.Series) -> pd.Series:
    """Values rounded to 12 significant digits (NaN kept), for ranking without float-noise ties."""
    x = values.to_numpy(dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        digits = np.where(np.isfinite(x) & (x != 0), 11 - np.floor(np.log10(np.abs(x))), 0)
    return pd.Series([round(v, int(d)) if np.isfinite(v) else v for v, d in zip(x, digits)], index=values.index)


def _pv(corridor) -> float:
    from ..risk.economics import pv_factor
    e = corridor.study["economics"]
    return float(pv_factor(e.discount_rate, e.horizon_years))


def _write_partition(directory: Path, row: dict) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    name = f"section={_section_key(row['id']):08x}.parquet"
    tmp = directory / (name + ".partial")
    pd.DataFrame([row]).to_parquet(tmp, index=False)
    os.replace(tmp, directory / name)


def run_corridor(corridor: Corridor, *, client=None, scheduler: str | None = None, n_workers: int | None = None,
                 n_blocks: int | None = None, partitions: Path | None = None, resume: bool = False,
                 keep_going: bool = False, progress=None, retries: int = 1, log=None) -> CorridorResult:
    """Assess every section of ``corridor`` as a task on a ``dask.distributed`` client.

    ``client``: an existing Client (used as is); else :func:`connect` (``scheduler`` / DASK_SCHEDULER_ADDRESS, or
    a LocalCluster of ``n_workers``).  ``partitions``: a directory receiving one Parquet file per finished section
    (written atomically as sections finish, so memory stays flat and an interrupted run keeps its work);
    ``resume`` skips sections already there.  A task that fails (or whose worker dies) is retried ``retries``
    times; then the run stops, or with ``keep_going`` the failure is listed and the rest continue.
    ``progress(done, total, section_id)`` is called as each section finishes; ``log(text)`` once connected
    (the cluster's dashboard address).

    Parameters
    ----------
    corridor : Corridor
        From :func:`load_corridor`.
    client : distributed.Client, optional
        An existing client.
    scheduler : str, optional
        Address of a dask scheduler.
    n_workers : int, optional
        Workers of a new LocalCluster.
    n_blocks : int, optional
        Blocks simulated per run (default: the corridor's).
    partitions : pathlib.Path, optional
        Directory for one Parquet file per finished section.
    resume : bool, optional
        Skip the sections already in ``partitions``.
    keep_going : bool, optional
        List failed sections instead of stopping.
    progress : callable, optional
        ``progress(done, total, section_id)``.
    retries : int, optional
        Retries of a failed task.
    log : callable, optional
        ``log(text)``, called once connected.

    Returns
    -------
    CorridorResult
        One row per section, the failures and the run's figures.
    """
    from distributed import as_completed
    if n_blocks is not None and (isinstance(n_blocks, bool) or not isinstance(n_blocks, (int, np.integer))
                                 or n_blocks < 100):
        raise ValueError(f"n_blocks = {n_blocks!r} must be a whole number >= 100 (the mass-coupled hazard needs at "
                         "least 20 blocks in each of at least 4 mass classes)")
    t0 = time.perf_counter()
    own = client is None
    cluster = None
    if own:
        client, cluster = connect(scheduler, n_workers)
    if log is not None:
        log(f"dask dashboard (live progress per worker): {getattr(client, 'dashboard_link', None)}")
    try:
        todo = list(corridor.sections)
        done_rows = []
        if resume and partitions is not None and Path(partitions).exists():
            have = {}
            for f in sorted(Path(partitions).glob("section=*.parquet")):
                r = pd.read_parquet(f).iloc[0].to_dict()
                have[r["id"]] = r
            nb = int(n_blocks or corridor.n_blocks)
            keep = [s for s in todo if not (s.id in have and int(have[s.id]["n_blocks"]) == nb
                                            and int(have[s.id]["seed"]) == _section_seed(corridor.seed, s.id))]
            done_rows = [have[s.id] for s in todo if s not in keep]
            todo = keep
        # every worker gets the corridor-wide inputs once, without the sections (each task carries its own)
        c_future = client.scatter(replace(corridor, sections=()), broadcast=True) if todo else None
        run = uuid.uuid4().hex[:8]           # fresh keys: a rerun never picks up an earlier run's (failed) result
        futures = {client.submit(_task, s, c_future, n_blocks, key=f"riskrf-section-{s.id}-{run}", retries=retries):
                   s.id for s in todo}
        failures = []
        total = len(corridor.sections)
        count = len(done_rows)
        for fut in as_completed(futures):
            sid = futures[fut]
            try:
                row = fut.result()
            except Exception as exc:                      # noqa: BLE001 (reported per section)
                if not keep_going:
                    for f in futures:
                        f.cancel()
                    raise RuntimeError(f"section {sid!r} failed: {type(exc).__name__}: {exc} "
                                       "(use --keep-going to run the other sections)") from exc
                failures.append(f"section {sid!r}: {type(exc).__name__}: {exc}")
                continue
            if partitions is not None:
                _write_partition(Path(partitions), row)
            done_rows.append(row)
            count += 1
            if progress is not None:
                progress(count, total, sid)
        workers = len(client.scheduler_info().get("workers", {}))
    finally:
        if own:
            _shutdown(client, cluster)
    if not done_rows:
        raise RuntimeError("no section finished: " + "; ".join(failures))
    table = pd.DataFrame(done_rows).sort_values("chainage_from_m").reset_index(drop=True)
    return CorridorResult(corridor=corridor, table=table, failures=tuple(failures), workers=workers,
                          seconds=time.perf_counter() - t0, n_blocks=int(n_blocks or corridor.n_blocks))


#: The objective whose programme is reported beside a programme's (``other_objective``).
OTHER_OBJECTIVE = {"alarp": "risk", "risk": "alarp", "cost": "alarp"}


def programme_summary(res: CorridorResult, programme, budget_basis: str = "total") -> dict:
    """A programme as summary.json gives it: budget, objective, GDF, cost, benefit, the funded sections with their
    options and benefit/cost, the sections required by tolerability and the overrun they cause.

    Parameters
    ----------
    res : CorridorResult
        The corridor run.
    programme : Programme
        The programme.
    budget_basis : str, optional
        ``"total"`` or ``"year"``.

    Returns
    -------
    dict
        JSON-ready; money in the corridor currency, benefit/cost [-].
    """
    ch = programme.chosen
    bc = ch["benefit_cost_ratio"] if "benefit_cost_ratio" in ch else pd.Series(np.nan, index=ch.index)
    gdf = programme.gdf if programme.objective == "alarp" else None
    return {"budget": programme.budget, "basis": budget_basis, "budget_caps": BUDGET_BASES[budget_basis],
            "objective": programme.objective, "maximised": programme.benefit_column,
            "gross_disproportion_factor": gdf, "cost": programme.cost, "benefit": programme.benefit,
            "sections_funded": int(len(ch)),
            "funded": [{"id": str(r["id"]), "option": str(r["option"]), "cost": float(r[programme.cost_column]),
                        "benefit_cost_ratio": None if not np.isfinite(b) else float(b),
                        "required_by_tolerability": bool(r.get("required_by_tolerability", False))}
                       for (_, r), b in zip(ch.iterrows(), bc)],
            "median_benefit_cost_ratio": float(np.nanmedian(bc)) if bc.notna().any() else None,
            "required_by_tolerability": list(programme.required), "overrun": programme.overrun,
            "gap": programme.gap}


def write_corridor(res: CorridorResult, out: Path, *, overwrite: bool = False, budget: float | None = None,
                   budget_basis: str = "total", objective: str = "alarp", programme=None, frontier=None,
                   gdf: float | None = None, other=None) -> None:
    """Write the corridor's outputs into ``out`` (a directory that appears only when everything is written; an
    existing non-empty ``out`` is replaced whole only with ``overwrite``):

    report.html, corridor.csv (ranked), sections.csv (by chainage; with a centreline also sections.gpkg, the same
    columns on each section's line in the centreline's CRS, and map.png), budget_curve.csv, chainage.png,
    rating_sheets.html (one RHRS sheet per rated section), summary.json; with ``budget`` also programme.csv (every
    section with the option the exact programme gives it, or none, and the option of the other objective's
    programme beside it), frontier.csv and frontier.png.  The other objective's programme (:data:`OTHER_OBJECTIVE`:
    deaths avoided beside the default ``"alarp"``, ``"alarp"`` beside the others) is solved at the same budget and
    named in summary.json (``other_programme``, and ``programme.disagreement``: one line) and in the report.
    ``programme``, ``frontier`` and ``other``: already solved (:meth:`CorridorResult.programme` and ``frontier`` of
    the same budget, basis and objective), written as they are instead of solved again.

    Parameters
    ----------
    res : CorridorResult
        The corridor run.
    out : pathlib.Path
        Output directory.
    overwrite : bool, optional
        Replace an existing non-empty ``out``.
    budget : float, optional
        Budget in the corridor currency (adds the programme outputs).
    budget_basis : str, optional
        ``"total"`` or ``"year"``.
    objective : str, optional
        ``"alarp"`` (default), ``"risk"`` or ``"cost"`` (see :meth:`CorridorResult.programme`).
    programme : Programme, optional
        Already solved programme.
    frontier : Frontier, optional
        Already solved frontier.
    gdf : float, optional
        Gross-disproportion factor [-] of ``"alarp"`` (default: the corridor's ``[criteria] disproportion_factor``).
    other : Programme, optional
        Already solved programme of the other objective.
    """
    from ..io.gis import write_lines_gpkg
    from ..io.outputs import atomic_output_dir, write_json
    from ..report.corridor_report import plot_frontier, plot_map, render_corridor_html, render_rating_sheets
    from ..report.files import save_figure
    if budget_basis not in BUDGET_BASES:
        _bad_basis(budget_basis)
    if budget is None and programme is not None:
        budget = programme.budget
    if programme is not None:
        objective = programme.objective
        gdf = programme.gdf if objective == "alarp" else gdf
    if budget is not None and programme is None:
        programme = res.programme(budget, basis=budget_basis, objective=objective, gdf=gdf)
    if budget is not None and other is None:
        other = res.programme(budget, basis=budget_basis, objective=OTHER_OBJECTIVE[objective], gdf=gdf)
    if budget is not None and frontier is None:
        # every frontier point is a full programme solve: fewer points for a long corridor (see FRONTIER_POINTS)
        frontier = res.frontier(basis=budget_basis, objective=objective, gdf=gdf,
                                points=FRONTIER_POINTS[0] if len(res.table) <= FRONTIER_POINTS[2] else FRONTIER_POINTS[1])
    compared = res.compare_programmes(programme, other) if programme is not None else None
    with atomic_output_dir(out, overwrite=overwrite) as tmp:
        res.summary().to_csv(tmp / "corridor.csv", index=False)
        sections = res.sections_table(programme)
        sections.to_csv(tmp / "sections.csv", index=False)
        res.budget_curve().to_csv(tmp / "budget_curve.csv", index=False)
        figures = {"chainage": save_figure(res.figure(), tmp / "chainage.png")}
        lines = res.lines()
        if lines is not None:
            write_lines_gpkg(tmp / "sections.gpkg", sections, lines, crs=res.corridor.crs)
            figures["map"] = save_figure(plot_map(res, lines, programme), tmp / "map.png")
        if programme is not None:
            pt = res.programme_table(programme)
            och = other.chosen.set_index("id")["option"]
            pt[f"other_programme_option_{other.objective}"] = [och[i] if i in och.index else "" for i in pt["id"]]
            pt.to_csv(tmp / "programme.csv", index=False)
            frontier.summary().to_csv(tmp / "frontier.csv", index=False)
            figures["frontier"] = save_figure(plot_frontier(frontier, currency=res.corridor.currency,
                                                            chosen_budget=budget), tmp / "frontier.png")
        (tmp / "rating_sheets.html").write_text(render_rating_sheets(res), encoding="utf-8")
        (tmp / "report.html").write_text(render_corridor_html(res, figures["chainage"], figures=figures,
                                                              programme=programme, frontier=frontier,
                                                              budget_basis=budget_basis, other=other,
                                                              compared=compared), encoding="utf-8")
        summary = res.to_json()
        if programme is not None:
            summary["programme"] = programme_summary(res, programme, budget_basis)
            summary["programme"]["disagreement"] = compared["line"]
            summary["other_programme"] = programme_summary(res, other, budget_basis)
        write_json(summary, tmp / "summary.json")
