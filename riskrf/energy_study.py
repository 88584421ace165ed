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
from .power_law import GutenbergRichterFit
from .units import DEFAULT_DENSITY_KG_M3


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

    def fence_verdicts(self) -> pd.DataFrame:
        rows = []
        for name, table in self.fences.items():
            rows.append({"fence": name, "adequate": bool(table["adequate"].all()),
                         "failed checks": "; ".join(table.loc[~table["adequate"], "check"]) or "none"})
        return pd.DataFrame(rows)

    def summary_text(self) -> str:
        hz = self.hazard
        lines = ["Impact energy hazard at the barrier line (Wyllie 2014, 8.1-8.3)",
                 f"  falls per year (mass model)   {hz.rate_per_year:.4g}   [{hz.summary().loc['mass model', 'value']}]",
                 f"  reach probability             {hz.reach_probability:.4f}"
                 + (f"  ({hz.n_released:,} simulated blocks)" if hz.n_released else ""),
                 f"  arrivals per year             {hz.arrival_rate:.4g}"]
        for note in hz.notes:
            lines.append(f"  {note}")
        e95, e99 = hz.energy_percentile([95, 99])
        lines.append(f"  energy per arriving fall      p95 {e95:,.4g} kJ, p99 {e99:,.4g} kJ")
        if hz.heights_m is not None:
            lines.append(f"  bounce height                 p95 {hz.height_percentile(95):.3g} m, "
                         f"p99 {hz.height_percentile(99):.3g} m (block centre above the slope)")
        lines += ["", f"Design energies (interval: {self.n_bootstrap} bootstrap replicates, seed {self.seed}; "
                      "sources: b, rate, finite simulation):"]
        d = self.design.copy()
        lines.append(d.to_string(index=False, float_format=lambda v: f"{v:,.4g}"))
        if self.uni is not None:
            u = self.uni
            block = u.design_mass_kg / (u.factors["gamma_VolF"] * u.factors["gamma_gamma"])
            lines += ["", f"UNI 11211-4 design energy for the {self.design_T:g}-year block "
                          f"({block:,.4g} kg) at the p95 velocity: "
                          f"E_k = {u.characteristic_energy_kj:,.4g} kJ, E_d = {u.design_energy_kj:,.4g} kJ "
                          f"(gamma_Tr {u.factors['gamma_Tr']}, gamma_Dp {u.factors['gamma_Dp']}, "
                          f"gamma_VolF {u.factors['gamma_VolF']}, gamma_gamma {u.factors['gamma_gamma']})"]
        for name, table in self.fences.items():
            lines += ["", f"Fence {name}:"]
            for _, r in table.iterrows():
                mark = "OK  " if r["adequate"] else "FAIL"
                lines.append(f"  [{mark}] {r['check']}: {r['demand']:,.4g} {r['unit']} vs {r['capacity']:,.4g} "
                             f"{r['unit']}" + (f" (interval {r['interval']})" if r["interval"] else "")
                             + f"; {r['note']}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        hz = self.hazard
        out = {"units": {"energy": "kJ", "height": "m", "rate": "1/yr", "return_period": "yr"},
               "hazard": {k: v for k, v in hz.summary()["value"].items()},
               "design_energies": self.design.to_dict(orient="records"),
               "fences": {name: t.to_dict(orient="records") for name, t in self.fences.items()},
               "notes": list(hz.notes)}
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
        if self.fences:
            pd.concat([t.assign(fence=n) for n, t in self.fences.items()]).to_csv(out / "fence_checks.csv",
                                                                                index=False)
        write_energy_figures(self, out, [float(n.split(" kJ")[0]) for n in self.fences])

def analyse_energy(hazard: EnergyHazard, *, fences=(), fence_height_m=5.0, free_board_m: float = 0.5,
                   T=DESIGN_RETURN_PERIODS, design_T: float = 100.0, density_kg_m3: float = DEFAULT_DENSITY_KG_M3,
                   n_bootstrap: int = 300, seed=1, uni_factors: dict | None = None) -> EnergyAnalysis:
    """Design table, fence checks (each capacity in ``fences`` at ``fence_height_m``: one height [m] for all, or
    one per fence) and UNI 11211-4 energy.  ``design_T`` [yr] must exceed 1 (a T-year event has annual
    probability 1/T); ``free_board_m`` >= 0 and heights > 0 [m]."""
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
    uni = None
    if isinstance(hazard.mass, GutenbergRichterFit) and design_T * hazard.rate_per_year > 1:
        block = float(hazard.mass.isf(1.0 / (design_T * hazard.rate_per_year)))   # the T-year block at this line
        v95 = hazard.velocity_percentile(UNI11211_FACTORS["velocity_percentile"])
        uni = uni11211_design_energy(block / density_kg_m3, density_kg_m3, v95, **(uni_factors or {}))
    return EnergyAnalysis(hazard=hazard, design=design, fences=checks, uni=uni, design_T=float(design_T),
                          density_kg_m3=density_kg_m3, seed=seed, n_bootstrap=int(n_bootstrap))


__all__ = ["EnergyAnalysis", "analyse_energy"]
