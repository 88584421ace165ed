"""Named slope materials (presets) from published ranges, usable in scenario files.

A material table in a scenario may name a preset and override any of its fields::

    [materials.apron]
    preset = "talus"                    # every field below is optional
    ground_friction_angle_deg = 40      # replaces the preset's value
    tangential = { std_deg = 2 }        # merged into the preset's tangential table

A field given beside a preset replaces the preset's value; a table given beside a
preset (``normal_restitution``, ``tangential``) is merged into the preset's table
when it names no ``law`` or the same law, and replaces it when it names another
law (or is a number or a law name).  An unknown preset is an error naming the
file, the material and the closest preset name.

The presets
-----------
Values are starting points for the substrate, to be calibrated to the site
(Wyllie 2014, ch. 5 and 7; Rocscience RocFall help: library values "are only a
start"); the README table repeats this one.  The evidence tags say how each
number was checked: **[V]** quoted in ``research/rockfall-simulation.md`` from a
retrieved source; **[R]** recalled from the named source and not re-checked
against its text here -- verify before relying on it; **[D]** a derived or chosen
value, with its reasoning.

========== ============================ ======================== ======== ====================
preset     normal restitution e_N       tangential law            rough-   rolling-resistance
                                                                  ness [m] angle phi_g [deg]
========== ============================ ======================== ======== ====================
bedrock    Wyllie law 19.5 theta^-1.03  Stronge, friction 30 +- 3 0.10     22
talus      Wyllie law                   e_T 0.55 +- 0.12          0.30     38
scree      constant 0.33 +- 0.03        e_T 0.55 +- 0.12          0.15     36
colluvium  constant 0.29 +- 0.02        e_T 0.55 +- 0.12          0.20     33
soil       constant 0.28 +- 0.03        e_T 0.55 +- 0.12          0.10     33
meadow     constant 0.23 +- 0.02        e_T 0.55 +- 0.12          0.05     38
asphalt    Wyllie law                   Stronge, friction 30 +- 2 0.02     14
concrete   Wyllie law                   Stronge, friction 30 +- 2 0.02     12
========== ============================ ======================== ======== ====================

All presets roll (``ground_motion = "roll"``).  Aliases: ``rock`` = bedrock, ``road`` = asphalt, ``vegetated_soil`` and ``grass`` = meadow,
``debris`` = colluvium.

Sources of each column:

* **e_N, hard and coarse surfaces (bedrock, talus, asphalt, concrete): Wyllie's law.**
  Wyllie (2014, IJRMMS 67:170-180; *Rock Fall Engineering* ch. 5) back-analysed
  rock falls at five sites "involving impacts on rock, talus, colluvium, asphalt and
  concrete" and found e_N related to the impact angle "essentially independent of the
  slope material" [V].  So these presets use the law, not a typed constant.
* **e_N, fine and vegetated ground (constants; Rockyfor3D soil types, Dorren 2016,
  "Rockyfor3D (v5.2) revealed", table of R_n by soil type)** [R]: scree (diameter
  < ~10 cm) or medium-compact soil with small boulders 0.33 (0.30-0.36); fine soil,
  depth < ~100 cm, 0.28 (0.25-0.31); fine soil, depth > ~100 cm (soft, meadow),
  0.23 (0.21-0.25).  Colluvium 0.29 (0.28-0.30): the CRSP 3 "colluvium lower
  foreslope" normal coefficients 0.28/0.29/0.30 (min/mean/max) of a Colorado permit
  table [V].  The spreads are the half-ranges / 2 (about two standard deviations span
  the published range).  These are RocFall/CRSP-style coefficients of the velocity
  components, the definition the ``constant`` law uses.
* **Tangential law, natural ground (talus, scree, colluvium, soil, meadow): Wyllie's
  e_T.**  Wyllie (2014) found "the tangential coefficient of restitution ranges between
  0.3 and 0.8 ... independent of the velocity and normal force" at his five sites [V];
  the presets use the constant law e_T = v_t'/v_t with mean 0.55 and standard
  deviation 0.12 (the range read as +- 2 sd; the spin decays by the same factor).  A
  rough rotating sphere (Stronge's law) that is already rolling loses nothing at a
  shallow impact, while real blocks on talus and soil lose much of their tangential
  speed at every impact (shape, ploughing, breakage); with the Stronge law on talus,
  blocks falling 60 m stopped at a median shadow angle of 17 deg, far beyond what
  Evans & Hungr (1993) observed, and with e_T they stop where talus slopes show
  (README, "Shadow angles") [D].
* **Tangential law, hard surfaces (bedrock, asphalt, concrete): Stronge's rough
  sphere** with the friction angle of rock surfaces, 25-35 deg (basic friction angle,
  Barton & Choubey 1977; Wyllie & Mah 2004, table 4.1) [R]; pavements 30 deg [D] (a
  dry road surface; it decides only whether an impact sticks or slips).
* **Roughness** [D]: the asperity amplitude seen by a 0.5-1 m block: coarse talus
  boulders 0.3 m (Rockyfor3D roughness classes MOH 0.1-0.5 m on talus, Dorren 2016
  [R]), bedrock 0.1 m, scree and colluvium 0.15-0.2 m, soil 0.1 m, meadow 0.05 m,
  pavements 0.02 m.
* **Rolling-resistance angle phi_g** (the ground contact law: a rolling sphere
  decelerates as 5/7 g (tan phi_g cos psi - sin psi), and stays at rest where
  psi <= phi_g).  Talus slopes stand at the dynamic angle of repose of their debris,
  about 32-38 deg (Kirkby & Statham 1975, J. Geol. 83:349; Statham 1976; Evans &
  Hungr 1993, CGJ 30:620, talus slopes of 30-38 deg) [R]; blocks must be able to stop
  on them, so the talus value, 38 deg, is above the steepest usual talus (35 deg) [D];
  scree 36 deg likewise.  Soil, colluvium and meadow 33-38 deg: rolling resistance of
  a block indenting soft ground (Dorren 2003, Progr. Phys. Geogr. 27:69, rolling
  friction coefficients of soil and vegetated surfaces of order 0.5-0.8) [R].
  Bedrock 22 deg and pavements 12-14 deg: hard surfaces, low rolling resistance
  (RocFall derives a friction angle from R_t as arctan((1 - R_t) / R_t) [V], 10 deg for
  its bedrock R_t of 0.85 [R]; the values here are above that because a lumped sphere
  on a rough rock face also loses energy to small impacts that the profile does not
  resolve) [D].
"""
from __future__ import annotations

import copy
import difflib

from .errors import RiskrfError

#: Wyllie's tangential coefficient on natural ground: e_T = v_t'/v_t in 0.3-0.8 (Wyllie 2014, IJRMMS 67:170,
#: "independent of the velocity and normal force") read as mean +- 2 standard deviations.
WYLLIE_ET = {"law": "constant", "mean": 0.55, "std": 0.12}

#: Named materials: each value is a scenario material table (the fields of ``[materials.NAME]``).
PRESETS: dict[str, dict] = {
    "bedrock": {"normal_restitution": {"law": "wyllie"},
                "tangential": {"law": "friction", "friction_angle_deg": 30.0, "std_deg": 3.0},
                "roughness_m": 0.10, "ground_motion": "roll", "ground_friction_angle_deg": 22.0},
    "talus": {"normal_restitution": {"law": "wyllie"},
              "tangential": WYLLIE_ET,
              "roughness_m": 0.30, "ground_motion": "roll", "ground_friction_angle_deg": 38.0},
    "scree": {"normal_restitution": {"law": "constant", "mean": 0.33, "std": 0.03},
              "tangential": WYLLIE_ET,
              "roughness_m": 0.15, "ground_motion": "roll", "ground_friction_angle_deg": 36.0},
    "colluvium": {"normal_restitution": {"law": "constant", "mean": 0.29, "std": 0.02},
                  "tangential": WYLLIE_ET,
                  "roughness_m": 0.20, "ground_motion": "roll", "ground_friction_angle_deg": 33.0},
    "soil": {"normal_restitution": {"law": "constant", "mean": 0.28, "std": 0.03},
             "tangential": WYLLIE_ET,
             "roughness_m": 0.10, "ground_motion": "roll", "ground_friction_angle_deg": 33.0},
    "meadow": {"normal_restitution": {"law": "constant", "mean": 0.23, "std": 0.02},
               "tangential": WYLLIE_ET,
               "roughness_m": 0.05, "ground_motion": "roll", "ground_friction_angle_deg": 38.0},
    "asphalt": {"normal_restitution": {"law": "wyllie"},
                "tangential": {"law": "friction", "friction_angle_deg": 30.0, "std_deg": 2.0},
                "roughness_m": 0.02, "ground_motion": "roll", "ground_friction_angle_deg": 14.0},
    "concrete": {"normal_restitution": {"law": "wyllie"},
                 "tangential": {"law": "friction", "friction_angle_deg": 30.0, "std_deg": 2.0},
                 "roughness_m": 0.02, "ground_motion": "roll", "ground_friction_angle_deg": 12.0},
}

#: Other names accepted for a preset.
ALIASES = {"rock": "bedrock", "road": "asphalt", "vegetated_soil": "meadow", "grass": "meadow",
           "debris": "colluvium"}

#: One line per preset: the sources of its values (see the module docstring for the full table).
SOURCES = {
    "bedrock": "e_N: Wyllie (2014) impact-angle law [V]; friction: basic friction angle of rock 25-35 deg "
               "(Barton & Choubey 1977) [R]; roughness, rolling resistance: chosen [D]",
    "talus": "e_N: Wyllie (2014) law, fitted on impacts including talus [V]; e_T 0.3-0.8 (Wyllie 2014) [V]; "
             "rolling resistance above the 30-38 deg angle of repose of talus (Kirkby & Statham 1975; Evans & "
             "Hungr 1993) so blocks can stop on it [R/D]; roughness: Rockyfor3D talus classes (Dorren 2016) [R]",
    "scree": "e_N 0.33 (0.30-0.36): Rockyfor3D soil type 'scree or medium compact soil with small boulders' "
             "(Dorren 2016) [R]; e_T 0.3-0.8 (Wyllie 2014) [V]; rolling resistance: angle of repose [R/D]",
    "colluvium": "e_N 0.29 (0.28-0.30): CRSP 3 colluvium lower foreslope, Colorado permit table [V]; e_T 0.3-0.8 (Wyllie 2014) [V]; rolling "
                 "resistance: soft ground (Dorren 2003) [R]",
    "soil": "e_N 0.28 (0.25-0.31): Rockyfor3D 'fine soil, depth < 100 cm' (Dorren 2016) [R]; e_T 0.3-0.8 (Wyllie 2014) [V]; rolling resistance: "
            "soft ground (Dorren 2003) [R]",
    "meadow": "e_N 0.23 (0.21-0.25): Rockyfor3D 'fine soil, depth > 100 cm' (Dorren 2016) [R]; e_T 0.3-0.8 (Wyllie 2014) [V]; rolling "
              "resistance: vegetated soft ground (Dorren 2003) [R]",
    "asphalt": "e_N: Wyllie (2014) law, fitted on impacts including asphalt [V]; rolling resistance: hard "
               "surface [D]",
    "concrete": "e_N: Wyllie (2014) law, fitted on impacts including concrete [V]; rolling resistance: hard "
                "surface [D]",
}


class PresetError(RiskrfError, ValueError):
    """An unknown preset or a preset given in a wrong form; the message names the file and material."""


def preset_names() -> list[str]:
    """Names of the presets (without aliases).

    Returns
    -------
    list of str
        Sorted preset names.
    """
    return sorted(PRESETS)


def data_basis_presets() -> list[str]:
    """Names of the presets that have a data-derived table (``basis = "data"``): those with fitted contact laws
    or posterior fields in ``simulation/preset_priors.py``.

    Returns
    -------
    list of str
        Sorted preset names.
    """
    from . import preset_priors
    return sorted(set(getattr(preset_priors, "LAWS", {})) | set(_data_priors()))


def _no_data_table(name: str, where: str, source: str) -> str:
    return (f"{source}: {where} = {name!r} has no data-derived table, so preset_basis = 'data' cannot apply to it "
            f"(it would silently give the published values); presets with one: {', '.join(data_basis_presets())}. "
            "Use preset_basis = 'published' for this material, or calibrate it to data (riskrf calibrate)")


def preset(name: str, basis: str = "published") -> dict:
    """A deep copy of the material table of preset ``name`` (aliases accepted).

    Parameters
    ----------
    name : str
        Preset name or alias.
    basis : {"published", "data"}
        ``"published"`` (default): the values of :data:`PRESETS` (published ranges, the table above).
        ``"data"``: the table the data-derived priors were fitted with -- the preset's table with the contact laws
        of ``simulation.preset_priors.LAWS`` put over it (Coulomb-bounded e_T with Pfeiffer & Bowen's
        normal-velocity scaling, hop heights, the size term of the rolling resistance) -- and every field fitted
        to real data (:func:`preset_prior`) replaced by its posterior median; fields no data set constrains keep
        their published values.  A preset without a data-derived table (:func:`data_basis_presets`) is
        refused under ``"data"``, never silently given its published values.

    Returns
    -------
    dict
        A scenario material table (point values).

    Raises
    ------
    PresetError
        An unknown name or basis, or ``basis="data"`` for a preset without a data-derived table.
    """
    key = ALIASES.get(name, name)
    if key not in PRESETS:
        raise PresetError(_unknown(name, "preset", "<preset()>"))
    if basis not in ("published", "data"):
        raise PresetError(f"<preset()>: basis = {basis!r} must be 'published' or 'data'")
    if basis == "data" and key not in data_basis_presets():
        raise PresetError(_no_data_table(name, "preset", "<preset()>"))
    out = copy.deepcopy(PRESETS[key])
    if basis == "data":
        from . import preset_priors
        for field, value in getattr(preset_priors, "LAWS", {}).get(key, {}).items():
            out[field] = copy.deepcopy(value)
        for field, stat in _data_priors().get(key, {}).items():
            holder = out
            parts = field.split(".")
            for p in parts[:-1]:
                holder = holder[p]
            holder[parts[-1]] = float(stat["median"])
    return out


def parameter_materials(name: str) -> tuple:
    """The materials a dotted parameter ``materials.NAME.FIELD`` sets: ``(NAME,)``, or for a shared parameter
    ``materials.A+B.FIELD`` (one value put into the same field of several materials) ``(A, B)``; ``()`` for a
    name that is not a material field.

    Parameters
    ----------
    name : str
        The dotted parameter name.

    Returns
    -------
    tuple of str
    """
    parts = str(name).split(".")
    if len(parts) < 3 or parts[0] != "materials":
        return ()
    return tuple(parts[1].split("+"))


def material_parameter(name: str, material: str) -> str:
    """The single-material name of the shared parameter ``name`` for ``material`` (``materials.A+B.FIELD`` ->
    ``materials.A.FIELD``).

    Parameters
    ----------
    name : str
        A dotted material parameter (:func:`parameter_materials`).
    material : str
        One of its materials.

    Returns
    -------
    str
    """
    _, _, field = str(name).split(".", 2)
    return f"materials.{material}.{field}"


def parameter_sets_any(name: str, materials) -> bool:
    """True when the dotted parameter ``name`` sets a field of at least one of ``materials`` (names).

    Parameters
    ----------
    name : str
        A dotted parameter (:func:`parameter_materials`).
    materials : collection of str
        Material names (a scenario's ``materials`` table, a list, ...).

    Returns
    -------
    bool
    """
    return any(m in materials for m in parameter_materials(name))


def _data_priors() -> dict:
    """preset -> {field (dotted, inside the material table): posterior summary} from simulation/preset_priors.py;
    a parameter shared by several presets (``materials.A+B.FIELD``) is a field of each of them."""
    from . import preset_priors
    out: dict = {}
    for path, stat in preset_priors.SUMMARY.items():
        field = path.split(".", 2)[2]
        for mat in parameter_materials(path):
            out.setdefault(mat, {})[field] = stat
    return out


def preset_prior(name: str):
    """The spread of preset ``name``'s values: one row per field, data-derived where a data set constrains it.

    Fields fitted jointly to real data (``validation/presets/derive_presets.py``: the Authume quarry
    releases P1 and P2, Garcia et al. 2022, and the minimum shadow angle of talus slopes, Evans & Hungr 1993)
    carry their posterior mean, sd, median and 90 % interval (``basis = "data"``); the other numeric fields carry
    the published point value (``basis = "published"``) and, for e_N and e_T, the published spread as ``sd``
    (that spread is the impact-to-impact variability of the law, not an uncertainty of the mean).

    Parameters
    ----------
    name : str
        Preset name or alias.

    Returns
    -------
    pandas.DataFrame
        Index ``field`` (dotted, inside the material table); columns ``basis``, ``published`` (the value of
        :data:`PRESETS`), ``mean``, ``sd``, ``median``, ``q05``, ``q95``, ``datasets``.

    References
    ----------
    Garcia, B. et al. (2022) Engineering Geology 310:106855. Evans, S.G. & Hungr, O. (1993) Can. Geotech. J.
    30:620-636.
    """
    import pandas as pd
    from . import preset_priors
    key = ALIASES.get(name, name)
    if key not in PRESETS:
        raise PresetError(_unknown(name, "preset", "<preset_prior()>"))
    p = PRESETS[key]
    data = _data_priors().get(key, {})
    rows = []
    flat = {"ground_friction_angle_deg": p["ground_friction_angle_deg"], "roughness_m": p["roughness_m"]}
    for tab in ("normal_restitution", "tangential"):
        for k, v in p[tab].items():
            if isinstance(v, (int, float)) and not k.startswith("std"):
                flat[f"{tab}.{k}"] = v
    for field, value in flat.items():
        if field in data:
            st = data[field]
            rows.append({"field": field, "basis": "data", "published": value, "mean": st["mean"], "sd": st["sd"],
                         "median": st["median"], "q05": st["q05"], "q95": st["q95"],
                         "datasets": ", ".join(preset_priors.DATASETS)})
        else:
            tab = field.split(".")[0] if "." in field else None
            sd = float("nan")
            if tab and field.endswith(".mean") and "std" in p[tab]:
                sd = float(p[tab]["std"])
            elif tab and field.endswith("friction_angle_deg") and "std_deg" in p[tab]:
                sd = float(p[tab]["std_deg"])
            rows.append({"field": field, "basis": "published", "published": value, "mean": value, "sd": sd,
                         "median": value, "q05": float("nan"), "q95": float("nan"), "datasets": ""})
    for field, st in data.items():            # fitted fields the published table leaves at the scenario default
        if field not in flat:
            rows.append({"field": field, "basis": "data", "published": p.get(field, FIELD_DEFAULTS.get(field)),
                         "mean": st["mean"], "sd": st["sd"], "median": st["median"], "q05": st["q05"],
                         "q95": st["q95"], "datasets": ", ".join(preset_priors.DATASETS)})
    return pd.DataFrame(rows).set_index("field")


#: The default of a material field no preset sets (simulation.scenario.Material reads it from here): what the
#: published basis uses for a field the data-derived presets fit (the size law of the rolling resistance, the
#: spread of phi_g between blocks).
FIELD_DEFAULTS = {"rolling_size_coefficient": 0.0, "rolling_size_exponent": 1.0, "ground_friction_std_deg": 0.0}


def _unknown(name, where: str, source: str) -> str:
    options = sorted(PRESETS) + sorted(ALIASES)
    close = difflib.get_close_matches(str(name), options, n=1, cutoff=0.5)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return (f"{source}: {where} = {name!r} is not a known material preset{hint} "
            f"(presets: {', '.join(sorted(PRESETS))}; aliases: {', '.join(sorted(ALIASES))})")


def _merge_table(base, override):
    """Merge a law table given beside a preset into the preset's table (see the module docstring)."""
    if isinstance(override, dict) and isinstance(base, dict):
        if "law" not in override or override.get("law") == base.get("law", override.get("law")):
            out = dict(base)
            out.update(override)
            return out
    return copy.deepcopy(override)


def resolve_material(spec: dict, where: str = "materials.?", source: str = "<dict>") -> dict:
    """The material table ``spec`` with its ``preset`` (if any) expanded and its own fields applied on top.

    ``where`` names the table (e.g. ``"materials.apron"``) and ``source`` the file, for error messages.
    A table without ``preset`` is returned unchanged (a copy).  ``preset_basis = "data"`` beside ``preset``
    starts from the data-derived table (:func:`preset` with ``basis="data"``: the fitted contact laws and the
    posterior medians) instead of the published values.

    Parameters
    ----------
    spec : dict
        A material table of a scenario.
    where : str, optional
        Name of the table, for error messages.
    source : str, optional
        The scenario file, for error messages.

    Returns
    -------
    dict
        The expanded material table (a copy).
    """
    if not isinstance(spec, dict):
        raise PresetError(f"{source}: {where} must be a table of material fields; got {spec!r}")
    if "preset" not in spec:
        return copy.deepcopy(spec)
    name = spec["preset"]
    if not isinstance(name, str):
        raise PresetError(f"{source}: {where}.preset must be a preset name (a string); got {name!r}")
    key = ALIASES.get(name, name)
    if key not in PRESETS:
        raise PresetError(_unknown(name, f"{where}.preset", source))
    basis = spec.get("preset_basis", "published")
    if basis not in ("published", "data"):
        raise PresetError(f"{source}: {where}.preset_basis = {basis!r} must be 'published' (the preset's published "
                          "values, the default) or 'data' (the data-derived table of preset(name, basis='data'))")
    if basis == "data" and key not in data_basis_presets():
        raise PresetError(_no_data_table(name, f"{where}.preset", source))
    out = preset(key, basis=basis)
    for field, value in spec.items():
        if field in ("preset", "preset_basis"):
            continue
        out[field] = _merge_table(out[field], value) if field in out else copy.deepcopy(value)
    return out


def resolve_materials(data: dict, source: str = "<dict>") -> dict:
    """A copy of a scenario dictionary with every material preset expanded.

    Parameters
    ----------
    data : dict
        A parsed scenario dictionary.
    source : str, optional
        The scenario file, for error messages.

    Returns
    -------
    dict
        A copy of ``data`` with every preset expanded.
    """
    out = copy.deepcopy(data)
    mats = out.get("materials")
    if isinstance(mats, dict):
        for name, spec in mats.items():
            if isinstance(spec, dict):
                mats[name] = resolve_material(spec, f"materials.{name}", source)
    return out


def presets_table():
    """The presets as a DataFrame: one row per preset with its fields and sources.

    Returns
    -------
    pandas.DataFrame
        One row per preset, indexed by ``preset``.
    """
    import pandas as pd
    rows = []
    for name in sorted(PRESETS):
        p = PRESETS[name]
        en, et = p["normal_restitution"], p["tangential"]
        rows.append({"preset": name,
                     "normal_restitution": "wyllie" if en["law"] == "wyllie" else
                     f"{en['mean']:.2f} +- {en.get('std', 0):.2f}",
                     "tangential": (f"Stronge, friction {et['friction_angle_deg']:g} +- {et.get('std_deg', 0):g} deg"
                                    if et["law"] == "friction" else
                                    f"e_T {et['mean']:.2f} +- {et.get('std', 0):.2f}"),
                     "roughness_m": p["roughness_m"], "ground_motion": p["ground_motion"],
                     "ground_friction_angle_deg": p["ground_friction_angle_deg"], "sources": SOURCES[name]})
    return pd.DataFrame(rows).set_index("preset")
