"""The impact-energy analysis behind ``riskrf energy``: hazard, design energies, fence checks.

:func:`analyse_energy` gives the :class:`EnergyAnalysis` of a hazard at the barrier line: the design table with
its bootstrap intervals (what they cover: :data:`INTERVAL_COVERS`), the fence checks, the UNI 11211-4 design
energy and the site's design masses, with their text, JSON and CSV forms.  :func:`design_energy_sensitivity`
tabulates the T-year energy over m_max and the rate share (:func:`sensitivity_grid`).  The one-way sensitivity
(tornado) of the design energies is in :mod:`riskrf.hazard.energy_tornado`; :func:`design_energy_tornado` is
importable from here too, where the user guide used to import it.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .annual_hazard import EnergyHazard
from .mass_models import mass_model
from .barriers import UNI11211_FACTORS, check_fence, uni11211_design_energy
from .energy_tornado import design_energy_tornado  # re-exported: a documented import path
from ..io.outputs import write_json
from ..frequency.power_law import fit_gutenberg_richter
from ..core.format import sig
from ..core.units import DEFAULT_DENSITY_KG_M3, DESIGN_RETURN_PERIODS

#: What the bootstrap interval of a design energy covers, and what it does not (stated with every interval).
INTERVAL_COVERS = ("sampling uncertainty of the power-law exponent b and of the rate, and the finite number of "
                   "simulated trajectories; NOT the maximum credible block m_max nor the rate share of the source "
                   "above the line (judgement inputs: see the sensitivity table), nor the slope's material "
                   "parameters or the choice of model")


@dataclass(frozen=True)
class EnergyAnalysis:
    """An energy hazard with its design table, fence checks and UNI 11211-4 design energy."""

    hazard: EnergyHazard
    design: pd.DataFrame
    fences: dict            # {"2000 kJ / 5 m": check table}
    uni: object             # UNI11211Design or None
    design_T: float
    density_kg_m3: float
    seed: int | None
    n_bootstrap: int
    design_block: object = None          # riskrf.hazard.design_block.DesignBlock or None
    sensitivity: pd.DataFrame | None = None
    site_masses: pd.DataFrame | None = None
    tornado: object = None               # DesignEnergyTornado or None

    def fence_verdicts(self) -> pd.DataFrame:
        """One row per fence checked: whether every check passed (``adequate``) and the names of those that failed.

        Returns
        -------
        pandas.DataFrame
            ``fence``, ``adequate``, ``failed checks``.
        """
        rows = []
        for name, table in self.fences.items():
            rows.append({"fence": name, "adequate": bool(table["adequate"].all()),
                         "failed checks": "; ".join(table.loc[~table["adequate"], "check"]) or "none"})
        return pd.DataFrame(rows)

    def summary_text(self) -> str:
        """The analysis in a few plain-text lines (rates [1/yr], reach probability, design energies [kJ], fence
        verdicts), for the CLI's closing summary; the caller prints it.

        Returns
        -------
        str
        """
        hz = self.hazard
        lines = ["Impact energy hazard at the barrier line (Wyllie 2014, 8.1-8.3)",
                 f"  falls per year (mass model)   {sig(hz.rate_per_year, 4)}   [{hz.summary().loc['mass model', 'value']}]",
                 f"  reach probability             {hz.reach_probability:.4f}"
                 + (f"  ({hz.n_released:,} simulated blocks)" if hz.n_released else ""),
                 f"  arrivals per year             {sig(hz.arrival_rate, 4)}"]
        for note in hz.notes:
            lines.append(f"  {note}")
        e95, e99 = hz.energy_percentile([95, 99])
        lines.append(f"  energy per arriving fall      p95 {sig(e95, 4)} kJ, p99 {sig(e99, 4)} kJ")
        if hz.heights_m is not None:
            lines.append(f"  bounce height                 p95 {hz.height_percentile(95):.3g} m, "
                         f"p99 {hz.height_percentile(99):.3g} m (block centre above the slope)")
        if hz.mass_coupled:
            lines += ["", "Reach, speed and bounce height by block mass (simulated across the mass range):",
                      hz.velocity.class_table().to_string(index=False, float_format=lambda v: sig(v, 4))]
        lines += ["", f"Design energies (interval: {self.n_bootstrap} bootstrap replicates, seed {self.seed}; "
                      f"it covers the {INTERVAL_COVERS}):"]
        d = self.design.copy()
        lines.append(d.to_string(index=False, float_format=lambda v: sig(v, 4)))
        short = d.loc[d["T_years"] * hz.arrival_rate < 1, "T_years"]
        if len(short):
            lines.append(f"  T = {', '.join(sig(t) for t in short)} years: fewer than one fall reaches the line in T "
                         f"years (T x {sig(hz.arrival_rate, 3)} arrivals per year < 1), so no T-year energy exists "
                         "there (shown as 0 kJ)")
        if self.site_masses is not None:
            lines += ["", "Design masses of the site's law (the hazard's; nothing above m_max) [kg]:",
                      self.site_masses.drop(columns="law").to_string(index=False, float_format=lambda v: sig(v, 4))]
        if self.design_block is not None:
            b = self.design_block
            lines += ["", f"Design block: {sig(b.mass_kg, 4)} kg ({sig(b.volume_m3, 4)} m3, sphere diameter "
                          f"{b.diameter_m:.3g} m) by rule {b.rule!r}: {b.basis}"]
            lines += [f"  {a}" for a in b.assumptions]
            lines.append(b.alternatives.to_string(index=False, float_format=lambda v: sig(v, 4)))
        if self.sensitivity is not None:
            lines += ["", f"Sensitivity of the {self.design_T:g}-year energy [kJ] to the judgement inputs "
                          "(m_max: rows; rate share: columns):",
                      sensitivity_grid(self.sensitivity).to_string(float_format=lambda v: sig(v, 4))]
        if self.tornado is not None:
            lines += ["", "One-way sensitivity (tornado) of the design energies: each input at low and high, the "
                          "others at base [kJ]:", self.tornado.text()]
            for _, r in self.tornado.dominant().iterrows():
                lines.append(f"  dominant for the {r['design_energy']}: {r['input']} "
                             f"({sig(r['energy_low_kj'], 3)} - {sig(r['energy_high_kj'], 3)} kJ)")
        if self.uni is not None:
            u = self.uni
            block = u.design_mass_kg / (u.factors["gamma_VolF"] * u.factors["gamma_gamma"])
            what = "design block" if self.design_block is not None else f"{self.design_T:g}-year block"
            lines += ["", f"UNI 11211-4 design energy for the {what} "
                          f"({sig(block, 4)} kg) at the p95 velocity: "
                          f"E_k = {sig(u.characteristic_energy_kj, 4)} kJ, E_d = {sig(u.design_energy_kj, 4)} kJ "
                          f"(gamma_Tr {u.factors['gamma_Tr']}, gamma_Dp {u.factors['gamma_Dp']}, "
                          f"gamma_VolF {u.factors['gamma_VolF']}, gamma_gamma {u.factors['gamma_gamma']})"]
        elif (why := self._uni_missing_reason()):
            lines += ["", f"UNI 11211-4 design energy not computed: {why}"]
        for name, table in self.fences.items():
            lines += ["", f"Fence {name}:"]
            for _, r in table.iterrows():
                mark = "N/A " if not np.isfinite(r["demand"]) else "OK  " if r["adequate"] else "FAIL"
                demand = f"{sig(r['demand'], 4)} {r['unit']}" if np.isfinite(r["demand"]) else "not defined"
                lines.append(f"  [{mark}] {r['check']}: {demand} vs {sig(r['capacity'], 4)} "
                             f"{r['unit']}" + (f" (interval {r['interval']})" if r["interval"] else "")
                             + f"; {r['note']}")
        return "\n".join(lines)

    def _uni_missing_reason(self) -> str:
        """Why the UNI 11211-4 design energy is absent ('' when it was computed)."""
        if self.uni is not None:
            return ""
        hz = self.hazard
        expected = self.design_T * hz.rate_per_year
        if mass_model(hz.mass).rate_per_year is not None and expected <= 1:
            return (f"the {self.design_T:g}-year block is not defined because fewer than one fall is expected in "
                    f"{self.design_T:g} years ({sig(expected, 3)} at {sig(hz.rate_per_year, 3)} falls per year); "
                    "a design block (riskrf energy --design-percentile or --block-survey; design_block= in Python) "
                    "would apply it")
        return ("it needs a design block (riskrf energy --design-percentile or --block-survey) or a power-law "
                "mass model for the T-year block")

    def to_dict(self) -> dict:
        """The analysis as a JSON-ready dict (``energy_summary.json``): units, hazard figures, design energies [kJ],
        fence checks, interval coverage and notes.

        Returns
        -------
        dict
        """
        hz = self.hazard
        out = {"units": {"energy": "kJ", "height": "m", "rate": "1/yr", "return_period": "yr"},
               "hazard": {k: v for k, v in hz.summary()["value"].items()},
               "design_energies": self.design.to_dict(orient="records"),
               "fences": {name: t.to_dict(orient="records") for name, t in self.fences.items()},
               "design_energy_interval_covers": INTERVAL_COVERS,
               "mass_coupled": hz.mass_coupled,
               "notes": list(hz.notes)}
        if hz.mass_coupled:
            out["mass_classes"] = hz.velocity.class_table().to_dict(orient="records")
        if self.site_masses is not None:
            out["site_design_masses"] = self.site_masses.to_dict(orient="records")
        if self.design_block is not None:
            out["design_block"] = self.design_block.to_dict()
        if self.sensitivity is not None:
            out["design_energy_sensitivity"] = self.sensitivity.to_dict(orient="records")
        if self.tornado is not None:
            out["design_energy_tornado"] = self.tornado.to_dict()
        if self.uni is None:
            out["uni11211"] = {"design_return_period_years": self.design_T, "not_computed": self._uni_missing_reason()}
        else:
            out["uni11211"] = {"design_return_period_years": self.design_T,
                               "characteristic_energy_kj": self.uni.characteristic_energy_kj,
                               "design_energy_kj": self.uni.design_energy_kj,
                               "design_velocity_ms": self.uni.design_velocity_ms, "factors": self.uni.factors}
        return out

    def write(self, out_dir) -> list[Path]:
        """Write ``energy_summary.json`` and the CSV tables (design energies, sensitivity, tornado) into ``out_dir``
        (which must exist); returns every file written.  The figures are drawn by
        :func:`riskrf.report.files.write_energy_study`, which calls this first.

        Parameters
        ----------
        out_dir : str or path
            Existing folder.

        Returns
        -------
        list of pathlib.Path
            The files written.
        """
        out = Path(out_dir)
        written = [out / "energy_summary.json", out / "design_energies.csv"]
        write_json(self.to_dict(), written[0])
        self.design.to_csv(written[1], index=False)
        tables = [("site_design_masses.csv", self.site_masses),
                  ("design_energy_sensitivity.csv", self.sensitivity),
                  ("design_energy_tornado.csv", None if self.tornado is None else self.tornado.table),
                  ("design_block.csv", None if self.design_block is None else self.design_block.alternatives),
                  ("fence_checks.csv", pd.concat([t.assign(fence=n) for n, t in self.fences.items()])
                   if self.fences else None)]
        for name, table in tables:
            if table is not None:
                table.to_csv(out / name, index=False)
                written.append(out / name)
        return written

def analyse_energy(hazard: EnergyHazard, *, fences=(), fence_height_m=5.0, free_board_m: float = 0.5,
                   T=DESIGN_RETURN_PERIODS, design_T: float = 100.0, density_kg_m3: float = DEFAULT_DENSITY_KG_M3,
                   n_bootstrap: int = 300, seed=1, uni_factors: dict | None = None, design_block=None,
                   sensitivity: pd.DataFrame | None = None, tornado=None) -> EnergyAnalysis:
    """Design table, fence checks (each capacity in ``fences`` at ``fence_height_m``: one height [m] for all, or
    one per fence) and UNI 11211-4 energy.

    ``design_block`` (a :class:`~riskrf.hazard.design_block.DesignBlock`): the UNI 11211-4 energy uses it (at the p95
    speed of simulated blocks of its mass when the hazard is mass-coupled) instead of the T-year block, and each
    fence gets an over-topping check by the block's top.  ``sensitivity``: a table from
    :func:`design_energy_sensitivity`, carried into the outputs; ``tornado``: a
    :class:`~riskrf.hazard.energy_tornado.DesignEnergyTornado`
    (:func:`~riskrf.hazard.energy_tornado.design_energy_tornado`), likewise.

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard at the line.
    fences : sequence of float
        Fence capacities (MEL) to check [kJ].
    fence_height_m : float or sequence of float
        Fence height(s) [m].
    free_board_m : float
        Margin over the 95th-percentile bounce height [m].
    T : sequence of float
        Return periods of the design table [yr].
    design_T : float
        Design return period [yr].
    density_kg_m3 : float
        Rock density [kg/m³] (UNI 11211-4 volume).
    n_bootstrap : int
        Replicates of the intervals.
    seed : int
        Seed of the intervals.
    uni_factors : dict, optional
        UNI 11211-4 partial factors (:func:`riskrf.hazard.barriers.uni11211_design_energy`).
    design_block : DesignBlock, optional
        The design block.
    sensitivity : pandas.DataFrame, optional
        A :func:`design_energy_sensitivity` table.
    tornado : DesignEnergyTornado, optional
        A :func:`~riskrf.hazard.energy_tornado.design_energy_tornado` result.

    Returns
    -------
    EnergyAnalysis
        Design table [kJ], fence checks, the UNI 11211-4 design and the carried tables.

    References
    ----------
    UNI 11211-4:2012; EOTA ETAG 027 / EAD 340059-00-0106 (see :mod:`riskrf.hazard.barriers`).
    """
    from ..core.validation import check_return_periods
    try:
        check_return_periods(design_T, "design_T")
    except (TypeError, ValueError):
        raise ValueError(f"design_T = {design_T!r}: the design return period must be a finite number > 1 year "
                         "(a T-year event has annual probability 1/T)") from None
    if not (np.isfinite(free_board_m) and free_board_m >= 0):
        raise ValueError(f"free_board_m = {free_board_m!r} must be a finite number >= 0 m")
    if any(not (np.isfinite(h) and h > 0) for h in np.atleast_1d(np.asarray(fence_height_m, dtype=float))):
        raise ValueError(f"fence_height_m = {fence_height_m!r}: every height must be a finite number > 0 m")
    T_all = np.union1d(np.asarray(T, dtype=float), [design_T])
    table = hazard.design_table(T_all, n_bootstrap=n_bootstrap, seed=seed)
    row = table.loc[table["T_years"] == design_T].iloc[0]
    e_design = (float(row["energy_kj"]), float(row["ci_low_kj"]), float(row["ci_high_kj"]))
    design = table.loc[table["T_years"].isin(np.asarray(T, dtype=float))].reset_index(drop=True)
    heights = list(fence_height_m) if np.ndim(fence_height_m) else [fence_height_m] * len(fences)
    if len(heights) != len(fences):
        raise ValueError(f"fence_height_m = {fence_height_m!r}: give one height or one per fence ({len(fences)})")
    checks = {f"{cap:g} kJ / {h:g} m": check_fence(hazard, cap, h, T=design_T, free_board_m=free_board_m,
                                                    design_energy=e_design)
              for cap, h in zip(fences, heights)}
    checks = {name: _undefined_design_energy(table, hazard, design_T) for name, table in checks.items()}
    if design_block is not None:
        for (name, table), h in zip(checks.items(), heights):
            checks[name] = pd.concat([table, _block_top_check(hazard, design_block, h, free_board_m)],
                                     ignore_index=True)
    uni = None
    block = None
    if design_block is not None:
        block = design_block.mass_kg
    elif mass_model(hazard.mass).rate_per_year is not None and design_T * hazard.rate_per_year > 1:
        # the T-year block at this line
        block = float(mass_model(hazard.mass).isf(1.0 / (design_T * hazard.rate_per_year)))
    if block is not None:
        v95 = hazard.velocity_percentile(UNI11211_FACTORS["velocity_percentile"], mass_kg=block)
        uni = uni11211_design_energy(block / density_kg_m3, density_kg_m3, v95, **(uni_factors or {}))
    from .design_block import site_design_masses
    site_masses = site_design_masses(hazard, DESIGN_RETURN_PERIODS, density_kg_m3)
    return EnergyAnalysis(hazard=hazard, design=design, fences=checks, uni=uni, design_T=float(design_T),
                          density_kg_m3=density_kg_m3, seed=seed, n_bootstrap=int(n_bootstrap),
                          design_block=design_block, sensitivity=sensitivity, site_masses=site_masses,
                          tornado=tornado)


def _undefined_design_energy(table: pd.DataFrame, hazard, design_T: float) -> pd.DataFrame:
    """Energy checks with no T-year energy: fewer than one fall reaches the line in T years.

    The T-year energy is then not defined (``energy_at_return_period`` gives 0 kJ), so the MEL/SEL rows get
    demand NaN (printed "N/A", never "OK" with 0 kJ) and a note giving the expected number of arrivals; the
    annual frequency of impacts above MEL/SEL in the note remains the check.
    """
    expected = float(design_T) * float(hazard.arrival_rate)
    if expected >= 1:
        return table
    t = table.copy()
    rows = (t["unit"] == "kJ") & t["check"].str.startswith(f"{design_T:g}-year energy")
    t.loc[rows, "demand"] = np.nan
    t.loc[rows, "interval"] = ""
    t.loc[rows, "note"] = (f"the {design_T:g}-year energy is not defined: fewer than one fall reaches the line in "
                           f"{design_T:g} years ({sig(expected, 3)} expected at {sig(hazard.arrival_rate, 3)} "
                           "arrivals per year); judge the fence by the frequency of impacts above its capacity: "
                           + t.loc[rows, "note"])
    return t


def _block_top_check(hazard, block, height_m: float, free_board_m: float) -> pd.DataFrame:
    """Over-topping by the design block's top: p95 centre height of blocks of its mass + its radius + free board
    against the fence height [m]."""
    vel = hazard.velocity
    if hazard.mass_coupled:
        h95, how = vel.height_percentile(95, block.mass_kg), "simulated blocks of its mass class"
    elif hazard.heights_m is not None:
        h95, how = float(hazard.height_percentile(95)), "all arriving blocks (mass-independent form)"
    else:
        return pd.DataFrame()
    r = block.diameter_m / 2.0
    demand = h95 + r + free_board_m
    return pd.DataFrame([{"check": "design block top: p95 centre height + radius + free board vs height",
                          "demand": demand, "capacity": float(height_m), "unit": "m", "interval": "",
                          "adequate": bool(demand <= height_m),
                          "note": f"design block {sig(block.mass_kg)} kg, diameter {sig(block.diameter_m)} m; p95 "
                                  f"centre height {sig(h95)} m of {how}"}])


def design_energy_sensitivity(hazard: EnergyHazard, masses_kg, duration_years: float, *, m_min: float,
                              m_max_values, rate_shares, T: float = 100.0) -> pd.DataFrame:
    """The T-year energy [kJ] over the judgement inputs: maximum credible block m_max [kg] x rate share [-].

    For each m_max the power law is refitted to the inventory's masses (``masses_kg`` over ``duration_years``,
    above ``m_min``) with that truncation; its rate is multiplied by each share; the slope model (the hazard's
    simulated reach and speeds, by mass when mass-coupled) stays.  ``simulated`` says whether the m_max lies
    inside the simulated masses (else its heaviest blocks borrow the top mass class's speeds).

    Parameters
    ----------
    hazard : EnergyHazard
        The hazard (its slope model is kept).
    masses_kg : array_like
        The inventory's masses [kg].
    duration_years : float
        Its record length [yr].
    m_min : float
        Completeness threshold [kg].
    m_max_values : sequence of float
        Maximum credible blocks [kg].
    rate_shares : sequence of float
        Rate shares [-].
    T : float
        Return period [yr].

    Returns
    -------
    pandas.DataFrame
        One row per (m_max, share): ``m_max_kg``, ``rate_share``, ``falls_per_year``, ``b``, ``T_years``,
        ``energy_kj``, ``simulated``.
    """
    rows = []
    top = hazard.velocity.edges_kg[-1] if hazard.mass_coupled else None
    for m_max in m_max_values:
        gr = fit_gutenberg_richter(masses_kg, duration_years, m_min=m_min, m_max=m_max)
        for share in rate_shares:
            rate = gr.rate_min * float(share)
            hz = hazard.with_mass(gr, rate)
            e = float(hz.energy_at_return_period(T)) if T * hz.arrival_rate > 1 else 0.0
            rows.append({"m_max_kg": m_max if m_max is not None else np.inf, "rate_share": float(share),
                         "falls_per_year": rate, "b": gr.b, "T_years": float(T), "energy_kj": e,
                         "simulated": bool(top is None or (m_max is not None and m_max <= top * (1 + 1e-9)))})
    out = pd.DataFrame(rows)
    return out


def sensitivity_grid(table: pd.DataFrame) -> pd.DataFrame:
    """The sensitivity table as a grid: m_max [kg] rows, rate share columns, T-year energy [kJ] values.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`design_energy_sensitivity` table.

    Returns
    -------
    pandas.DataFrame
    """
    g = table.pivot(index="m_max_kg", columns="rate_share", values="energy_kj")
    g.index = [f"m_max {sig(v)} kg" if np.isfinite(v) else "m_max none" for v in g.index]
    g.columns = [f"share {c:g}" for c in g.columns]
    return g


__all__ = ["EnergyAnalysis", "INTERVAL_COVERS", "analyse_energy", "design_energy_sensitivity",
           "design_energy_tornado", "sensitivity_grid"]
