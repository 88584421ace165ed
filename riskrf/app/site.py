"""Site files: one TOML describing one assessment (inventory, slope, exposure, options, economics).

Every field is described in the documentation (File formats, "Site files").  Paths are relative to
the site file.  Unknown fields are errors with a did-you-mean; optional fields
left out take documented defaults, and :attr:`Site.defaults_used` lists them so
the report can state them.  Everything is checked before any computing starts.

The checked tables are typed records generated from the file's one declaration
(:data:`riskrf.core.file_schemas.SITE_SCHEMA`, :meth:`riskrf.core.schema.Table.record`): the code reads
``site.hazard.n_blocks``, and a field's name, type, unit and default have one home.
"""
from __future__ import annotations

import datetime
import difflib
import tomllib
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

from ..core import file_schemas as _fs
from ..core.schema import as_record as _as_record
from ..core.schema import check as _check_schema
from ..core.validation import RiskrfError, is_finite_number
from ..risk.mitigation_inputs import MitigationError, study_inputs
from ..risk.site_rates import SiteRatesTable, check_closure_options, check_rates


class SiteError(RiskrfError, ValueError):
    """A site file is invalid; the message names the file and the field."""


#: Fields of the site file's own tables and their defaults, from the one declaration of the file
#: (:data:`riskrf.core.file_schemas.SITE_SCHEMA`: type, unit, range, default of every field).
SITE_FIELDS = {t.name: t.defaults() for t in (_fs.SITE, _fs.INVENTORY, _fs.HAZARD, _fs.DESIGN_BLOCK, _fs.DESIGN,
                                              _fs.REPORT)}
MITIGATION_TABLES = ("traffic", "consequences", "economics", "options", "uncertainty", "criteria")
#: Optional tables checked by their own modules: [rates] (riskrf.risk.site_rates), [model_uncertainty]
#: (riskrf.app.model_uncertainty), [required_barrier] (riskrf.risk.required_barrier).
OTHER_TABLES = ("rates", "model_uncertainty", "required_barrier")

@dataclass(frozen=True)
class SiteMitigation:
    """The checked mitigation tables of a site (:func:`riskrf.risk.mitigation_inputs.study_inputs`): ``options`` (list of
    :class:`~riskrf.risk.mitigation_inputs.Option`), ``exposure`` ([traffic]), ``consequences``, ``economics``,
    ``uncertainty`` (None when there is no [uncertainty] table) and ``criteria``, each the typed object its parser
    gives; :meth:`study_kwargs` passes them to :class:`~riskrf.risk.mitigation.MitigationStudy`."""
    options: list
    exposure: object
    consequences: object
    economics: object
    uncertainty: object = None
    criteria: object = None

    def study_kwargs(self) -> dict:
        """The tables as keyword arguments of :class:`~riskrf.risk.mitigation.MitigationStudy`.

        Returns
        -------
        dict
            ``options``, ``exposure``, ``consequences``, ``economics``, ``uncertainty``, ``criteria``.
        """
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True)
class Site:
    """A checked site file (``riskrf assess SITE.toml``, documentation: File formats, "Site files").

    ``path`` of the file (relative paths inside it resolve against its folder), ``name`` and ``description``;
    ``inventory``, ``hazard``, ``design_block``, ``design``, ``report`` and ``required_barrier``: the checked tables
    as typed records with every default filled in (:data:`riskrf.core.file_schemas.SITE_RECORDS`, generated from the
    file's declaration: ``site.hazard.n_blocks``); ``mitigation``: the checked mitigation tables
    (:class:`SiteMitigation`); ``rates`` (:data:`SiteRatesTable`) and ``model_uncertainty``
    (:data:`riskrf.app.model_uncertainty.ModelUncertaintySettings`): None when the table is absent; and
    ``defaults_used``: the names of the defaults applied, reported as such in every output.
    """
    path: Path
    name: str
    description: str
    inventory: _fs.SITE_RECORDS["inventory"]
    hazard: _fs.SITE_RECORDS["hazard"]
    mitigation: SiteMitigation
    defaults_used: tuple = field(default_factory=tuple)
    design_block: _fs.SITE_RECORDS["design_block"] = field(default_factory=_fs.SITE_RECORDS["design_block"])
    rates: SiteRatesTable | None = None
    design: _fs.SITE_RECORDS["design"] = field(default_factory=_fs.SITE_RECORDS["design"])
    report: _fs.SITE_RECORDS["report"] = field(default_factory=_fs.SITE_RECORDS["report"])
    #: True when hazard.scenario is a 3-D terrain scenario (a ``[terrain]`` table): ``riskrf assess`` then runs
    #: :func:`riskrf.app.assess3d.run_terrain_assessment` (hazard, energy and road outputs; no option ranking).
    three_d: bool = False
    #: the checked [model_uncertainty] table (riskrf.app.model_uncertainty), None when absent (off)
    model_uncertainty: object = None
    #: the [required_barrier] table (its cost model, riskrf.risk.required_barrier), its defaults when absent
    required_barrier: _fs.SITE_RECORDS["required_barrier"] = field(default_factory=_fs.SITE_RECORDS["required_barrier"])

    def resolve(self, relative) -> Path:
        """A path given in the site file, resolved against the site file's folder.

        Parameters
        ----------
        relative : str or pathlib.Path
            Path as given in the site file.

        Returns
        -------
        pathlib.Path
            The absolute path.
        """
        return (self.path.parent / relative).resolve()


def _unknown(key, allowed, where, source):
    close = difflib.get_close_matches(key, list(allowed), n=1)
    return SiteError(f"{source}: unknown field {where}{key!r}"
                     + (f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(sorted(allowed))}"))


def load_site(path) -> Site:
    """Read and validate a site file; raises :class:`SiteError` before anything is computed.

    Parameters
    ----------
    path : str or pathlib.Path
        Site TOML file.

    Returns
    -------
    Site
        The checked site.
    """
    path = Path(path)
    data = _read_site_toml(path)
    tables, used = _merge_site_tables(data, path)
    if tables["inventory"].path is None:
        raise SiteError(f"{path}: inventory.path is required (the rock fall inventory file)")
    hz, inv = tables["hazard"], tables["inventory"]
    _check_hazard(hz, path)
    _check_inventory(inv, path)
    tables["design_block"] = _check_design_block(tables, path)
    _check_design(tables, path)
    _check_site_files(tables, path)
    rates, rates_used = check_rates(data.get("rates"), inv, path, error=SiteError)
    used += rates_used
    three_d, scenario, hz = _check_scenario(data, hz, inv, path, used)
    _check_velocity_file(hz, path)
    mitigation = _check_mitigation(data, path, rates, hz, scenario, three_d, used)
    # every declared field against its type and range (shares and probabilities in [0, 1], rates, speeds,
    # lengths and traffic > 0): the checks above keep their own messages, this catches the rest
    _check_schema(data, _fs.SITE_SCHEMA, path, error=SiteError)
    from .model_uncertainty import check_model_uncertainty
    model_uncertainty, mu_used = check_model_uncertainty(data.get("model_uncertainty"), path, hz, error=SiteError)
    used += mu_used
    required = _as_record(_fs.REQUIRED_BARRIER, data.get("required_barrier", {}), source=path, error=SiteError)
    from ..risk.required_barrier import cost_model_from_site
    try:
        cost_model_from_site(required, source=str(path))
    except ValueError as exc:
        raise SiteError(str(exc)) from exc
    return Site(path=path.resolve(), name=str(tables["site"].name or path.stem),
                description=str(tables["site"].description), inventory=inv, hazard=hz, mitigation=mitigation,
                defaults_used=tuple(used), design_block=tables["design_block"], rates=rates,
                design=tables["design"], report=tables["report"], three_d=three_d,
                model_uncertainty=model_uncertainty, required_barrier=required)


def _read_site_toml(path: Path) -> dict:
    """The site file's content, read as TOML.

    Parameters
    ----------
    path : pathlib.Path
        Site TOML file.

    Returns
    -------
    dict
        The parsed file.

    Raises
    ------
    FileNotFoundError
        When there is no such file.
    SiteError
        When ``path`` is a directory or not valid TOML (a binary file included).
    """
    if not path.exists():
        raise FileNotFoundError(f"site file not found: {path}")
    if path.is_dir():
        raise SiteError(f"{path} is a directory; give the site file (.toml) inside it")
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:   # a binary file: named, not a bare codec error
        raise SiteError(f"{path}: not valid TOML: {exc}") from exc


def _merge_site_tables(data: dict, path: Path) -> tuple[dict, list]:
    """The site file's own tables (:data:`SITE_FIELDS`) with their defaults filled in; unknown names refused.

    Parameters
    ----------
    data : dict
        The parsed site file.
    path : pathlib.Path
        The site file, named in errors.

    Returns
    -------
    tables : dict
        Table name -> its typed record (:data:`riskrf.core.file_schemas.SITE_RECORDS`), every field of
        :data:`SITE_FIELDS` present.
    used : list of str
        The defaults applied, as ``"table.field = value"``.

    Raises
    ------
    SiteError
        For an unknown table or field (with a did-you-mean) or a table that is not one.
    """
    allowed = set(SITE_FIELDS) | set(MITIGATION_TABLES) | set(OTHER_TABLES)
    for key in data:
        if key not in allowed:
            raise _unknown(key, allowed, "", path)
    used = []
    tables = {}
    for table, fields in SITE_FIELDS.items():
        given = data.get(table, {})
        if not isinstance(given, dict):
            raise SiteError(f"{path}: [{table}] must be a table")
        for key in given:
            if key not in fields:
                raise _unknown(key, fields, f"{table}.", path)
        merged = {}
        for key, default in fields.items():
            if key in given:
                merged[key] = given[key]
            else:
                merged[key] = default
                if default is not None:
                    used.append(f"{table}.{key} = {default!r}")
        tables[table] = _fs.SITE_RECORDS[table](**merged)
    return tables, used


def _check_hazard(hz, path: Path) -> None:
    """The [hazard] table's own fields: one source of speeds, block counts, fences, design period, reach, units.

    Parameters
    ----------
    hz : HazardTable
        The merged [hazard] table (``fences_kj`` [kJ], ``fence_height_m``, ``free_board_m``, ``drop_height_m`` [m],
        ``design_period_years`` [yr], ``reach_probability`` [-]).
    path : pathlib.Path
        The site file, named in every message.

    Raises
    ------
    SiteError
        Naming the file, the hazard field and its value.
    """
    if (hz.scenario is None) == (hz.velocities is None):
        raise SiteError(f"{path}: give exactly one of hazard.scenario (a slope scenario to simulate) or "
                        "hazard.velocities (a velocity file)")
    for key in ("n_blocks", "bootstrap", "option_blocks"):
        value = getattr(hz, key)
        if not isinstance(value, int) or value < 1:
            raise SiteError(f"{path}: hazard.{key} = {value!r} must be a whole number >= 1")
    if not isinstance(hz.fences_kj, list) or not all(isinstance(v, (int, float)) and v > 0
                                                        for v in hz.fences_kj):
        raise SiteError(f"{path}: hazard.fences_kj = {hz.fences_kj!r} must be a list of capacities > 0")
    fh = hz.fence_height_m
    if isinstance(fh, list):
        if len(fh) != len(hz.fences_kj) or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                      and v > 0 for v in fh):
            raise SiteError(f"{path}: hazard.fence_height_m = {fh!r} must be one height > 0 or one per fence in "
                            f"hazard.fences_kj ({len(hz.fences_kj)})")
    elif isinstance(fh, bool) or not isinstance(fh, (int, float)) or fh <= 0:
        raise SiteError(f"{path}: hazard.fence_height_m = {fh!r} must be a number > 0 (or a list, one per fence)")
    if not is_finite_number(hz.free_board_m) or hz.free_board_m < 0:
        raise SiteError(f"{path}: hazard.free_board_m = {hz.free_board_m!r} must be a number >= 0 m")
    if not is_finite_number(hz.design_period_years) or hz.design_period_years <= 1:
        raise SiteError(f"{path}: hazard.design_period_years = {hz.design_period_years!r} must be a number > 1 "
                        "year (a T-year event has annual probability 1/T)")
    if not is_finite_number(hz.reach_probability) or not 0 < hz.reach_probability <= 1:
        raise SiteError(f"{path}: hazard.reach_probability = {hz.reach_probability!r} must be a probability in "
                        "(0, 1]")
    if hz.velocity_unit not in (None, "m/s", "km/h"):
        raise SiteError(f"{path}: hazard.velocity_unit = {hz.velocity_unit!r} is not 'm/s' or 'km/h'")
    if hz.drop_height_m is not None and (not is_finite_number(hz.drop_height_m) or hz.drop_height_m <= 0):
        raise SiteError(f"{path}: hazard.drop_height_m = {hz.drop_height_m!r} must be a height > 0 m (release "
                        "to the barrier line, for the velocity plausibility check)")


def _check_inventory(inv, path: Path) -> None:
    """The [inventory] table's numbers (masses, density, duration, rate scale) and its rate basis.

    Parameters
    ----------
    inv : InventoryTable
        The merged [inventory] table (``m_min_kg``, ``m_max_kg`` [kg], ``density_kg_m3`` [kg/m3],
        ``duration_years`` [yr], ``rate_scale`` [-], ``rate_basis``).
    path : pathlib.Path
        The site file, named in errors.

    Raises
    ------
    SiteError
        Naming the file, field and value.
    """
    for key in ("m_min_kg", "m_max_kg", "density_kg_m3", "duration_years"):
        value = getattr(inv, key)
        if value is not None and (not is_finite_number(value) or value <= 0):
            raise SiteError(f"{path}: inventory.{key} = {value!r} must be a number > 0")
    if inv.m_min_kg is not None and inv.m_max_kg is not None and inv.m_min_kg >= inv.m_max_kg:
        raise SiteError(f"{path}: inventory.m_min_kg = {inv.m_min_kg!r} must be below inventory.m_max_kg = "
                        f"{inv.m_max_kg!r}")
    if not isinstance(inv.rate_scale, (int, float)) or not 0 < inv.rate_scale <= 1e6:
        raise SiteError(f"{path}: inventory.rate_scale = {inv.rate_scale!r} must be a number > 0")
    if inv.rate_basis not in ("release", "road"):
        raise SiteError(f"{path}: inventory.rate_basis = {inv.rate_basis!r} must be 'release' (the inventory "
                        "counts falls released from the slope) or 'road' (it counts falls that reached the road, "
                        "e.g. a patrol record)")


def _check_site_files(tables: dict, path: Path) -> None:
    """The files the site's own tables name (inventory, annual maxima, scenario, velocities, survey) exist.

    Parameters
    ----------
    tables : dict
        Table name -> the merged site table's record.
    path : pathlib.Path
        The site file; paths in it are relative to its folder.

    Raises
    ------
    SiteError
        Naming the field, the value and the resolved path of the missing file.
    """
    for table, key in (("inventory", "path"), ("inventory", "annual_maxima"), ("hazard", "scenario"),
                       ("hazard", "velocities"), ("design_block", "survey")):
        rel = getattr(tables[table], key)
        if rel is not None and not (path.parent / rel).exists():
            raise SiteError(f"{path}: {table}.{key} = {rel!r}: file not found ({(path.parent / rel).resolve()})")


def _check_scenario(data: dict, hz, inv, path: Path, used: list) -> tuple:
    """Load hazard.scenario (2-D profile or 3-D terrain) and check the collectors the site names in it.

    A missing ``hazard.collector`` defaults to ``"barrier"`` (set in the returned ``hz`` and recorded in ``used``).

    Parameters
    ----------
    data : dict
        The parsed site file (a 3-D terrain site refuses the tables it does not use yet).
    hz : HazardTable
        The checked [hazard] table.
    inv : InventoryTable
        The checked [inventory] table (a 3-D terrain site needs rate_basis 'release').
    path : pathlib.Path
        The site file; the scenario is relative to its folder.
    used : list of str
        The defaults applied so far (appended to in place).

    Returns
    -------
    three_d : bool
        True for a 3-D terrain scenario (False also when there is no scenario).
    scenario : object or None
        The loaded scenario, None when the hazard comes from a velocity file.
    hz : HazardTable
        ``hz`` with its collector default filled in.

    Raises
    ------
    SiteError
        For a collector the scenario does not have, a bad scenario file, or a table a 3-D site cannot use.
    """
    if hz.scenario is None:
        return False, None, hz
    import simulation
    if hz.collector is None:
        hz = replace(hz, collector="barrier")
        used.append("hazard.collector = 'barrier'")
    three_d = simulation.is_terrain_scenario_file(path.parent / hz.scenario)
    if three_d:
        scenario = simulation.load_terrain_scenario(path.parent / hz.scenario)
        _check_terrain_site(data, hz, inv, path)
    else:
        scenario = simulation.load_scenario(path.parent / hz.scenario)
        _fs.check_scenario_file(path.parent / hz.scenario, error=SiteError)
    names = [c.name for c in scenario.collectors]
    if hz.collector not in names:
        raise SiteError(f"{path}: hazard.collector = {hz.collector!r}: scenario {hz.scenario!r} has no "
                        f"collector named {hz.collector!r}; its collectors are {names}")
    if hz.road_collector not in names and "road_collector" in data.get("hazard", {}):
        raise SiteError(f"{path}: hazard.road_collector = {hz.road_collector!r}: scenario {hz.scenario!r} "
                        f"has no such collector; its collectors are {names}")
    return three_d, scenario, hz


def _check_velocity_file(hz, path: Path) -> None:
    """Read hazard.velocities now, so that a bad velocity file is found before the fits run.

    Parameters
    ----------
    hz : HazardTable
        The checked [hazard] table (``velocities``, ``collector``, ``velocity_unit``).
    path : pathlib.Path
        The site file; the velocity file is relative to its folder.

    Raises
    ------
    SiteError
        Naming the field, the value and the reader's message.
    """
    if hz.velocities is None:
        return
    from ..io.velocities import read_velocities
    try:
        read_velocities(path.parent / hz.velocities, collector=hz.collector,
                        velocity_unit=hz.velocity_unit)
    except ValueError as exc:
        raise SiteError(f"{path}: hazard.velocities = {hz.velocities!r}: {exc}") from exc


def _check_mitigation(data: dict, path: Path, rates, hz, scenario, three_d: bool, used: list) -> SiteMitigation:
    """The mitigation tables (:data:`MITIGATION_TABLES`), their closure rules and option geometry.

    Parameters
    ----------
    data : dict
        The parsed site file (its mitigation tables are taken from it).
    path : pathlib.Path
        The site file, named in errors.
    rates : SiteRatesTable or None
        The checked [rates] table (closure rules need it).
    hz : HazardTable
        The checked [hazard] table.
    scenario : object or None
        The loaded scenario (:func:`_check_scenario`).
    three_d : bool
        True for a 3-D terrain site (options are then neither required nor checked).
    used : list of str
        The defaults applied so far (the mitigation defaults are appended in place).

    Returns
    -------
    SiteMitigation
        The checked study inputs (:func:`riskrf.risk.mitigation_inputs.study_inputs`), without ``defaults_used``.

    Raises
    ------
    SiteError
        With the message of the failed check.
    """
    mit = {k: data[k] for k in MITIGATION_TABLES if k in data}
    try:
        mitigation = study_inputs(mit, str(path), require_options=not three_d)
    except MitigationError as exc:
        raise SiteError(str(exc)) from exc
    used += list(mitigation.pop("defaults_used"))
    mitigation = SiteMitigation(**mitigation)
    if not three_d:
        check_closure_options(mitigation.options, rates, path, error=SiteError)
    if hz.scenario is not None and not three_d:
        _check_option_geometry(mitigation.options, scenario, hz, path, mitigation.uncertainty)
    return mitigation


def _check_terrain_site(data, hz, inv, path):
    """A site on 3-D terrain: what ``riskrf assess`` does with it (hazard, energy at the barrier line, road per
    metre) and what it does not do yet, refused before any work rather than ignored."""
    for table in ("options", "rates", "uncertainty", "model_uncertainty"):
        if data.get(table) or (table == "model_uncertainty" and table in data):     # an empty one switches it on
            raise SiteError(f"{path}: [{table}] is given, but hazard.scenario {hz.scenario!r} is a 3-D terrain "
                            "scenario: on 3-D terrain riskrf assess writes the hazard, energy and road outputs and "
                            f"does not rank mitigation options yet; remove [{table}] or give a 2-D profile scenario")
    if hz.mass_coupling != "simulated":
        raise SiteError(f"{path}: hazard.mass_coupling = {hz.mass_coupling!r}: a 3-D terrain site is assessed "
                        "with the mass-coupled hazard only ('simulated')")
    if inv.rate_basis != "release":
        raise SiteError(f"{path}: inventory.rate_basis = 'road' is not supported on 3-D terrain yet (the inventory "
                        "must count falls released from the slope)")


def _check_design(tables, path):
    """The [design] table (a valid basis with factors of that basis) and the [report] title block (text)."""
    from ..hazard.design_basis import design_basis_from_site
    d = tables["design"]
    for key in ("positions_x_m", "mel_classes_kj"):
        v = getattr(d, key)
        if v is not None and (not isinstance(v, list) or not v or not all(is_finite_number(x) for x in v)):
            raise SiteError(f"{path}: design.{key} = {v!r} must be a list of numbers")
    pb = d.position_blocks
    if pb is not None and (isinstance(pb, bool) or not isinstance(pb, int) or pb < 100):
        raise SiteError(f"{path}: design.position_blocks = {pb!r} must be a whole number >= 100")
    try:
        design_basis_from_site(d, design_T=tables["hazard"].design_period_years,
                               free_board_m=tables["hazard"].free_board_m)
    except (TypeError, ValueError) as exc:
        raise SiteError(f"{path}: {exc}") from exc
    for key, v in tables["report"].as_dict().items():
        if v is not None and (isinstance(v, bool) or not isinstance(v, (str, int, datetime.date))):
            raise SiteError(f"{path}: report.{key} = {v!r} must be text")


def _check_design_block(tables, path):
    """inventory.sizes, hazard.mass_coupling and the [design_block] table (rule, percentile, survey); returns the
    [design_block] record with its percentile as checked."""
    from ..hazard.design_block import RULES, SIZES, check_percentile
    inv, hz, db = tables["inventory"], tables["hazard"], tables["design_block"]
    if inv.sizes is not None and inv.sizes not in SIZES:
        raise SiteError(f"{path}: inventory.sizes = {inv.sizes!r} must be one of {list(SIZES)} (what the "
                        "inventory's volumes are: detached event volumes, or individual block sizes)")
    if hz.mass_coupling not in ("simulated", "independent"):
        raise SiteError(f"{path}: hazard.mass_coupling = {hz.mass_coupling!r} must be 'simulated' (reach and "
                        "speed by block mass, the default) or 'independent'")
    if db.rule not in RULES:
        raise SiteError(f"{path}: design_block.rule = {db.rule!r} must be one of {list(RULES)}")
    try:
        db = replace(db, percentile=check_percentile(db.percentile, "design_block.percentile"))
    except (TypeError, ValueError) as exc:
        raise SiteError(f"{path}: {exc}") from exc
    fragmenting = db.fractal_dimension is not None or db.iterations is not None
    if db.rule == "fragmentation" and not fragmenting:
        raise SiteError(f"{path}: design_block.rule = 'fragmentation' needs design_block.fractal_dimension and "
                        "design_block.iterations (the fragmentation parameters you assume)")
    if fragmenting:
        from ..hazard.design_block import fractal_fragments
        try:
            fractal_fragments(1.0, db.fractal_dimension, db.iterations)
        except (TypeError, ValueError) as exc:
            raise SiteError(f"{path}: {exc}") from exc
    if db.survey is not None and not isinstance(db.survey, str):
        raise SiteError(f"{path}: design_block.survey = {db.survey!r} must be a file name")
    return db


def _check_option_geometry(options, scenario, hz, path, uncertainty=None):
    """Option geometry against the scenario, before anything is computed: positions inside the profile,
    ditches that fit, scaling zones inside the release zone, uncertain material parameters that exist."""
    from ..risk.measures import Ditch, MeasureError, ditch_profile, material_value, seeder_share
    prof = scenario.profile
    paths = list(uncertainty.materials) if uncertainty is not None else []
    if uncertainty is not None and uncertainty.calibration is not None:
        paths += [c.removeprefix("materials.") for c in uncertainty.calibration.columns]
    for p in paths:
        try:
            material_value(scenario, p, f"{path}: uncertainty.materials")
        except MeasureError as exc:
            raise SiteError(str(exc)) from exc
    for o in options:
        where = f"{path}: option {o.name!r}"
        for fld in ("x_m", "road_x_m"):
            v = getattr(o, fld)
            if v is not None and not prof.x[0] < v < prof.x[-1]:
                raise SiteError(f"{where}: {fld} = {v:g} m is outside the profile ({prof.x[0]:g}, {prof.x[-1]:g}) m")
        try:
            if o.kind == "ditch" and o.retention is None:
                d = Ditch(o.x_m, o.width_m, o.depth_m, option=o.name)
                ditch_profile(prof, d.x_m, d.width_m, d.depth_m, where=where)
                if o.material is not None and o.material not in prof.material_names:
                    raise SiteError(f"{where}: material = {o.material!r} is not a material of the scenario "
                                    f"({', '.join(prof.material_names)})")
                road = next((c for c in scenario.collectors if c.name == hz.road_collector), None)
                if road is not None and d.span[0] <= road.x <= d.span[1]:
                    raise SiteError(f"{where}: the ditch ({d.span[0]:g}-{d.span[1]:g} m) would cut through the road "
                                    f"line (collector {road.name!r} at x = {road.x:g} m)")
            if o.kind == "scaling" and o.zone_x_m is not None:
                seeder_share(scenario, o.zone_x_m, where)
            if o.retention is None and o.kind in ("bench", "bund", "drape"):
                _check_slope_measure(o, scenario, hz, path)
        except MeasureError as exc:
            raise SiteError(str(exc)) from exc


def _check_slope_measure(o, scenario, hz, path):
    """A bench, bund or drape against the scenario before anything is simulated: inside the profile, fitting the
    ground, clear of the road line, its material known; a drape on a rock face over part of the release zone.
    Raises MeasureError naming the site file ``path``, the option and the field."""
    from ..risk.geometry_measures import SlopeMeasure, check_drape_zone, scenario_with_measures
    from ..risk.measures import MeasureError
    where = f"{path}: option {o.name!r}"
    prof = scenario.profile
    if o.kind == "drape":
        check_drape_zone(scenario, o.zone_x_m, where)
        return
    end = o.x_m + o.width_m
    if not prof.x[0] < o.x_m < end < prof.x[-1]:
        raise MeasureError(f"{where}: x_m = {o.x_m:g} m + width_m = {o.width_m:g} m spans {o.x_m:g}-{end:g} m, "
                           f"outside the profile ({prof.x[0]:g}, {prof.x[-1]:g}) m")
    m = SlopeMeasure(o.kind, o.name, o.x_m, o.width_m, o.height_m, None, o.inner_slope_hv, o.outer_slope_hv,
                     o.material)
    scenario_with_measures(scenario, [m], where=str(path), road_collector=hz.road_collector)
