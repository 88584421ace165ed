"""The design block: event volume kept apart from the block that hits a barrier.

A laser-scanning or road-maintenance inventory records *event volumes*: the
volume that detached.  A large detachment breaks up on the way down, so the
block a fence must stop is not the event volume.  Practice fixes the design
block by a rule, stated with the result:

``percentile``
    The p-th percentile of a block-size distribution, by default the 97th
    (ONR 24810:2021 sets the design block as the P95-P98 of the block-size
    distribution, depending on event frequency; as summarised in Natural
    Hazards 2024, doi 10.1007/s11069-024-06432-4, which also notes that deposit
    surveys under-represent small blocks, De Biagi et al. 2017, pushing these
    percentiles up).  The sizes come from a block survey file
    (``survey``); without one, the inventory's own sizes stand in, and when the
    inventory records event volumes that substitution is an ASSUMPTION stated
    in every output (event volumes overstate blocks).
``return_period``
    The T-year fall of the site's magnitude-frequency law (truncated at the
    maximum credible block, rate scaled to the share of the source above the
    line): m_T with rate x P(M > m_T) = 1/T (Wyllie 2014, 8.4.1).  It treats a
    detached volume as one intact block: an upper bound.

``fragmentation``
    The T-year event volume broken up by a fractal fragmentation step (Perfect
    1997, Eng. Geol. 48:185-198; the model behind the rock fall fractal
    fragmentation model of Ruiz-Carulla, Corominas and Mavrouli 2017,
    Landslides 14:875-889, here without their in-situ block-size initiators and
    survival rate): the detached volume splits into b^3 = 8 equal blocks, each
    of which splits again with probability p = b^(D - 3) for ``iterations``
    generations, so that the number of fragments larger than a size L grows as
    L^-D (D the fractal dimension).  The design block is the chosen percentile,
    by count, of the fragment volumes.  D and the number of generations are
    the user's stated ASSUMPTIONS (calibrate them on a deposit survey).

:func:`design_block` computes the chosen block and the alternatives side by
side (the ONR 24810 band, the T-year fall at the source and at the line), each
with its volume, equivalent-sphere diameter and the energy it carries at the
95th-percentile speed of simulated blocks of its own mass.
:func:`site_design_masses` is the design-mass table of the site's law (the
hazard's), never above its stated m_max.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..frequency.inventory.reader import SIZES  # one home: what an inventory's sizes can be
from ..core.format import sig
from ..core.units import DEFAULT_DENSITY_KG_M3, DESIGN_RETURN_PERIODS, kinetic_energy_kj

#: The percentile band of ONR 24810:2021 for the design block [%].
ONR24810_PERCENTILES = (95.0, 98.0)
RULES = ("percentile", "return_period", "fragmentation")


def resolve_sizes(stated, inventory=None) -> str:
    """What the inventory's sizes are: ``stated`` (site file ``inventory.sizes`` or ``--inventory-sizes``) when
    given, else the inventory sidecar's ``sizes``, else ``"event_volumes"`` (the default: a detached volume is taken
    as one block, an upper bound).

    Parameters
    ----------
    stated : str or None
        ``"event_volumes"`` or ``"blocks"`` as stated by the user.
    inventory : Inventory, optional
        The inventory (its sidecar's ``sizes``).

    Returns
    -------
    str
    """
    if stated is not None:
        return stated
    return getattr(inventory, "sizes", None) or "event_volumes"


def sphere_diameter_m(volume_m3):
    """Diameter [m] of the sphere of the given volume [m³]: d = (6 V / pi)^(1/3).

    Parameters
    ----------
    volume_m3 : float or array_like
        Volume [m³].

    Returns
    -------
    numpy.ndarray
        Diameter [m].
    """
    return (6.0 * np.asarray(volume_m3, dtype=float) / np.pi) ** (1.0 / 3.0)


def check_percentile(percentile, where: str = "percentile") -> float:
    """A percentile strictly between 0 and 100 [%].

    Parameters
    ----------
    percentile : float
        The value [%].
    where : str
        The argument or field, for the message.

    Returns
    -------
    float
    """
    if isinstance(percentile, bool) or not isinstance(percentile, (int, float, np.integer, np.floating)):
        raise TypeError(f"{where} = {percentile!r} must be a number between 0 and 100 (exclusive)")
    p = float(percentile)
    if not 0.0 < p < 100.0:
        raise ValueError(f"{where} = {percentile!r} must lie strictly between 0 and 100 (ONR 24810: 95-98)")
    return p


def percentile_block(volumes_m3, percentile: float = 97.0) -> float:
    """The ``percentile``-th percentile [m³] of block volumes (ONR 24810 design block, 95th-98th).

    Parameters
    ----------
    volumes_m3 : array_like
        Block volumes [m³].
    percentile : float
        Percentile [%], in (0, 100).

    Returns
    -------
    float
        Volume [m³].

    References
    ----------
    ONR 24810:2021, Technischer Steinschlagschutz (Austrian Standards): design block the 95th-98th percentile of the
    block sizes.
    """
    p = check_percentile(percentile)
    v = np.asarray(volumes_m3, dtype=float).ravel()
    if v.size == 0:
        raise ValueError("the block survey is empty")
    bad = ~np.isfinite(v) | (v <= 0)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"block volume [{i}] = {float(v[i])!r}: block sizes must be finite and > 0 m3")
    return float(np.percentile(v, p))


def read_block_survey(path, density_kg_m3: float, *, sheet=None, header_row: int | None = None,
                      decimal: str | None = None, encoding: str | None = None) -> np.ndarray:
    """Block volumes [m³] from a survey file with a volume (m³, dm³, l, cm³) or mass (kg, t) column.

    Read by the rules of :mod:`riskrf.io.tables` shared by every table riskrf reads: CSV/TXT with
    any separator (``#`` comment lines skipped), Excel (``sheet``, ``header_row``) or Parquet;
    decimal commas decided per column (``decimal`` overrides); UTF-8 with or without BOM, else
    cp1252.  Empty rows are skipped.  Errors name the file and the column, or the row (file
    line) and the value.

    Parameters
    ----------
    path : str or path
        The survey file.
    density_kg_m3 : float
        Rock density [kg/m³] converting masses to volumes.
    sheet, header_row, decimal, encoding : optional
        Table-reading options (:func:`riskrf.io.tables.read_table`).

    Returns
    -------
    numpy.ndarray
        Block volumes [m³].
    """
    from ..frequency.inventory.reader import _MASS_NAMES, _MASS_UNITS, _VOLUME_NAMES, _VOLUME_UNITS, _find_column
    from ..io.tables import is_blank, parse_numbers, read_table
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"block survey not found: {path}")
    text = path.suffix.lower() in (".csv", ".txt", ".tsv")
    df, first, _ = read_table(path, sheet=sheet, header_row=header_row, encoding=encoding, what="block survey",
                              comment="#" if text else None)
    col, unit = _find_column(df.columns, _VOLUME_NAMES, _VOLUME_UNITS)
    factor = None
    if col is not None:
        factor = _VOLUME_UNITS[unit or "m3"]
    else:
        col, unit = _find_column(df.columns, _MASS_NAMES, _MASS_UNITS)
        if col is None:          # a column named only "block" holds masses when nothing else does (not ids first)
            col, unit = _find_column(df.columns, {"block"}, _MASS_UNITS)
        if col is not None:
            factor = _MASS_UNITS[unit or "kg"] / float(density_kg_m3)
    if col is None:
        raise ValueError(f"{path}: no block-size column; expected a volume (e.g. 'volume_m3') or mass (e.g. "
                         f"'mass_kg') column, found {list(map(str, df.columns))}")
    rows = np.arange(len(df)) + first
    keep = ~is_blank(df).to_numpy() if len(df) else np.ones(0, bool)
    df, rows = df[keep].reset_index(drop=True), rows[keep]
    if df.empty:
        raise ValueError(f"{path}: the block survey has no rows")
    values = parse_numbers(df[col], path, col, rows, decimal=decimal).to_numpy(dtype=float)
    bad = ~np.isfinite(values) | (values <= 0)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{path}: row {rows[i]}, column {col!r}: value {df[col].iloc[i]} is not a block size > 0")
    return values * factor


def fractal_fragments(volume_m3: float, fractal_dimension: float, iterations: int, branching: int = 2
                      ) -> pd.DataFrame:
    """Expected fragments of a detached volume [m³] by fractal fragmentation (Perfect 1997).

    Generation k (1..``iterations``) holds blocks of volume V / b^(3k) (b = ``branching``).  Each block of
    generation k < ``iterations`` splits again with probability p = b^(D - 3); the others stay as fragments,
    so the expected number of fragments of generation k is b^(3k) p^(k-1) (1 - p) (k < iterations) and
    b^(3 iterations) p^(iterations - 1) for the last; successive counts grow by b^D and the volumes add to V.

    Parameters
    ----------
    volume_m3 : float
        Detached volume V [m³].
    fractal_dimension : float
        Fractal dimension D [-] (< 3).
    iterations : int
        Generations of splitting.
    branching : int
        Splits per edge b (each block into b³).

    Returns
    -------
    pandas.DataFrame
        One row per generation: ``generation``, ``volume_m3`` per fragment, ``count`` (expected),
        ``volume_share``.

    References
    ----------
    Perfect, E. (1997). Fractal models for the fragmentation of rocks and soils: a review. Engineering Geology
    48(3-4), 185-198.
    """
    v0 = float(volume_m3)
    if not np.isfinite(v0) or v0 <= 0:
        raise ValueError(f"volume_m3 = {volume_m3!r} must be finite and > 0 m3")
    D = fractal_dimension
    if isinstance(D, bool) or not isinstance(D, (int, float, np.integer, np.floating)) or not 0.0 < float(D) < 3.0:
        raise ValueError(f"design_block.fractal_dimension = {D!r} must lie strictly between 0 and 3 "
                         "(N(>L) ~ L^-D; rock fragmentation typically 2-3)")
    n = iterations
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= 12:
        raise ValueError(f"design_block.iterations = {n!r} must be a whole number of fragmentation generations "
                         "between 1 and 12")
    b = int(branching)
    p = float(b) ** (float(D) - 3.0)
    k = np.arange(1, n + 1)
    count = float(b) ** (3.0 * k) * p ** (k - 1.0) * np.where(k < n, 1.0 - p, 1.0)
    vol = v0 / float(b) ** (3.0 * k)
    return pd.DataFrame({"generation": k, "volume_m3": vol, "count": count, "volume_share": count * vol / v0})


def fragment_percentile(fragments: pd.DataFrame, percentile: float) -> float:
    """The fragment volume [m³] at ``percentile`` (by count) of a :func:`fractal_fragments` table.

    Parameters
    ----------
    fragments : pandas.DataFrame
        A :func:`fractal_fragments` table.
    percentile : float
        Percentile [%] by count.

    Returns
    -------
    float
        Volume [m³].
    """
    q = check_percentile(percentile) / 100.0
    f = fragments.sort_values("volume_m3")
    cdf = np.cumsum(f["count"].to_numpy()) / f["count"].sum()
    return float(f["volume_m3"].to_numpy()[min(np.searchsorted(cdf, q), len(f) - 1)])


@dataclass(frozen=True)
class DesignBlock:
    """The design block and its alternatives.

    Attributes
    ----------
    rule : "percentile" or "return_period"
    mass_kg, volume_m3, diameter_m : the chosen block [kg, m³, m (equivalent sphere)]
    basis : how it was obtained (rule, source of the sizes)
    assumptions : statements that are judgement, to be repeated in every output
    alternatives : one row per candidate rule (``chosen`` marks the design block): mass, volume, diameter,
        the p95 speed [m/s] of simulated blocks of that mass at the line and the energy 1/2 m v95^2 [kJ]
    inputs : the keyword arguments of :func:`design_block` that produced it (without the hazard), so that the
        same rule can be re-applied to another hazard (the design-energy tornado)
    """

    rule: str
    mass_kg: float
    volume_m3: float
    diameter_m: float
    basis: str
    assumptions: tuple
    alternatives: pd.DataFrame
    inputs: dict = field(default_factory=dict, repr=False, compare=False)

    def summary(self) -> pd.DataFrame:
        """The chosen design block (one-column table): rule, mass [kg], volume [m3], equivalent sphere diameter [m],
        basis and each assumption.

        Returns
        -------
        pandas.DataFrame
            Index: quantity; column ``value``.
        """
        rows = {"rule": self.rule, "design block mass [kg]": self.mass_kg, "volume [m3]": self.volume_m3,
                "equivalent sphere diameter [m]": self.diameter_m, "basis": self.basis}
        for i, a in enumerate(self.assumptions):
            rows[f"assumption {i + 1}"] = a
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def to_dict(self) -> dict:
        """The design block and its alternatives as a JSON-ready dict (mass_kg, volume_m3, diameter_m, ...).

        Returns
        -------
        dict
        """
        return {"rule": self.rule, "mass_kg": self.mass_kg, "volume_m3": self.volume_m3,
                "diameter_m": self.diameter_m, "basis": self.basis, "assumptions": list(self.assumptions),
                "alternatives": self.alternatives.to_dict(orient="records")}


def line_return_period_mass(hazard, T) -> np.ndarray:
    """The T-year block reaching the line [kg]: rate x P(M > m, reaches) = 1/T (mass-coupled reach), NaN when
    fewer than one fall a T years reaches it.

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard (mass law, rate, reach by mass).
    T : float or array_like
        Return period [yr].

    Returns
    -------
    numpy.ndarray
        Mass [kg].
    """
    from .mass_models import mass_model
    T = np.atleast_1d(np.asarray(T, dtype=float))
    mm = mass_model(hazard.mass)
    if not hazard.mass_coupled:
        p = 1.0 / (T * hazard.rate_per_year * hazard.reach_probability)
        return np.where(p < 1, mm.isf(np.minimum(p, 1.0)), np.nan)
    from scipy import optimize
    vel = hazard.velocity
    lo, hi = (float(v) for v in mm.support)
    lo = lo if np.isfinite(lo) and lo > 0 else float(mm.isf(1.0 - 1e-12))
    hi = hi if np.isfinite(hi) else float(mm.isf(1e-15))
    rate = hazard.rate_per_year

    def g(lm, target):
        return np.log(max(rate * vel.arrival_sf(np.exp(lm), mm), 1e-300)) - np.log(target)
    out = np.full(T.size, np.nan)
    for i, t in enumerate(T):
        a, b = np.log(lo) - 1e-9, np.log(hi) * (1 - 1e-12)
        if g(a, 1.0 / t) > 0 > g(b, 1.0 / t):
            out[i] = np.exp(optimize.brentq(g, a, b, args=(1.0 / t,), xtol=1e-12))
    return out


def _law_text(hazard) -> str:
    """The site's mass law in words, numbers without exponent notation."""
    m = hazard.mass
    if hasattr(m, "b") and hasattr(m, "m_min"):
        return (f"power law b = {sig(m.b)} above {sig(m.m_min)} kg"
                + (f", truncated at m_max = {sig(m.m_max)} kg" if getattr(m, "m_max", None) else ", not truncated")
                + f", {sig(hazard.rate_per_year)} falls/yr")
    from .mass_models import mass_model
    return f"{mass_model(m).description}, {sig(hazard.rate_per_year)} falls/yr"


def site_design_masses(hazard, T=DESIGN_RETURN_PERIODS,
                       density_kg_m3: float = DEFAULT_DENSITY_KG_M3) -> pd.DataFrame:
    """Design masses [kg] of the site's law (the hazard's: truncated at m_max, rate scaled to the source above the
    line): the T-year fall at the source and the T-year fall reaching the line; NaN where fewer than one such fall
    is expected in T years.  Never above the law's m_max.

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard.
    T : sequence of float
        Return periods [yr].
    density_kg_m3 : float
        Rock density [kg/m³].

    Returns
    -------
    pandas.DataFrame
        ``T_years``, the source and line masses [kg] and volumes [m³].
    """
    from .mass_models import mass_model
    T = np.atleast_1d(np.asarray(T, dtype=float))
    mm = mass_model(hazard.mass)
    p = 1.0 / (T * hazard.rate_per_year)
    source = np.where(p < 1, mm.isf(np.minimum(p, 1.0)), np.nan)
    line = line_return_period_mass(hazard, T)
    return pd.DataFrame({"T_years": T, "source_mass_kg": source, "source_volume_m3": source / density_kg_m3,
                         "line_mass_kg": line, "line_volume_m3": line / density_kg_m3,
                         "law": _law_text(hazard)})


def design_block(hazard, *, rule: str = "return_period", percentile: float = 97.0, survey_volumes_m3=None,
                 survey_source: str | None = None, inventory=None, sizes: str = "event_volumes",
                 design_T: float = 100.0, density_kg_m3: float = DEFAULT_DENSITY_KG_M3,
                 fractal_dimension: float | None = None,
                 iterations: int | None = None) -> DesignBlock:
    """The design block by ``rule`` with its alternatives (see module notes).

    Parameters
    ----------
    hazard : EnergyHazard (its mass law and rate are the site's; mass-coupled speeds give each block's v95)
    rule : "percentile", "return_period" or "fragmentation"
    percentile : float in (0, 100) [%], the percentile of the block sizes (ONR 24810: 95-98)
    survey_volumes_m3 : array of block volumes [m³] from a block survey, optional
    survey_source : name of the survey (file) for the outputs
    inventory : Inventory whose recorded sizes stand in for a block survey when none is given
    sizes : "event_volumes" or "blocks": what the inventory's sizes are
    design_T : return period [yr] of the return-period block
    density_kg_m3 : rock density [kg/m³]
    fractal_dimension, iterations : parameters of the fragmentation step (:func:`fractal_fragments`); needed for
        ``rule="fragmentation"``, shown as an alternative whenever given

    Returns
    -------
    DesignBlock
        The chosen block (mass [kg], volume [m³], diameter [m]) with its alternatives and assumptions.

    References
    ----------
    ONR 24810:2021, Technischer Steinschlagschutz (Austrian Standards): design block the 95th-98th percentile of the
    block sizes.
    """
    from ..core.validation import check_choice, check_positive
    inputs = dict(rule=rule, percentile=percentile, survey_volumes_m3=survey_volumes_m3, survey_source=survey_source,
                  inventory=inventory, sizes=sizes, design_T=design_T, density_kg_m3=density_kg_m3,
                  fractal_dimension=fractal_dimension, iterations=iterations)
    check_choice(rule, "design_block.rule", RULES)
    check_choice(sizes, "inventory sizes", SIZES)
    pct = check_percentile(percentile, "design_block.percentile")
    rho = check_positive(density_kg_m3, "density_kg_m3")
    T = check_positive(design_T, "design_T")
    survey, source, assumptions = _block_sizes(survey_volumes_m3, survey_source, inventory, sizes, rule)
    fragmenting, stated = _check_rule_arguments(rule, survey, fractal_dimension, iterations)
    assumptions += stated
    if sizes == "event_volumes":
        assumptions.append("the inventory records event volumes; the return-period block treats a detached volume "
                           "as one intact block (an upper bound)")
    coupled = bool(getattr(hazard, "mass_coupled", False))
    alt = _alternatives(hazard, coupled, survey, source, pct, T, rho,
                        (fractal_dimension, iterations) if fragmenting else None)
    row = _chosen_row(alt, hazard, coupled, rule, pct, T)
    basis = _basis(rule, pct, T, source, fractal_dimension, iterations)
    return DesignBlock(rule=rule, mass_kg=float(row["mass_kg"]), volume_m3=float(row["volume_m3"]),
                       diameter_m=float(row["diameter_m"]), basis=basis, assumptions=tuple(assumptions),
                       alternatives=alt, inputs=inputs)


def _block_sizes(survey_volumes_m3, survey_source, inventory, sizes: str, rule: str):
    """The block sizes the percentile rule reads: the block survey, else the inventory's own sizes.

    Parameters
    ----------
    survey_volumes_m3, survey_source, inventory, sizes, rule
        As in :func:`design_block`.

    Returns
    -------
    tuple
        (block volumes [m³] or None, their source in words or None, the list of assumptions the substitution
        makes: the inventory's event volumes standing in for blocks under the percentile rule).
    """
    if survey_volumes_m3 is not None:
        return np.asarray(survey_volumes_m3, dtype=float), f"block survey {survey_source or ''}".strip(), []
    if inventory is None:
        return None, None, []
    volumes = inventory.masses / inventory.density_kg_m3
    kind = "event volumes" if sizes == "event_volumes" else "block sizes"
    source = f"inventory {Path(str(inventory.source)).name} ({kind})"
    assumptions = []
    if sizes == "event_volumes" and rule == "percentile":
        assumptions.append("ASSUMPTION: no block survey; the percentile is taken of the inventory's EVENT "
                           "volumes, which overstate the blocks that reach a barrier (detachments break up)")
    return volumes, source, assumptions


def _check_rule_arguments(rule: str, survey, fractal_dimension, iterations):
    """Check, before any work, what the rule needs: both fragmentation parameters (valid) for the fragmentation
    rule or whenever one is given, and block sizes (``survey``) for the percentile rule.

    Parameters
    ----------
    rule, fractal_dimension, iterations
        As in :func:`design_block`.
    survey : numpy.ndarray or None
        Block volumes [m³] (:func:`_block_sizes`).

    Returns
    -------
    tuple
        (True when fragmentation parameters are stated, the list of assumptions they make).
    """
    fragmenting = fractal_dimension is not None or iterations is not None
    if rule == "fragmentation" and not fragmenting:
        raise ValueError("design_block.rule = 'fragmentation' needs design_block.fractal_dimension and "
                         "design_block.iterations (the user's stated fragmentation parameters)")
    assumptions = []
    if fragmenting:
        fractal_fragments(1.0, fractal_dimension, iterations)        # checks both parameters before any work
        assumptions.append(f"ASSUMPTION: fragmentation parameters stated, not calibrated: fractal dimension "
                           f"D = {sig(fractal_dimension)}, {iterations} generation(s) (Perfect 1997)")
    if rule == "percentile" and survey is None:
        raise ValueError("design_block.rule = 'percentile' needs a block survey (design_block.survey) or an "
                         "inventory whose sizes stand in for one")
    return fragmenting, assumptions


def _alternative(hazard, coupled: bool, density_kg_m3: float, name: str, mass: float, note: str) -> dict:
    """One row of the alternatives table: the candidate ``name`` of ``mass`` [kg].

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard (speeds of blocks of that mass).
    coupled : bool
        Whether the hazard is mass-coupled (a mass outside its simulated masses is labelled).
    density_kg_m3 : float
        Rock density [kg/m³].
    name, note : str
        The candidate and where it comes from.
    mass : float
        Mass [kg], NaN when undefined.

    Returns
    -------
    dict
        ``rule``, ``mass_kg``, ``volume_m3``, ``diameter_m`` (equivalent sphere), ``velocity_p95_ms``,
        ``energy_at_v95_kj`` and ``note``.
    """
    v95 = hazard.velocity_percentile(95, mass_kg=mass) if np.isfinite(mass) else np.nan
    if coupled and np.isfinite(mass) and not hazard.velocity.contains(mass):
        note += "; outside the simulated masses (nearest class's speeds)"
    volume = mass / density_kg_m3
    return {"rule": name, "mass_kg": mass, "volume_m3": volume, "diameter_m": float(sphere_diameter_m(volume)),
            "velocity_p95_ms": v95, "energy_at_v95_kj": kinetic_energy_kj(mass, v95), "note": note}


def _alternatives(hazard, coupled: bool, survey, source, pct: float, T: float, rho: float,
                  fragmentation) -> pd.DataFrame:
    """The candidate design blocks side by side: the ONR 24810 percentile band of the block sizes (when there
    are any), the T-year fall at the source and reaching the line, the fragments of the T-year fall (when
    fragmentation is stated) and the maximum credible block (when stated).

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard.
    coupled : bool
        Whether it is mass-coupled.
    survey, source
        Block volumes [m³] and their source (:func:`_block_sizes`), or None.
    pct, T, rho : float
        Percentile [%], return period [yr], rock density [kg/m³].
    fragmentation : tuple or None
        (fractal dimension D, generations) when stated.

    Returns
    -------
    pandas.DataFrame
        One :func:`_alternative` row per candidate.
    """
    rows = []

    def add(name, mass, note):
        rows.append(_alternative(hazard, coupled, rho, name, mass, note))

    if survey is not None:
        for q in sorted(set(ONR24810_PERCENTILES) | {pct}):
            add(f"percentile p{q:g}", percentile_block(survey, q) * rho,
                f"{source}; ONR 24810 band 95-98" + (" (chosen percentile)" if q == pct else ""))
    table = site_design_masses(hazard, [T], rho)
    source_kg = float(table["source_mass_kg"].iloc[0])
    add(f"return period {T:g} yr at the source", source_kg, "site law: " + str(table["law"].iloc[0]))
    add(f"return period {T:g} yr reaching the line", float(table["line_mass_kg"].iloc[0]),
        "site law x reach probability by mass" if hazard.mass_coupled else "site law x one reach probability")
    if fragmentation is not None and np.isfinite(source_kg):
        D, n = fragmentation
        mass, frags = _fragment_of(source_kg, D, n, pct, rho)
        add(f"fragmentation of the {T:g}-yr event, p{pct:g}", mass,
            f"fractal fragmentation (Perfect 1997), D = {sig(D)}, {n} generation(s): "
            f"{sig(frags['count'].sum())} fragments; percentile by count")
    m_max = getattr(hazard.mass, "m_max", None)
    if m_max:
        add("maximum credible block m_max", float(m_max), "stated by the user (judgement); the upper bound")
    return pd.DataFrame(rows)


def _chosen_row(alt: pd.DataFrame, hazard, coupled: bool, rule: str, pct: float, T: float) -> pd.Series:
    """Mark the block ``rule`` chooses (column ``chosen``) and label the alternatives above m_max, in ``alt``;
    refuse a chosen block that is undefined, outside the simulated masses (mass-coupled hazard) or above m_max.

    Parameters
    ----------
    alt : pandas.DataFrame
        The alternatives (:func:`_alternatives`), changed in place.
    hazard : EnergyHazard
        The hazard (its simulated masses and m_max).
    coupled : bool
        Whether it is mass-coupled.
    rule, pct, T
        The rule, percentile [%] and return period [yr].

    Returns
    -------
    pandas.Series
        The chosen row.
    """
    chosen = {"percentile": f"percentile p{pct:g}", "return_period": f"return period {T:g} yr at the source",
              "fragmentation": f"fragmentation of the {T:g}-yr event, p{pct:g}"}[rule]
    alt["chosen"] = alt["rule"] == chosen
    row = alt.loc[alt["chosen"]].iloc[0]
    if not np.isfinite(row["mass_kg"]):
        raise ValueError(f"the {T:g}-year block is undefined: fewer than one fall a {T:g} years at this rate")
    if coupled and not hazard.velocity.contains(row["mass_kg"]):
        lo, hi = hazard.velocity.edges_kg[0], hazard.velocity.edges_kg[-1]
        raise ValueError(f"design block {sig(row['mass_kg'], 4)} kg ({row['rule']}) lies outside the simulated masses "
                         f"{sig(lo, 4)} - {sig(hi, 4)} kg: its speeds would be the nearest mass class's, not its own.  "
                         "Choose a design-block rule or parameters whose block lies in that range, or simulate a "
                         "range that includes it (energy_hazard(..., design_masses_kg=[mass]); riskrf energy and "
                         "riskrf assess include the design-block candidates, fragmentation too, by themselves)")
    m_max = getattr(hazard.mass, "m_max", None)
    if m_max:
        above = alt["mass_kg"] > m_max * (1 + 1e-12)
        alt.loc[above, "note"] = alt.loc[above, "note"] + "; ABOVE the stated maximum credible block m_max"
        if row["mass_kg"] > m_max * (1 + 1e-12):
            raise ValueError(f"design block {row['mass_kg']:.6g} kg ({row['rule']}) exceeds the stated maximum "
                             f"credible block m_max = {m_max:.6g} kg: revise m_max or the design-block rule")
    return row


def _basis(rule: str, pct: float, T: float, source, fractal_dimension, iterations) -> str:
    """How the design block was obtained, in words: the rule, the source of the sizes, the parameters.

    Parameters
    ----------
    rule, pct, T, source, fractal_dimension, iterations
        The rule, percentile [%], return period [yr], source of the block sizes and fragmentation parameters.

    Returns
    -------
    str
    """
    if rule == "percentile":
        return (f"{pct:g}th percentile of the block sizes ({source}), after ONR 24810 (design block: 95th-98th "
                "percentile of the surveyed blocks)")
    if rule == "fragmentation":
        return (f"{pct:g}th percentile (by count) of the fragments of the {T:g}-year event volume broken up by "
                f"fractal fragmentation (Perfect 1997; D = {sig(fractal_dimension)}, {iterations} generation(s))")
    return (f"{T:g}-year fall of the site's law (truncated at m_max, rate scaled to the source above the line), "
            "taken as one intact block")


def design_block_candidates_kg(*, rule, percentile, survey_volumes_m3, inventory, density_kg_m3) -> list:
    """Masses [kg] the design-block rule can pick before the hazard exists (the percentile band), so that the
    simulated mass range can include them.

    Parameters
    ----------
    rule : str
        The design-block rule.
    percentile : float
        Percentile [%].
    survey_volumes_m3 : array_like or None
        Block-survey volumes [m³].
    inventory : Inventory or None
        The inventory standing in for a survey.
    density_kg_m3 : float
        Rock density [kg/m³].

    Returns
    -------
    list of float
        Masses [kg].
    """
    out = []
    if survey_volumes_m3 is not None:
        vols = np.asarray(survey_volumes_m3, dtype=float)
    elif inventory is not None:
        vols = inventory.masses / inventory.density_kg_m3
    else:
        return out
    for q in sorted(set(ONR24810_PERCENTILES) | {check_percentile(percentile, "design_block.percentile")}):
        out.append(percentile_block(vols, q) * density_kg_m3)
    return out


def fragment_block_kg(law, rate_per_year: float, *, design_T: float, fractal_dimension, iterations,
                      percentile: float, density_kg_m3: float) -> float | None:
    """Mass [kg] of the fragmentation alternative of :func:`design_block` from the site's law alone (before the
    hazard is simulated): the ``percentile`` fragment of the ``design_T``-year fall at the source.  None when no
    fragmentation is stated or fewer than one such fall is expected; so that the simulated mass range can
    include it.

    Parameters
    ----------
    law : mass model
        The site's mass law [kg].
    rate_per_year : float
        Falls per year it describes [1/yr].
    design_T : float
        Return period [yr].
    fractal_dimension : float or None
        Fractal dimension D [-].
    iterations : int or None
        Generations of splitting.
    percentile : float
        Percentile [%] of the fragments by count.
    density_kg_m3 : float
        Rock density [kg/m³].

    Returns
    -------
    float or None
        Mass [kg].
    """
    if fractal_dimension is None or iterations is None:
        return None
    from .mass_models import mass_model
    p = 1.0 / (float(design_T) * float(rate_per_year))
    if not p < 1:
        return None
    return _fragment_of(float(mass_model(law).isf(p)), fractal_dimension, iterations, percentile, density_kg_m3)[0]


def _fragment_of(source_kg, fractal_dimension, iterations, percentile, density_kg_m3):
    """(mass [kg] of the ``percentile`` fragment, the fragments table) of a fall of ``source_kg`` broken up by
    fractal fragmentation: the one computation behind the design block's fragmentation rule and
    :func:`fragment_block_kg`."""
    frags = fractal_fragments(source_kg / density_kg_m3, fractal_dimension, iterations)
    return fragment_percentile(frags, percentile) * density_kg_m3, frags


__all__ = ["DesignBlock", "ONR24810_PERCENTILES", "design_block", "design_block_candidates_kg", "fractal_fragments",
           "fragment_block_kg",
           "fragment_percentile",
           "line_return_period_mass", "percentile_block", "read_block_survey", "resolve_sizes", "site_design_masses",
           "sphere_diameter_m"]
