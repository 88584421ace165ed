"""The impact-energy analysis behind ``riskrf energy``: hazard, design energies, fence checks."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .annual_hazard import EnergyHazard
from .barriers import UNI11211_FACTORS, check_fence, uni11211_design_energy
from .frequency_study import DESIGN_RETURN_PERIODS
from .outputs import write_json
from .power_law import GutenbergRichterFit, fit_gutenberg_richter
from .report.format import sig
from .units import DEFAULT_DENSITY_KG_M3

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
    design_block: object = None          # riskrf.design_block.DesignBlock or None
    sensitivity: pd.DataFrame | None = None
    site_masses: pd.DataFrame | None = None

    def fence_verdicts(self) -> pd.DataFrame:
        rows = []
        for name, table in self.fences.items():
            rows.append({"fence": name, "adequate": bool(table["adequate"].all()),
                         "failed checks": "; ".join(table.loc[~table["adequate"], "check"]) or "none"})
        return pd.DataFrame(rows)

    def summary_text(self) -> str:
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
        if self.uni is not None:
            u = self.uni
            block = u.design_mass_kg / (u.factors["gamma_VolF"] * u.factors["gamma_gamma"])
            what = "design block" if self.design_block is not None else f"{self.design_T:g}-year block"
            lines += ["", f"UNI 11211-4 design energy for the {what} "
                          f"({sig(block, 4)} kg) at the p95 velocity: "
                          f"E_k = {sig(u.characteristic_energy_kj, 4)} kJ, E_d = {sig(u.design_energy_kj, 4)} kJ "
                          f"(gamma_Tr {u.factors['gamma_Tr']}, gamma_Dp {u.factors['gamma_Dp']}, "
                          f"gamma_VolF {u.factors['gamma_VolF']}, gamma_gamma {u.factors['gamma_gamma']})"]
        for name, table in self.fences.items():
            lines += ["", f"Fence {name}:"]
            for _, r in table.iterrows():
                mark = "OK  " if r["adequate"] else "FAIL"
                lines.append(f"  [{mark}] {r['check']}: {sig(r['demand'], 4)} {r['unit']} vs {sig(r['capacity'], 4)} "
                             f"{r['unit']}" + (f" (interval {r['interval']})" if r["interval"] else "")
                             + f"; {r['note']}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
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
        if self.uni is not None:
            out["uni11211"] = {"design_return_period_years": self.design_T,
                               "characteristic_energy_kj": self.uni.characteristic_energy_kj,
                               "design_energy_kj": self.uni.design_energy_kj,
                               "design_velocity_ms": self.uni.design_velocity_ms, "factors": self.uni.factors}
        return out

    def write(self, out_dir) -> None:
        from .report.files import write_energy_figures
        out = Path(out_dir)
        write_json(self.to_dict(), out / "energy_summary.json")
        self.design.to_csv(out / "design_energies.csv", index=False)
        if self.sensitivity is not None:
            self.sensitivity.to_csv(out / "design_energy_sensitivity.csv", index=False)
        if self.design_block is not None:
            self.design_block.alternatives.to_csv(out / "design_block.csv", index=False)
        if self.fences:
            pd.concat([t.assign(fence=n) for n, t in self.fences.items()]).to_csv(out / "fence_checks.csv",
                                                                                index=False)
        write_energy_figures(self, out, [float(n.split(" kJ")[0]) for n in self.fences])

def analyse_energy(hazard: EnergyHazard, *, fences=(), fence_height_m=5.0, free_board_m: float = 0.5,
                   T=DESIGN_RETURN_PERIODS, design_T: float = 100.0, density_kg_m3: float = DEFAULT_DENSITY_KG_M3,
                   n_bootstrap: int = 300, seed=1, uni_factors: dict | None = None, design_block=None,
                   sensitivity: pd.DataFrame | None = None) -> EnergyAnalysis:
    """Design table, fence checks (each capacity in ``fences`` at ``fence_height_m``: one height [m] for all, or
    one per fence) and UNI 11211-4 energy.

    ``design_block`` (a :class:`~riskrf.design_block.DesignBlock`): the UNI 11211-4 energy uses it (at the p95
    speed of simulated blocks of its mass when the hazard is mass-coupled) instead of the T-year block, and each
    fence gets an over-topping check by the block's top.  ``sensitivity``: a table from
    :func:`design_energy_sensitivity`, carried into the outputs."""
    from .validation import check_return_periods
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
    if design_block is not None:
        for (name, table), h in zip(checks.items(), heights):
            checks[name] = pd.concat([table, _block_top_check(hazard, design_block, h, free_board_m)],
                                     ignore_index=True)
    uni = None
    block = None
    if design_block is not None:
        block = design_block.mass_kg
    elif isinstance(hazard.mass, GutenbergRichterFit) and design_T * hazard.rate_per_year > 1:
        block = float(hazard.mass.isf(1.0 / (design_T * hazard.rate_per_year)))   # the T-year block at this line
    if block is not None:
        v95 = hazard.velocity_percentile(UNI11211_FACTORS["velocity_percentile"], mass_kg=block)
        uni = uni11211_design_energy(block / density_kg_m3, density_kg_m3, v95, **(uni_factors or {}))
    from .design_block import site_design_masses
    site_masses = site_design_masses(hazard, DESIGN_RETURN_PERIODS, density_kg_m3)
    return EnergyAnalysis(hazard=hazard, design=design, fences=checks, uni=uni, design_T=float(design_T),
                          density_kg_m3=density_kg_m3, seed=seed, n_bootstrap=int(n_bootstrap),
                          design_block=design_block, sensitivity=sensitivity, site_masses=site_masses)


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
    """The sensitivity table as a grid: m_max [kg] rows, rate share columns, T-year energy [kJ] values."""
    g = table.pivot(index="m_max_kg", columns="rate_share", values="energy_kj")
    g.index = [f"m_max {sig(v)} kg" if np.isfinite(v) else "m_max none" for v in g.index]
    g.columns = [f"share {c:g}" for c in g.columns]
    return g


__all__ = ["EnergyAnalysis", "INTERVAL_COVERS", "analyse_energy", "design_energy_sensitivity", "sensitivity_grid"]
