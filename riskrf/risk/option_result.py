"""The central-value result of one mitigation option (:meth:`riskrf.risk.mitigation.MitigationStudy.evaluate`):
rates per year, money in the study currency."""
from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from simulation._display import Displayed, short_repr

from .mitigation_inputs import Option


@dataclass(frozen=True)
class OptionResult(Displayed):
    """Central-value results of one option (rates per year, money in the study currency)."""

    option: Option
    road_falls_per_year: float
    repairs_per_year: float
    replacements_per_year: float
    vehicle_hits_per_year: float
    rock_strikes_per_year: float
    deaths_per_year: float
    expected_annual_loss: float
    individual_risk: float
    retention: float | None
    effectiveness: float

    @property
    def held_impacts_above_sel_per_year(self) -> float:
        """Impacts per year [1/yr] held by the barrier above its service energy level (SEL = MEL / 3), each
        needing a repair; the same number as ``repairs_per_year``.
        """
        return self.repairs_per_year

    def __repr__(self) -> str:
        return short_repr(self, repr(self.option.name), kind=self.option.kind,
                          road_falls_per_year=self.road_falls_per_year, deaths_per_year=self.deaths_per_year,
                          expected_annual_loss=self.expected_annual_loss)

    def summary(self) -> pd.DataFrame:
        """The central-value results as one row.

        Returns
        -------
        pandas.DataFrame
            One row: ``option``, ``kind`` and every rate [1/yr], the expected annual loss [study currency/yr],
            the individual risk [1/yr], the retention and the effectiveness (shares, 0-1).
        """
        row = {"option": self.option.name, "kind": self.option.kind}
        row.update({k: getattr(self, k) for k in (
            "road_falls_per_year", "repairs_per_year", "replacements_per_year", "vehicle_hits_per_year",
            "rock_strikes_per_year", "deaths_per_year", "expected_annual_loss", "individual_risk", "retention",
            "effectiveness")})
        return pd.DataFrame([row])


__all__ = ["OptionResult"]
