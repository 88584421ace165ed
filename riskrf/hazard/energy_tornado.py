"""One-way sensitivity (tornado) of the design energies behind ``riskrf energy`` and ``riskrf assess``.

:func:`design_energy_tornado` moves each judgement or uncertain input (maximum credible block m_max, rate share,
power-law exponent b, fractal dimension and fragmentation generations of the design block, velocity percentile)
to its low and high value with the others at base, and re-evaluates the T-year energy at the line, the
design-block energy and the fragmentation alternative's energy on the same simulated slope
(:meth:`~riskrf.hazard.annual_hazard.EnergyHazard.with_mass`; nothing is re-simulated).  The result,
:class:`DesignEnergyTornado`, holds the table with its summary, dominant inputs, text and JSON form; its figure is
drawn by :func:`riskrf.report.fit_figures.plot_design_energy_tornado`.  The energy analysis that carries it is in
:mod:`riskrf.hazard.energy_study`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from .annual_hazard import EnergyHazard
from .mass_models import mass_model
from .barriers import UNI11211_FACTORS
from ..frequency.power_law import fit_gutenberg_richter
from ..core.format import sig
from ..core.units import kinetic_energy_kj


#: Default ranges of the one-way sensitivity where the user states none (typed, labelled in every output).
TORNADO_DEFAULTS = {"m_max_factors": (0.5, 2.0), "rate_share_factors": (0.5, 2.0),
                    "velocity_percentile_range": (90.0, 99.0), "fractal_dimension_step": 0.25,
                    "iterations_step": 1}



@dataclass(frozen=True)
class DesignEnergyTornado:
    """One-way sensitivity of the design energies: each input at its low and high value, the others at base.

    Attributes
    ----------
    table : DataFrame, one row per (design energy, input): ``design_energy`` (which energy the row moves),
        ``input``, ``unit`` (of low/base/high), ``low``, ``base``, ``high``, ``range_basis`` (where low and high
        come from), ``energy_low_kj``, ``energy_base_kj``, ``energy_high_kj`` (the design energy with the input at
        low, base and high) and ``swing_kj`` (|high - low|); rows of one design energy sorted by swing.
    design_T : return period [yr] of the T-year energy
    notes : what was left out and why
    """

    table: pd.DataFrame
    design_T: float
    notes: tuple = ()

    def summary(self) -> pd.DataFrame:
        """The tornado table: one row per input and design energy; low/high inputs and the energy [kJ] at each.

        Returns
        -------
        pandas.DataFrame
        """
        return self.table

    @property
    def design_energies(self) -> list:
        """The design energies studied, in order (the T-year energy at the line first)."""
        return list(dict.fromkeys(self.table["design_energy"]))

    def dominant(self) -> pd.DataFrame:
        """Per design energy: the input with the largest swing [kJ], its low-high energies and its share of the
        sum of swings.

        Returns
        -------
        pandas.DataFrame
        """
        rows = []
        for name in self.design_energies:
            sub = self.table[self.table["design_energy"] == name]
            if not np.isfinite(sub["swing_kj"]).any():
                continue
            r = sub.loc[sub["swing_kj"].idxmax()]
            total = float(np.nansum(sub["swing_kj"]))
            rows.append({"design_energy": name, "input": r["input"], "energy_base_kj": r["energy_base_kj"],
                         "energy_low_kj": r["energy_low_kj"], "energy_high_kj": r["energy_high_kj"],
                         "swing_kj": r["swing_kj"], "share_of_swings": r["swing_kj"] / total if total > 0 else np.nan})
        return pd.DataFrame(rows)

    def text(self) -> str:
        """The table for a terminal, numbers by :func:`sig`.

        Returns
        -------
        str
        """
        lines = []
        for name in self.design_energies:
            sub = self.table[self.table["design_energy"] == name]
            lines.append(f"  {name} (base {sig(sub['energy_base_kj'].iloc[0], 4)} kJ):")
            for _, r in sub.iterrows():
                lines.append(f"    {r['input']:<52s} {_value(r['low'], r['unit']):>12s} -> "
                             f"{sig(r['energy_low_kj'], 4):>9s} kJ"
                             f"   {_value(r['high'], r['unit']):>12s} -> {sig(r['energy_high_kj'], 4):>9s} kJ"
                             f"   swing {sig(r['swing_kj'], 3)} kJ   [{r['range_basis']}]")
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The tornado as a JSON-ready dict: design return period [yr], rows, dominant inputs and notes.

        Returns
        -------
        dict
        """
        return {"design_T_years": self.design_T, "rows": self.table.to_dict(orient="records"),
                "dominant": self.dominant().to_dict(orient="records"), "notes": list(self.notes)}


#: Unit label of a dimensionless input in the tornado table.
NO_UNIT = "dimensionless"



def _value(v, unit) -> str:
    return f"{sig(v, 4)} {unit}".strip() if unit not in (NO_UNIT, "") else sig(v, 4)



def _pair(values, name, check):
    """(low, high) of a range argument, each checked by ``check(value, f"{name}[i]")``."""
    try:
        lo, hi = values
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {values!r} must be a pair (low, high)") from None
    return check(lo, f"{name}[0]"), check(hi, f"{name}[1]")



def _positive(v, name) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) \
            or not (np.isfinite(v) and v > 0):
        raise ValueError(f"{name} = {v!r} must be a finite number > 0")
    return float(v)



def design_energy_tornado(hazard: EnergyHazard, *, design_T: float = 100.0, block=None, masses_kg=None,
                          duration_years: float | None = None, m_max_range=None, rate_share: float = 1.0,
                          rate_share_range=None, velocity_percentile: float | None = None,
                          velocity_percentile_range=None, fractal_dimension_range=None, iterations_range=None,
                          sensitivity: pd.DataFrame | None = None,
                          rate_label: str = "rate share of the source above the line") -> DesignEnergyTornado:
    """One-way sensitivity (tornado) of the design energies [kJ] to the judgement and uncertain inputs.

    Design energies (each row says which one it moves):

    * the T-year energy at the barrier line, ``hazard.energy_at_return_period(design_T)``;
    * the design-block energy 1/2 m v_p^2 of ``block`` (:class:`~riskrf.hazard.design_block.DesignBlock`), v_p the
      ``velocity_percentile`` speed (default the UNI 11211-4 95th) of blocks of its mass at the line;
    * when fragmentation parameters are stated but another rule chose the block: the fragmentation
      alternative's energy 1/2 m v_p^2, its own output.

    Inputs, each at low and high with the others at base; every row is a re-evaluation of the same simulated
    slope (:meth:`EnergyHazard.with_mass`), nothing is re-simulated:

    * maximum credible block m_max [kg] (``m_max_range``; default x0.5 and x2 of the law's): the power law refitted
      to ``masses_kg`` over ``duration_years`` with that truncation (as
      :func:`~riskrf.hazard.energy_study.design_energy_sensitivity`), or, without the masses, re-truncated with b kept;
    * rate share [-] (``rate_share_range`` around ``rate_share``; default x0.5 and x2): the rate scaled (its row is
      named ``rate_label``: a rate from a rate model makes it a factor on the inventory's rate, not a share);
    * power-law exponent b [-] at the ends of the fit's interval ``hazard.mass.b_ci``: the law re-scaled with b
      fixed, the rate of falls above m_min kept;
    * fractal dimension D [-] and fragmentation generations (``fractal_dimension_range``, ``iterations_range``;
      default D +- 0.25, generations +- 1, typed): only when the block's fragmentation parameters are stated;
    * the velocity percentile [%] of the design-block energy (``velocity_percentile_range``, default 90 and 99).

    An input enters a row only where it enters that design energy: the velocity percentile does not enter the
    T-year energy (which integrates over every speed), and the law's inputs do not move a percentile block taken
    from a survey.  ``sensitivity``: a :func:`~riskrf.hazard.energy_study.design_energy_sensitivity` table whose
    T-year energies at (m_max, rate share) are reused instead of recomputed.

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard at the line.
    design_T : float
        Design return period [yr].
    block : DesignBlock, optional
        The design block.
    masses_kg : array_like, optional
        The inventory's masses [kg] (for refits with another m_max).
    duration_years : float, optional
        Its record length [yr].
    m_max_range : tuple of float, optional
        (low, high) maximum credible block [kg].
    rate_share : float
        Base rate share [-].
    rate_share_range : tuple of float, optional
        (low, high) rate share [-].
    velocity_percentile : float, optional
        Percentile [%] of the design-block speed (default 95).
    velocity_percentile_range : tuple of float, optional
        (low, high) percentile [%].
    fractal_dimension_range : tuple of float, optional
        (low, high) fractal dimension D [-].
    iterations_range : tuple of int, optional
        (low, high) fragmentation generations.
    sensitivity : pandas.DataFrame, optional
        A :func:`~riskrf.hazard.energy_study.design_energy_sensitivity` table to reuse.
    rate_label : str
        Name of the rate row.

    Returns
    -------
    DesignEnergyTornado
    """
    args = _check_tornado_arguments(hazard, design_T, block, masses_kg, duration_years, m_max_range, rate_share,
                                    rate_share_range, velocity_percentile, velocity_percentile_range,
                                    fractal_dimension_range, iterations_range)
    notes = []
    energies = _TornadoEnergies(hazard, block, args.inputs, sensitivity, args.T, notes)
    cases = _tornado_cases(hazard, args, rate_label, notes)
    return _tornado_table(hazard, block, args, cases, energies, notes)



@dataclass(frozen=True)
class _TornadoArguments:
    """The checked arguments of :func:`design_energy_tornado` with the defaults of their ranges filled in.

    Attributes
    ----------
    T : float
        Design return period [yr].
    share, s_lo, s_hi : float
        Base, low and high rate share [-].
    q, q_lo, q_hi : float
        Base, low and high velocity percentile [%].
    gr : GutenbergRichterFit or None
        The power law of the hazard's mass model (None when it is not a power-law fit).
    m_max : float or None
        The law's maximum credible block [kg].
    masses : numpy.ndarray or None
        The inventory's masses [kg] for refits.
    duration_years : float or None
        Their record length [yr].
    mm_lo, mm_hi : float or None
        Low and high maximum credible block [kg] (None: no m_max row).
    inputs : dict
        The design block's rule inputs (empty without a block).
    D, n_gen : float or int or None
        Stated fractal dimension [-] and fragmentation generations of the block.
    fragmenting : bool
        Whether both fragmentation parameters are stated.
    d_lo, d_hi, g_lo, g_hi : float or int or None
        Low and high fractal dimension [-] and generations (None unless ``fragmenting``).
    given : frozenset of str
        Names of the range arguments the caller gave (the others are typed defaults).
    """

    T: float
    share: float
    s_lo: float
    s_hi: float
    q: float
    q_lo: float
    q_hi: float
    gr: object
    m_max: float | None
    masses: np.ndarray | None
    duration_years: float | None
    mm_lo: float | None
    mm_hi: float | None
    inputs: dict
    D: float | None
    n_gen: int | None
    fragmenting: bool
    d_lo: float | None
    d_hi: float | None
    g_lo: int | None
    g_hi: int | None
    given: frozenset



def _check_tornado_arguments(hazard, design_T, block, masses_kg, duration_years, m_max_range, rate_share,
                             rate_share_range, velocity_percentile, velocity_percentile_range,
                             fractal_dimension_range, iterations_range) -> _TornadoArguments:
    """Check every argument of :func:`design_energy_tornado` before any work and fill in the default ranges.

    Parameters
    ----------
    hazard, design_T, block, masses_kg, duration_years, m_max_range, rate_share, rate_share_range, \
velocity_percentile, velocity_percentile_range, fractal_dimension_range, iterations_range
        As in :func:`design_energy_tornado` (units there).

    Returns
    -------
    _TornadoArguments

    Raises
    ------
    ValueError
        Naming the first bad argument and its value, in the order of the signature's checks.
    """
    from .design_block import check_percentile
    from ..core.validation import check_return_periods
    try:
        T = float(check_return_periods(design_T, "design_T"))
    except (TypeError, ValueError):
        raise ValueError(f"design_T = {design_T!r}: the design return period must be a finite number > 1 year") \
            from None
    share = _positive(rate_share, "rate_share")
    s_lo, s_hi = (_pair(rate_share_range, "rate_share_range", _positive) if rate_share_range is not None
                  else tuple(share * f for f in TORNADO_DEFAULTS["rate_share_factors"]))
    q = check_percentile(UNI11211_FACTORS["velocity_percentile"] if velocity_percentile is None
                         else velocity_percentile, "velocity_percentile")
    q_range = velocity_percentile_range if velocity_percentile_range is not None \
        else TORNADO_DEFAULTS["velocity_percentile_range"]
    q_lo, q_hi = _pair(q_range, "velocity_percentile_range", check_percentile)
    gr = mass_model(hazard.mass).power_law
    m_max = getattr(gr, "m_max", None)
    masses = None
    if masses_kg is not None:
        masses = np.asarray(masses_kg, dtype=float)
        duration_years = _positive(duration_years, "duration_years")
    mm_lo, mm_hi = _tornado_m_max_range(m_max_range, m_max, masses)
    inputs = dict(block.inputs) if block is not None else {}
    D, n_gen = inputs.get("fractal_dimension"), inputs.get("iterations")
    fragmenting = D is not None and n_gen is not None
    d_lo = d_hi = g_lo = g_hi = None
    if fragmenting:
        d_lo, d_hi, g_lo, g_hi = _tornado_fragmentation_ranges(D, n_gen, fractal_dimension_range,
                                                               iterations_range)
    given = frozenset(name for name, value in (
        ("m_max_range", m_max_range), ("rate_share_range", rate_share_range),
        ("velocity_percentile_range", velocity_percentile_range),
        ("fractal_dimension_range", fractal_dimension_range), ("iterations_range", iterations_range))
        if value is not None)
    return _TornadoArguments(T=T, share=share, s_lo=s_lo, s_hi=s_hi, q=q, q_lo=q_lo, q_hi=q_hi, gr=gr, m_max=m_max,
                             masses=masses, duration_years=duration_years, mm_lo=mm_lo, mm_hi=mm_hi, inputs=inputs,
                             D=D, n_gen=n_gen, fragmenting=fragmenting, d_lo=d_lo, d_hi=d_hi, g_lo=g_lo, g_hi=g_hi,
                             given=given)



def _tornado_m_max_range(m_max_range, m_max, masses):
    """Low and high maximum credible block [kg] of the tornado, given or typed.

    Parameters
    ----------
    m_max_range : tuple of float or None
        The caller's (low, high) [kg].
    m_max : float or None
        The law's maximum credible block [kg].
    masses : numpy.ndarray or None
        The inventory's masses [kg]: neither end may lie below the largest.

    Returns
    -------
    tuple
        (low, high) [kg], or (None, None) when the law is not truncated and no range is given.
    """
    mm_lo = mm_hi = None
    if m_max_range is not None:
        mm_lo, mm_hi = _pair(m_max_range, "m_max_range", _positive)
        if masses is not None:
            for i, v in enumerate((mm_lo, mm_hi)):
                if v < masses.max():
                    raise ValueError(f"m_max_range[{i}] = {v:g} kg is below the largest recorded mass "
                                     f"{masses.max():g} kg: a maximum credible block cannot be smaller")
    elif m_max:
        mm_lo, mm_hi = (m_max * f for f in TORNADO_DEFAULTS["m_max_factors"])
        if masses is not None:
            mm_lo = max(mm_lo, float(masses.max()))
    return mm_lo, mm_hi



def _tornado_fragmentation_ranges(D, n_gen, fractal_dimension_range, iterations_range):
    """Low and high fractal dimension [-] and fragmentation generations of the tornado, checked.

    Parameters
    ----------
    D : float
        The block's stated fractal dimension [-].
    n_gen : int
        Its stated fragmentation generations.
    fractal_dimension_range : tuple of float or None
        The caller's (low, high) D; None: D +- ``TORNADO_DEFAULTS["fractal_dimension_step"]`` kept inside (0, 3).
    iterations_range : tuple of int or None
        The caller's (low, high) generations; None: +- ``TORNADO_DEFAULTS["iterations_step"]`` kept in 1..12.

    Returns
    -------
    tuple
        (d_lo, d_hi, g_lo, g_hi).
    """
    from .design_block import fractal_fragments
    if fractal_dimension_range is not None:
        d_lo, d_hi = _pair(fractal_dimension_range, "fractal_dimension_range", _positive)
    else:
        step = TORNADO_DEFAULTS["fractal_dimension_step"]
        d_lo, d_hi = (D - step if D - step > 0 else D / 2), (D + step if D + step < 3 else (D + 3) / 2)
    for i, v in enumerate((d_lo, d_hi)):
        if not 0 < v < 3:
            raise ValueError(f"fractal_dimension_range[{i}] = {v!r} must lie strictly between 0 and 3")
    if iterations_range is not None:
        g_lo, g_hi = iterations_range
    else:
        g_lo, g_hi = max(1, n_gen - TORNADO_DEFAULTS["iterations_step"]), \
            min(12, n_gen + TORNADO_DEFAULTS["iterations_step"])
    for i, v in enumerate((g_lo, g_hi)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 1 <= v <= 12:
            raise ValueError(f"iterations_range[{i}] = {v!r} must be a whole number of generations from 1 to 12")
    fractal_fragments(1.0, d_lo, int(g_lo))
    fractal_fragments(1.0, d_hi, int(g_hi))
    return d_lo, d_hi, g_lo, g_hi



class _TornadoEnergies:
    """The design energies [kJ] of a tornado re-evaluated under a perturbed hazard.

    Parameters
    ----------
    hazard : EnergyHazard
        The base hazard at the line.
    block : DesignBlock or None
        The design block.
    inputs : dict
        Its rule inputs.
    sensitivity : pandas.DataFrame or None
        A :func:`~riskrf.hazard.energy_study.design_energy_sensitivity` table whose T-year energies are reused.
    T : float
        Design return period [yr].
    notes : list of str
        Where undefined design blocks are noted (appended to).
    """

    def __init__(self, hazard, block, inputs, sensitivity, T, notes):
        self.hazard, self.block, self.inputs, self.sensitivity, self.T, self.notes = \
            hazard, block, inputs, sensitivity, T, notes

    def t_energy(self, hz, key=None) -> float:
        """T-year energy [kJ] under ``hz``, from the sensitivity table at ``key`` = (m_max, share) when it has it."""
        sensitivity, T = self.sensitivity, self.T
        if key is not None and sensitivity is not None:
            hit = sensitivity[np.isclose(sensitivity["m_max_kg"], key[0] if key[0] is not None else np.inf,
                                         rtol=1e-9) & np.isclose(sensitivity["rate_share"], key[1], rtol=1e-9)
                              & np.isclose(sensitivity["T_years"], T)]
            if len(hit) == 1:
                return float(hit["energy_kj"].iloc[0])
        return float(hz.energy_at_return_period(T)) if T * hz.arrival_rate > 1 else 0.0

    def block_masses(self, hz, **change):
        """(chosen block, fragmentation alternative) masses [kg] under hazard ``hz`` with changed rule inputs."""
        from .design_block import design_block as _design_block
        block = self.block
        if block is None:
            return np.nan, np.nan
        if not change and hz is self.hazard:
            alt = block.alternatives
        else:
            try:
                alt = _design_block(hz, **{**self.inputs, **change}).alternatives
            except ValueError as exc:
                self.notes.append(f"design block undefined with {change or 'the changed law'}: {exc}")
                return np.nan, np.nan
        frag = alt.loc[alt["rule"].str.startswith("fragmentation"), "mass_kg"]
        return float(alt.loc[alt["chosen"], "mass_kg"].iloc[0]), float(frag.iloc[0]) if len(frag) else np.nan

    @staticmethod
    def block_energy(hz, m, pct) -> float:
        """1/2 m v_p^2 [kJ] of a block of mass ``m`` [kg] at the ``pct`` speed percentile under ``hz`` (NaN mass: NaN)."""
        if not np.isfinite(m):
            return np.nan
        return kinetic_energy_kj(m, hz.velocity_percentile(pct, mass_kg=m))



def _tornado_cases(hazard, args: _TornadoArguments, rate_label: str, notes: list) -> dict:
    """The perturbed hazards of the law's inputs (cheap: the same simulated slope, another mass law or rate).

    Parameters
    ----------
    hazard : EnergyHazard
        The base hazard.
    args : _TornadoArguments
        The checked arguments.
    rate_label : str
        Name of the rate row.
    notes : list of str
        Appended to when a row cannot be made.

    Returns
    -------
    dict
        input name -> (unit, low, base, high, basis, hazard at low, hazard at high, sensitivity key at low,
        sensitivity key at high).
    """
    gr, m_max, share, masses = args.gr, args.m_max, args.share, args.masses
    cases = {}
    if args.mm_lo is not None:
        if masses is not None:
            def law(v):
                return fit_gutenberg_richter(masses, args.duration_years, m_min=gr.m_min, m_max=v)
            how = "law refitted to the inventory with each m_max"
        else:
            def law(v):
                return replace(gr, m_max=float(v))
            how = "law re-truncated, b kept"
        basis = ("given" if "m_max_range" in args.given else "typed: x0.5 and x2 of the stated m_max (ASSUMPTION)") \
            + f"; {how}"
        cases["maximum credible block m_max"] = ("kg", args.mm_lo, m_max, args.mm_hi, basis,
                                                 hazard.with_mass(law(args.mm_lo), hazard.rate_per_year),
                                                 hazard.with_mass(law(args.mm_hi), hazard.rate_per_year),
                                                 (args.mm_lo, share), (args.mm_hi, share))
    elif gr is not None:
        notes.append("m_max: the law is not truncated (no maximum credible block stated); no m_max row")
    cases[rate_label] = (
        NO_UNIT, args.s_lo, share, args.s_hi,
        "given" if "rate_share_range" in args.given else "typed: x0.5 and x2 (ASSUMPTION)",
        hazard.with_mass(hazard.mass, hazard.rate_per_year * args.s_lo / share),
        hazard.with_mass(hazard.mass, hazard.rate_per_year * args.s_hi / share), (m_max, args.s_lo),
        (m_max, args.s_hi))
    if gr is not None:
        b_lo, b_hi = gr.b_ci

        def with_b(b):
            law = replace(gr, b=float(b), a=float(np.log10(gr.rate_min) + b * np.log10(gr.m_min)))
            return hazard.with_mass(law, hazard.rate_per_year)
        cases["power-law exponent b"] = (NO_UNIT, b_lo, gr.b, b_hi,
                                         f"{gr.level:.0%} interval of the fit ({gr.b_ci_method}); rate at m_min kept",
                                         with_b(b_lo), with_b(b_hi), None, None)
    else:
        notes.append("b: the mass model is not a power-law fit; no b row")
    return cases



def _tornado_row(output, name, unit, lo, base, hi, basis, e_lo, e_base, e_hi) -> dict:
    """One row of the tornado table: ``output`` [kJ] at input ``name`` low, base and high, and its swing [kJ]."""
    return {"design_energy": output, "input": name, "unit": unit, "low": lo, "base": base, "high": hi,
            "range_basis": basis, "energy_low_kj": e_lo, "energy_base_kj": e_base, "energy_high_kj": e_hi,
            "swing_kj": abs(e_hi - e_lo)}



def _tornado_table(hazard, block, args: _TornadoArguments, cases: dict, energies: _TornadoEnergies,
                   notes: list) -> DesignEnergyTornado:
    """Evaluate every design energy at each input's low and high and order the rows by output and swing.

    Parameters
    ----------
    hazard : EnergyHazard
        The base hazard.
    block : DesignBlock or None
        The design block.
    args : _TornadoArguments
        The checked arguments.
    cases : dict
        The law's perturbed hazards (:func:`_tornado_cases`).
    energies : _TornadoEnergies
        The evaluator.
    notes : list of str
        Appended to.

    Returns
    -------
    DesignEnergyTornado
    """
    q, rule = args.q, args.inputs.get("rule")
    t_name = f"{args.T:g}-year energy at the barrier line"
    b_name = f"design-block energy 1/2 m v_p{q:g}^2 ({rule} rule)" if block is not None else None
    f_name = (f"fragmentation alternative 1/2 m v_p{q:g}^2 (not the chosen block)"
              if args.fragmenting and rule != "fragmentation" else None)
    base_t = energies.t_energy(hazard, (args.m_max, args.share))
    base_chosen, base_frag = energies.block_masses(hazard)
    base = dict(t=base_t, chosen=base_chosen, frag=base_frag, b=energies.block_energy(hazard, base_chosen, q),
                f=energies.block_energy(hazard, base_frag, q))
    law_moves_block = rule in ("return_period", "fragmentation")
    rows = _tornado_law_rows(cases, energies, q, t_name, b_name if law_moves_block else None, f_name, base)
    if block is not None:
        rows += _tornado_velocity_rows(hazard, args, energies, b_name, f_name, base)
    else:
        notes.append("no design block given: only the T-year energy is studied")
    if args.fragmenting:
        rows += _tornado_fragmentation_rows(hazard, args, energies, b_name if rule == "fragmentation" else None,
                                            f_name, base)
    elif block is not None:
        notes.append("fragmentation not configured: no fractal-dimension or generations rows")
    if block is not None and not law_moves_block:
        notes.append(f"the {rule} design block is taken from the block sizes, not the law: m_max, the rate share "
                     "and b do not move it")
    table = pd.DataFrame(rows)
    order = {name: i for i, name in enumerate(n for n in (t_name, b_name, f_name) if n)}
    table = (table.assign(_o=table["design_energy"].map(order), _s=-table["swing_kj"].fillna(-1))
             .sort_values(["_o", "_s"], kind="stable").drop(columns=["_o", "_s"]).reset_index(drop=True))
    return DesignEnergyTornado(table=table, design_T=args.T, notes=tuple(dict.fromkeys(notes)))



def _tornado_law_rows(cases, energies, q, t_name, b_name, f_name, base) -> list:
    """Rows of the law's inputs (m_max, rate share, b): the T-year energy and the design energies the law moves.

    Parameters
    ----------
    cases : dict
        The law's perturbed hazards (:func:`_tornado_cases`).
    energies : _TornadoEnergies
        The evaluator.
    q : float
        Velocity percentile [%] of the block energies.
    t_name : str
        Name of the T-year energy.
    b_name : str or None
        Name of the design-block energy, None when the law does not move the block.
    f_name : str or None
        Name of the fragmentation alternative's energy, None when it is not an output.
    base : dict
        Base energies [kJ] (``t``, ``b``, ``f``).

    Returns
    -------
    list of dict
    """
    rows = []
    for name, (unit, lo, b0, hi, basis, hz_lo, hz_hi, key_lo, key_hi) in cases.items():
        label = f"{name} [{unit}]" if unit != NO_UNIT else name
        rows.append(_tornado_row(t_name, label, unit, lo, b0, hi, basis, energies.t_energy(hz_lo, key_lo),
                                 base["t"], energies.t_energy(hz_hi, key_hi)))
        if b_name or f_name:
            (c_lo, fr_lo), (c_hi, fr_hi) = energies.block_masses(hz_lo), energies.block_masses(hz_hi)
            if b_name:
                rows.append(_tornado_row(b_name, label, unit, lo, b0, hi, basis,
                                         energies.block_energy(hz_lo, c_lo, q), base["b"],
                                         energies.block_energy(hz_hi, c_hi, q)))
            if f_name:
                rows.append(_tornado_row(f_name, label, unit, lo, b0, hi, basis,
                                         energies.block_energy(hz_lo, fr_lo, q), base["f"],
                                         energies.block_energy(hz_hi, fr_hi, q)))
    return rows



def _tornado_velocity_rows(hazard, args, energies, b_name, f_name, base) -> list:
    """Rows of the velocity percentile [%]: the design-block energy and the fragmentation alternative's.

    Parameters
    ----------
    hazard : EnergyHazard
        The base hazard.
    args : _TornadoArguments
        The checked arguments (``q``, ``q_lo``, ``q_hi``).
    energies : _TornadoEnergies
        The evaluator.
    b_name : str
        Name of the design-block energy.
    f_name : str or None
        Name of the fragmentation alternative's energy, None when it is not an output.
    base : dict
        Base masses [kg] (``chosen``, ``frag``) and energies [kJ] (``b``, ``f``).

    Returns
    -------
    list of dict
    """
    q, q_lo, q_hi = args.q, args.q_lo, args.q_hi
    basis = "given" if "velocity_percentile_range" in args.given else "typed: p90 and p99 (ASSUMPTION)"
    label = "velocity percentile of the block energy [%]"
    rows = [_tornado_row(b_name, label, "%", q_lo, q, q_hi, basis,
                         energies.block_energy(hazard, base["chosen"], q_lo), base["b"],
                         energies.block_energy(hazard, base["chosen"], q_hi))]
    if f_name:
        rows.append(_tornado_row(f_name, label, "%", q_lo, q, q_hi, basis,
                                 energies.block_energy(hazard, base["frag"], q_lo), base["f"],
                                 energies.block_energy(hazard, base["frag"], q_hi)))
    return rows



def _tornado_fragmentation_rows(hazard, args, energies, b_name, f_name, base) -> list:
    """Rows of the fractal dimension D [-] and the fragmentation generations.

    Parameters
    ----------
    hazard : EnergyHazard
        The base hazard.
    args : _TornadoArguments
        The checked arguments (their stated and low/high fragmentation parameters).
    energies : _TornadoEnergies
        The evaluator.
    b_name : str or None
        Name of the design-block energy when the block is the fragmentation rule's, else None.
    f_name : str or None
        Name of the fragmentation alternative's energy (used when ``b_name`` is None).
    base : dict
        Base energies [kJ] (``b``, ``f``).

    Returns
    -------
    list of dict
    """
    q = args.q
    basis_d = "given" if "fractal_dimension_range" in args.given else "typed: stated D +- 0.25 (ASSUMPTION)"
    basis_g = "given" if "iterations_range" in args.given else "typed: stated generations +- 1 (ASSUMPTION)"
    rows = []
    for name, unit, lo, b0, hi, basis, key in (
            ("fractal dimension D", NO_UNIT, args.d_lo, args.D, args.d_hi, basis_d, "fractal_dimension"),
            ("fragmentation generations", NO_UNIT, args.g_lo, args.n_gen, args.g_hi, basis_g, "iterations")):
        (c_lo, fr_lo), (c_hi, fr_hi) = (energies.block_masses(hazard, **{key: lo}),
                                        energies.block_masses(hazard, **{key: hi}))
        if b_name:
            rows.append(_tornado_row(b_name, name, unit, lo, b0, hi, basis, energies.block_energy(hazard, c_lo, q),
                                     base["b"], energies.block_energy(hazard, c_hi, q)))
        else:
            rows.append(_tornado_row(f_name, name, unit, lo, b0, hi, basis, energies.block_energy(hazard, fr_lo, q),
                                     base["f"], energies.block_energy(hazard, fr_hi, q)))
    return rows


__all__ = ["DesignEnergyTornado", "TORNADO_DEFAULTS", "design_energy_tornado"]
