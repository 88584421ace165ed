"""Scenario tables and their dotted parameters (``materials.talus.ground_friction_angle_deg``): read a scenario
as tables, check material names, set one or several parameters.  The lowest layer of the calibration wing: the
single-scenario calibration (:mod:`simulation.calibration`), the pooled one (:mod:`simulation.pooled`) and the
material uncertainty (:mod:`simulation.material_uncertainty`) all build on it, so none of them imports another
for these helpers (no import circle).  Lengths in m, angles in degrees, as the scenario tables give them.
"""
from __future__ import annotations

import copy
import difflib
import tomllib
from pathlib import Path

import numpy as np

from .materials import material_parameter, parameter_materials
from .scenario import Scenario, ScenarioError, scenario_from_dict


def scenario_dict(scenario) -> tuple[dict, str]:
    """The dictionary form of a scenario given as a path, a dict or a Scenario loaded from a TOML file.

    Parameters
    ----------
    scenario : str, path, dict or Scenario
        The scenario.

    Returns
    -------
    tuple of (dict, str)
        Its tables and its source (file name or ``"<dict>"``).
    """
    if isinstance(scenario, (str, Path)):
        path = Path(scenario)
        if not path.exists():
            raise FileNotFoundError(f"scenario file not found: {path}")
        with open(path, "rb") as fh:
            try:
                return tomllib.load(fh), str(path)
            except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:   # a binary file: named, not a bare codec error
                raise ScenarioError(f"{path}: not valid TOML: {exc}") from exc
    if isinstance(scenario, dict):
        return copy.deepcopy(scenario), "<dict>"
    if isinstance(scenario, Scenario):
        path = Path(scenario.source)
        if not path.is_file():
            raise TypeError(f"scenario {scenario.name!r} was not loaded from a file ({scenario.source!r}); pass its "
                            "TOML path or the dictionary it was built from")
        data, src = scenario_dict(path)
        again = scenario_from_dict(data, source=src, base_dir=path.parent)
        if not (np.array_equal(again.profile.x, scenario.profile.x) and again.materials == scenario.materials
                and again.seeder == scenario.seeder):
            raise ValueError(f"scenario {scenario.name!r} differs from its file {path} (changed after loading?); "
                             "pass the dictionary it was built from")
        return data, src
    raise TypeError(f"scenario must be a TOML path, a dict or a Scenario; got {type(scenario).__name__}")


def _did_you_mean(key, options) -> str:
    close = difflib.get_close_matches(str(key), [str(o) for o in options], n=1)
    return f"; did you mean {close[0]!r}?" if close else f"; available: {', '.join(map(str, options))}"


def check_material_names(names) -> None:
    """Refuse a shared parameter with an empty material (``materials.a+.x``) and two parameters that set the same
    field of the same material (``materials.a+b.x`` beside ``materials.a.x``: whichever was set last would win).

    Parameters
    ----------
    names : iterable of str
        Dotted parameter names.

    Raises
    ------
    ValueError
        Naming the parameter(s).
    """
    seen = {}
    for name in names:
        mats = parameter_materials(name)
        if mats and not all(mats):
            raise ValueError(f"parameter {name!r}: an empty material name in {str(name).split('.')[1]!r} (use "
                             "'materials.A+B.FIELD')")
        for m in mats:
            key = material_parameter(name, m)
            if seen.setdefault(key, name) != name:
                raise ValueError(f"parameters {seen[key]!r} and {name!r} both set {key!r}")


def set_parameter(data: dict, name: str, value: float, *, source: str | None = None) -> None:
    """Set the value at dotted path ``name`` in a scenario dictionary (in place).

    Tables along the path must exist up to the material (``materials.NAME``);
    a missing last field (a default) or a missing law table (e.g.
    ``normal_restitution.mean`` where the file gives ``normal_restitution =
    0.35``) is created.  ``collectors.NAME.FIELD`` addresses a collector by name.
    ``materials.A+B.FIELD`` is one value shared by several materials: it is set in each of A, B that the scenario
    defines (at least one must be).

    Parameters
    ----------
    data : dict
        Scenario tables, changed in place.
    name : str
        Dotted path, e.g. ``"materials.talus.ground_friction_angle_deg"``.
    value : float
        The value, in the field's unit.
    source : str, optional
        The scenario file (or other origin) named in error messages.
    """
    where = f"{source}: " if source else ""
    parts = name.split(".")
    if len(parts) < 2 or any(not p for p in parts):
        raise ValueError(f"{where}parameter {name!r}: use a dotted path such as "
                         "'materials.talus.ground_friction_angle_deg'")
    shared = parameter_materials(name)
    if len(shared) > 1:
        defined = data.get("materials") or {}
        check_material_names([name])
        if not any(m in defined for m in shared):
            raise ValueError(f"{where}parameter {name!r}: the scenario defines none of the materials "
                             f"{list(shared)} (materials: {sorted(defined)})")
        for m in shared:
            if m in defined:
                set_parameter(data, material_parameter(name, m), value, source=source)
        return
    node = data
    for depth, key in enumerate(parts[:-1]):
        if isinstance(node, list):          # [[collectors]]: address by name
            named = {str(item.get("name")): item for item in node if isinstance(item, dict)}
            if key not in named:
                raise ValueError(f"{where}parameter {name!r}: no entry named {key!r} in "
                                 f"{'.'.join(parts[:depth])}{_did_you_mean(key, list(named))}")
            node = named[key]
            continue
        if key not in node:
            if depth < 2:
                raise ValueError(f"{where}parameter {name!r}: no table {'.'.join(parts[:depth + 1])!r} in the "
                                 f"scenario{_did_you_mean(key, list(node))}")
            node[key] = {}
        elif not isinstance(node[key], (dict, list)):
            current = node[key]
            if isinstance(current, str):                 # a law name: normal_restitution = "wyllie"
                node[key] = {"law": current}
            elif isinstance(current, (int, float)) and not isinstance(current, bool):
                node[key] = {"law": "constant", "mean": current}   # a constant coefficient
            else:
                raise ValueError(f"{where}parameter {name!r}: {'.'.join(parts[:depth + 1])} is {current!r}, "
                                 "not a table")
        node = node[key]
    if not isinstance(node, dict):
        raise ValueError(f"{where}parameter {name!r}: {'.'.join(parts[:-1])} is not a table")
    node[parts[-1]] = float(value)


def apply_parameters(data: dict, values: dict, *, source: str | None = None) -> dict:
    """A deep copy of the scenario dictionary with each dotted path set to its value.

    Parameters
    ----------
    data : dict
        Scenario tables (not changed).
    values : dict
        Dotted path → value (in the field's unit).
    source : str, optional
        The scenario, named in errors.

    Returns
    -------
    dict
    """
    out = copy.deepcopy(data)
    for k, v in values.items():
        set_parameter(out, k, v, source=source)
    return out


__all__ = ["apply_parameters", "check_material_names", "scenario_dict", "set_parameter"]
