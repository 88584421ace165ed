"""The corridor's mass law and rates of falls: fitted or typed mass law, inventory rates, the shared rate.

``[mass]`` gives the mass law (fitted to an inventory or typed, an ASSUMPTION); a section's rate comes from
its own column or inventory, or from its share (by km of road or m2 of rock face) of a corridor-wide
``[rates]`` inventory.  Masses kg, rates per year, lengths m, areas m2.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...core.file_schemas import CORRIDOR_MASS, CORRIDOR_RATES
from .model import CorridorError, _unknown


def _face_area(num: dict, length_m: float, where: str, what: str) -> float:
    """Rock-face area [m2] of a section: length x the face's slope length (height / sin angle)."""
    if "cut_height_m" not in num or "face_angle_deg" not in num:
        raise CorridorError(f"{where}: {what} needs cut_height_m and face_angle_deg (the face area is the section "
                            "length x the face's slope length)")
    return length_m * num["cut_height_m"] / math.sin(math.radians(num["face_angle_deg"]))


@dataclass(frozen=True)
class SharedRate:
    """A corridor-wide rate of falls (:func:`_shared_rate`): ``rate`` of the ``[rates]`` inventory [1/yr] (falls >=
    the corridor's m_min), ``share`` ('km': by section length, 'm2': by rock-face area), ``covered`` (km of road or
    m2 of face the inventory covers; None: the sharing sections together) and ``note`` (how the rate was
    obtained)."""
    rate: float
    share: str
    covered: float | None
    note: str


def _shared_rate(table, base: Path, m_min_kg: float, source: str) -> SharedRate | None:
    """``[rates]``: a corridor-wide inventory shared among the sections that give no rate of their own, in
    proportion to their length (``share = "km"``) or rock-face area (``share = "m2"``).  ``covered_length_km`` /
    ``covered_face_area_m2``: what the inventory covers (default: the sharing sections together).
    Returns None (no ``[rates]`` table) or the :class:`SharedRate`."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise CorridorError(f"{source}: rates = {table!r} must be a table ([rates] with inventory = ...)")
    _unknown(table, {f.name for f in CORRIDOR_RATES.fields}, "rates.", source)
    r = CORRIDOR_RATES.record(table)
    if r.inventory is None:
        raise CorridorError(f"{source}: [rates] needs inventory = \"file\" (the corridor-wide inventory)")
    share = r.share
    if share not in ("km", "m2"):
        raise CorridorError(f"{source}: rates.share = {share!r} must be 'km' (by section length) or 'm2' (by "
                            "rock-face area)")
    key, cov, other, other_value = (("covered_length_km", r.covered_length_km, "covered_face_area_m2",
                                     r.covered_face_area_m2) if share == "km" else
                                    ("covered_face_area_m2", r.covered_face_area_m2, "covered_length_km",
                                     r.covered_length_km))
    if other_value is not None:
        raise CorridorError(f"{source}: rates.{other} does not apply with share = {share!r} (give {key})")
    if cov is not None and (isinstance(cov, bool) or not isinstance(cov, (int, float)) or not cov > 0):
        raise CorridorError(f"{source}: rates.{key} = {cov!r} must be a number > 0")
    inv_path = (base / str(r.inventory)).resolve()
    rate, note = inventory_rate(inv_path, m_min_kg, f"{source}: rates.inventory = {r.inventory!r}")
    return SharedRate(rate=rate, share=share, covered=None if cov is None else float(cov), note=note)


def _mass_law(table: dict, base: Path, source: str):
    """The corridor's mass law: fitted to an inventory file, or typed (b, m_min_kg, m_max_kg; an ASSUMPTION).

    ``table`` is the ``[mass]`` table as written, read into its typed record once its field names are checked."""
    from ...frequency.power_law import GutenbergRichterFit, fit_gutenberg_richter
    _unknown(table, {f.name for f in CORRIDOR_MASS.fields}, "mass.", source)
    m = CORRIDOR_MASS.record(table)
    for k, v in (("m_min_kg", m.m_min_kg), ("m_max_kg", m.m_max_kg), ("b", m.b)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0):
            raise CorridorError(f"{source}: mass.{k} = {v!r} must be a number > 0")
    if m.inventory is not None:
        if m.b is not None:
            raise CorridorError(f"{source}: give mass.inventory (fitted) or mass.b (typed), not both")
        from ...frequency.inventory.reader import read_inventory
        inv_path = (base / m.inventory).resolve()
        if not inv_path.exists():
            raise CorridorError(f"{source}: mass.inventory = {m.inventory!r}: file not found ({inv_path})")
        inv = read_inventory(inv_path)
        gr = fit_gutenberg_richter(inv.masses, inv.duration_years, m_min=m.m_min_kg, m_max=m.m_max_kg)
        note = (f"mass law fitted to {inv_path.name}: b = {gr.b:.3g} +- {gr.b_stderr:.2g}, m_min = {gr.m_min:.4g} kg "
                f"({gr.n_tail} falls)")
        return gr, note
    if m.b is None or m.m_min_kg is None:
        raise CorridorError(f"{source}: [mass] needs inventory = \"file\" (fitted) or b and m_min_kg (typed)")
    b, m_min, m_max = float(m.b), float(m.m_min_kg), m.m_max_kg
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

    from ...frequency.inventory.reader import read_inventory
    from ...frequency.power_law import fit_gutenberg_richter
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
