"""Reading a corridor file: :func:`load_corridor`, the corridor TOML and its sections table, checked before any work.

The TOML's tables (``[corridor]``, ``[defaults]``, ``[mass]``, ``[materials]``, ``[rates]``, the mitigation
tables and ``[[options]]``) are checked against :data:`riskrf.core.file_schemas.CORRIDOR_SCHEMA` and by hand
where a flat declaration cannot say it; the sections table is read by the rules of :mod:`riskrf.io.tables`
and each row by :mod:`riskrf.app.corridor.rows`.  Every error names the file, the row, the section id, the
column and the value.  Chainage m (or km), rates per year, money in the corridor currency.
"""
from __future__ import annotations

import difflib
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ...core.file_schemas import CORRIDOR_MATERIALS, CORRIDOR_SCHEMA
from ...core.schema import check as check_schema
from ...core.units import M_PER_KM
from ...risk import rhrs
from ...risk.mitigation_inputs import MitigationError, parse_mitigation
from .model import (
    ALL_COLUMNS,
    NUMBER_COLUMNS,
    PER_M_FIELDS,
    RHRS_COLUMNS,
    Corridor,
    CorridorError,
    _check_corridor_gdf,
    _unknown,
)
from .rates import _mass_law, _shared_rate
from .rows import _cross_row_errors, _read_section_row, _RowContext, _share_corridor_rate

BUNDLED_MATERIALS = Path(__file__).resolve().parents[3] / "simulation" / "scenarios" / "road_cut_barrier.toml"


def _read_table(path: Path, reader: dict | None = None) -> tuple[pd.DataFrame, np.ndarray]:
    """The sections table as text cells, with the file line of each row (rules of :mod:`riskrf.io.tables`).

    Number columns are converted by the decimal-mark rule of :func:`riskrf.io.tables.parse_numbers`
    (decided per column: ``1,5`` and ``1.192,5`` read as in a European export); cells that are
    not numbers stay text so that each row's error names its value.  Wholly empty rows and
    ``#`` comment lines of a text file are skipped (their lines still count).
    """
    from ...io.tables import is_blank, parse_numbers, read_table
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


@dataclass(frozen=True)
class _CorridorSettings:
    """The checked ``[corridor]`` table (:func:`_corridor_settings`): ``table``, its typed record
    (:data:`riskrf.core.file_schemas.CORRIDOR_RECORDS`), and what is read or decided from it: ``variant`` (RHRS
    variant), ``centreline`` (:mod:`riskrf.io.gis` centreline or None), ``reader`` (options of :func:`_read_table`),
    ``rhrs_cap`` (points or None), ``unit`` (chainage unit, 'm' or 'km') and ``basis`` (rate basis, 'road' or
    'release')."""
    table: object
    variant: str
    centreline: object
    reader: dict
    rhrs_cap: float | None
    unit: str
    basis: str


def _corridor_settings(cor: dict, path: Path, src: str, sheet, header_row, decimal, encoding) -> _CorridorSettings:
    """Check the ``[corridor]`` table and read its centreline, in the order the errors are raised.

    Parameters
    ----------
    cor : dict
        The ``[corridor]`` table as written (read into its typed record once its field names are checked).
    path : pathlib.Path
        The corridor file (paths in it are relative to its folder).
    src : str
        The corridor file's name for messages.
    sheet, header_row, decimal, encoding
        Reader options of the sections table given as arguments (they win over ``sections_*`` fields).

    Returns
    -------
    _CorridorSettings
        The record and the settings read from it.

    Raises
    ------
    CorridorError
        An unknown or invalid field, or a centreline that cannot be read.
    """
    cor_table = CORRIDOR_SCHEMA.table("corridor")          # one declaration of the [corridor] fields
    _unknown(cor, {f.name for f in cor_table.fields}, "corridor.", src)
    given = list(cor)                                      # the fields the file states, in its order
    c = cor_table.record(cor)
    variant = c.rhrs_variant
    why = rhrs.variant_problem(variant)
    if why:
        raise CorridorError(f"{src}: corridor.rhrs_variant = {variant!r} {why}")
    for k in [k for k in given if k.startswith("centreline")]:     # checked before the line is read
        why = cor_table.field(k).problem(getattr(c, k))
        if why:
            raise CorridorError(f"{src}: corridor.{k} = {getattr(c, k)!r} {why}")
    centreline = None
    if c.centreline is not None:
        from ...io.gis import GISError, read_centreline
        try:
            centreline = read_centreline(
                (path.parent / str(c.centreline)).resolve(), layer=c.centreline_layer,
                calibration_layer=c.centreline_calibration_layer,
                calibration_field=c.centreline_calibration_field,
                chainage_start_m=float(c.centreline_chainage_start_m))
        except GISError as exc:
            raise CorridorError(f"{src}: corridor.centreline = {c.centreline!r}: {exc}") from None
    elif any(k.startswith("centreline_") for k in given):
        raise CorridorError(f"{src}: centreline_* fields need corridor.centreline = \"road.gpkg\" (the road's line)")
    reader = {"sheet": sheet if sheet is not None else c.sections_sheet,
              "header_row": header_row if header_row is not None else c.sections_header_row,
              "decimal": decimal if decimal is not None else c.sections_decimal,
              "encoding": encoding if encoding is not None else c.sections_encoding}
    if reader["decimal"] not in (None, ".", ","):
        raise CorridorError(f"{src}: corridor.sections_decimal = {reader['decimal']!r} must be '.' or ','")
    rhrs_cap = c.rhrs_cap_points
    if rhrs_cap is not None and (isinstance(rhrs_cap, bool) or not isinstance(rhrs_cap, (int, float))
                                 or rhrs_cap < 81):
        raise CorridorError(f"{src}: corridor.rhrs_cap_points = {rhrs_cap!r} must be a number >= 81")
    if c.sections is None:
        raise CorridorError(f"{src}: [corridor] needs sections = \"table.csv\" (CSV, Excel or Parquet)")
    for k, v in (("seed", c.seed), ("n_blocks", c.n_blocks), ("option_blocks", c.option_blocks)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, int) or v < (0 if k == "seed" else 100)):
            raise CorridorError(f"{src}: corridor.{k} = {v!r} must be a whole number"
                                + (" >= 0" if k == "seed" else " >= 100"))
    unit = c.chainage_unit
    if unit not in ("m", "km"):
        raise CorridorError(f"{src}: corridor.chainage_unit = {unit!r} must be 'm' or 'km'")
    basis = c.rate_basis
    if basis not in ("road", "release"):
        raise CorridorError(f"{src}: corridor.rate_basis = {basis!r} must be 'road' (rates count falls reaching "
                            "the road, as a road maintenance record does) or 'release' (falls >= m_min released)")
    return _CorridorSettings(table=c, variant=variant, centreline=centreline, reader=reader, rhrs_cap=rhrs_cap,
                             unit=unit, basis=basis)


def _materials_template(mat: dict, path: Path, src: str) -> tuple[dict, dict, Path]:
    """The materials and settings that generated cuts use, from ``materials.scenario`` or the bundled file.

    Parameters
    ----------
    mat : dict
        The ``[materials]`` table as written (``scenario``: a scenario TOML relative to the corridor file).
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
    _unknown(mat, {f.name for f in CORRIDOR_MATERIALS.fields}, "materials.", src)
    m = CORRIDOR_MATERIALS.record(mat)
    template_path = (path.parent / m.scenario).resolve() if m.scenario is not None else BUNDLED_MATERIALS
    if not template_path.exists():
        raise CorridorError(f"{src}: materials.scenario = {m.scenario!r}: file not found ({template_path})")
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
    cs = _corridor_settings(data.get("corridor", {}), path, src, sheet, header_row, decimal, encoding)
    cor, centreline, variant = cs.table, cs.centreline, cs.variant
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

    df, file_rows, tsrc = _read_sections_table((path.parent / cor.sections).resolve(), cs.reader)
    default_seeder = {"dist": "lognormal", "median": float(gr.m_min) * 2, "sigma": 1.0,
                      "max": float(gr.m_max or gr.m_min * 1e4)}
    ctx = _RowContext(path=path, columns=df.columns, defaults=defaults,
                      scale=M_PER_KM if cs.unit == "km" else 1.0, unit=cs.unit, shared=shared,
                      m_min_kg=float(gr.m_min), materials=materials, settings=settings, template_path=template_path,
                      default_seeder=default_seeder, option_names=[o.name for o, _ in options],
                      exposure=study["exposure"], variant=variant, rhrs_cap=cs.rhrs_cap, centreline=centreline)
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
    return Corridor(name=str(cor.name if cor.name is not None else path.stem), path=path, sections=tuple(ordered),
                    mass=gr, mass_note=mass_note, rate_basis=cs.basis, study=study, options=options,
                    n_blocks=int(cor.n_blocks if cor.n_blocks is not None else 2000),
                    option_blocks=int(cor.option_blocks if cor.option_blocks is not None else 1000),
                    seed=int(cor.seed if cor.seed is not None else 1), currency=study["consequences"].currency, errors=tuple(errors),
                    defaults_used=tuple(used), crs=None if centreline is None else centreline.crs,
                    centreline=centreline, rhrs_variant=variant)
