"""Which inputs can change the mitigation study's answer, and by how much: the tornado, the break-even values of
every input (material parameters included) and the value of perfect information about the fall rate
(:class:`SensitivityMixin`, a part of :class:`~riskrf.risk.mitigation.MitigationStudy`).  Money in the study
currency.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .measures import material_value
from .mitigation_inputs import MitigationError


class SensitivityMixin:
    """The sensitivity methods of :class:`~riskrf.risk.mitigation.MitigationStudy` (they use its central-value
    engine, parameter ranges and slope models)."""

    def sensitivity_parameters(self) -> list:
        """Every input that can change the order: all engine parameters with an effect.

        Returns
        -------
        list of str
            The names of :meth:`central_parameters`.
        """
        return list(self.central_parameters())

    def _tornado_range(self, name, value):
        ranges = self.parameter_ranges()
        if name in ranges:
            return ranges[name][0], ranges[name][1], ranges[name][2]
        if name.startswith(("retention:", "rate_reduction:", "scaling_effectiveness:", "containment:")):
            return max(value - 0.2, 0.0), min(value + 0.2, 1.0), "+-0.2 (no range stated)"
        if name == "discount_rate":
            return value * 0.5, min(value * 2, 0.2), "x0.5 / x2 (no range stated)"
        if name == "fractal_dimension":
            return max(value - 0.25, 0.05), min(value + 0.25, 2.95), "+-0.25 (no range stated)"
        return value * 0.5, value * 2.0, "x0.5 / x2 (no range stated)"

    def tornado(self) -> pd.DataFrame:
        """Lowest expected total cost (central values) as each input moves over its stated range (or x0.5/x2),
        with the best option at each end, whether the best or the whole order changes; inputs that change the
        best first, then those that change the order, each by swing.  Material parameters are re-simulated at
        both ends of their ranges.

        Returns
        -------
        pandas.DataFrame
            One row per input: ``parameter``, ``low``, ``high`` (its own unit), ``range`` (basis in words),
            ``changes_order``, ``cost_at_low``, ``cost_at_high`` and ``base`` (lowest total cost [study currency]),
            ``best_at_low``, ``best_at_high``, ``changes_best`` and ``swing`` [study currency].
        """
        c = self.central_parameters()
        base_r = self._central_result
        base = float(base_r.total[0].min())
        names = base_r.names
        rows = []
        items = [(p, v) for p, v in c.items() if p != "material_draw"]
        labels = [m.label for m in self._models]
        for name, (lo, hi, how) in self.parameter_ranges().items():
            if name.startswith("material:"):
                path = name.split(":", 1)[1]
                items.append((name, (labels.index(f"{path} low"), labels.index(f"{path} high"), lo, hi, how)))
        for p, v in items:
            if p.startswith("material:"):
                i_lo, i_hi, lo, hi, how = v
                t = self._central({"material_draw": [i_lo, i_hi]}).total
            else:
                lo, hi, how = self._tornado_range(p, v)
                if lo == hi:
                    continue                     # e.g. a zero cost: nothing to vary
                t = self._central({p: [lo, hi]}).total
            order = list(np.argsort(base_r.total[0], kind="stable"))
            rows.append({"parameter": p, "low": lo, "high": hi, "range": how,
                         "changes_order": any(list(np.argsort(row, kind="stable")) != order for row in t),
                         "cost_at_low": t[0].min(), "cost_at_high": t[1].min(),
                         "best_at_low": names[int(np.argmin(t[0]))], "best_at_high": names[int(np.argmin(t[1]))],
                         "base": base})
        df = pd.DataFrame(rows)
        best = names[int(np.argmin(base_r.total[0]))]
        df["changes_best"] = (df["best_at_low"] != best) | (df["best_at_high"] != best)
        df["swing"] = (df["cost_at_high"] - df["cost_at_low"]).abs()
        return df.sort_values(["changes_best", "changes_order", "swing"], ascending=[False, False, False]
                              ).reset_index(drop=True)

    def _bracket(self, name, value):
        if name.startswith(("retention:", "rate_reduction:", "scaling_effectiveness:", "containment:")):
            return 0.0, 1.0, False
        if name == "b":
            return 0.2, 3.0, False
        if name == "discount_rate":
            return 0.0, 0.3, False
        if name == "vulnerability_factor":
            return 1e-3, 1e3, True
        if name == "fractal_dimension":
            return 1e-6, 3.0 - 1e-9, False
        return max(value, 1.0) * 1e-3 if value > 0 else 0.0, max(value, 1.0) * 1e3, True

    def break_even(self, parameter: str, *, option_a: str | None = None, option_b: str | None = None):
        """Value of ``parameter`` (others central) at which options a and b (default: the two cheapest at
        central values) cost the same; None if they do not tie within the searched range.

        Parameters
        ----------
        parameter : str
            A name of :meth:`central_parameters`.
        option_a, option_b : str, optional
            The two options to tie (default the cheapest and second-cheapest at central values).

        Returns
        -------
        (float, float) or None
            ``(factor, value)``: the tie value in the parameter's own unit and its ratio to the central value [-] (NaN
            when the central value is 0); None when the options do not tie within the searched range.

        Raises
        ------
        MitigationError
            When ``parameter`` is not a parameter of the study.
        """
        r = self._central_result
        names = r.names
        order = np.argsort(r.total[0], kind="stable")
        a = option_a or names[order[0]]
        b = option_b or names[order[1]]
        ia, ib = names.index(a), names.index(b)
        c = self.central_parameters()
        if parameter not in c:
            raise MitigationError(f"unknown sensitivity parameter {parameter!r}; parameters are {sorted(c)}")
        lo, hi, log = self._bracket(parameter, c[parameter])
        grid = np.geomspace(max(lo, 1e-12), hi, 161) if log else np.linspace(lo, hi, 161)
        try:
            t = self._central({parameter: grid}).total
        except ValueError:
            return None
        d = t[:, ia] - t[:, ib]
        cross = np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0]
        if cross.size == 0:
            return None
        # the crossing nearest the current value
        j = cross[np.argmin(np.abs(grid[cross] - c[parameter]))]
        from scipy.optimize import brentq

        def diff(x):
            tt = self._central({parameter: [x]}).total[0]
            return tt[ia] - tt[ib]
        x = float(brentq(diff, grid[j], grid[j + 1], xtol=1e-12 * max(abs(grid[j + 1]), 1.0)))
        return x / c[parameter] if c[parameter] else np.nan, x

    def break_even_table(self) -> pd.DataFrame:
        """For every input: the value at which the second-cheapest option would tie with the cheapest, and
        whether that value lies inside the stated range.

        Returns
        -------
        pandas.DataFrame
            One row per input: ``parameter``, ``current``, ``break_even``, ``range_low``, ``range_high`` (its own
            unit), ``factor`` [-], ``within_stated_range`` and ``note``.
        """
        r = self._central_result
        order = np.argsort(r.total[0], kind="stable")
        a, b = r.names[order[0]], r.names[order[1]]
        ranges = self.parameter_ranges()
        rows = []
        for p, v in self.central_parameters().items():
            if p == "material_draw":
                continue                 # material parameters: below, from their re-simulated low and high models
            be = self.break_even(p, option_a=a, option_b=b)
            lo, hi = (ranges[p][0], ranges[p][1]) if p in ranges else (np.nan, np.nan)
            inside = bool(be is not None and p in ranges and lo <= be[1] <= hi)
            rows.append({"parameter": p, "current": v, "break_even": be[1] if be else np.nan,
                         "factor": be[0] if be else np.nan, "range_low": lo, "range_high": hi,
                         "within_stated_range": inside,
                         "note": f"{b!r} ties with {a!r}" if be else "no tie within the searched range"})
        rows += self._material_break_even(a, b, ranges)
        return pd.DataFrame(rows)

    def _material_break_even(self, a: str, b: str, ranges: dict) -> list:
        """Break-even rows of the uncertain material parameters.  Each is re-simulated only at the low and high
        ends of its range (the slope models of the tornado), so the tie of options a and b is found by linear
        interpolation of their cost difference between the low, base (reference) and high models; the tie
        nearest the current value, or none within [low, high]."""
        materials = [p for p in ranges if p.startswith("material:")]
        if not materials or self.context is None:
            return []
        names = self._central_result["names"]
        ia, ib = names.index(a), names.index(b)
        labels = [m.label for m in self._models]
        rows = []
        for p in materials:
            path = p.split(":", 1)[1]
            lo, hi, _ = ranges[p]
            current = float(material_value(self.context.scenario, path))
            draws = [labels.index(f"{path} low"), 0, labels.index(f"{path} high")]
            t = self._central({"material_draw": draws}).total
            x, d = np.array([lo, current, hi], dtype=float), t[:, ia] - t[:, ib]
            keep = np.argsort(x, kind="stable")
            x, d = x[keep], d[keep]
            ties = [float(x[j]) for j in range(3) if d[j] == 0]
            ties += [float(x[j] + (x[j + 1] - x[j]) * d[j] / (d[j] - d[j + 1])) for j in range(2)
                     if d[j] * d[j + 1] < 0]
            tie = min(ties, key=lambda v: abs(v - current)) if ties else None
            how = "linear interpolation of the cost difference between the re-simulated low, base and high models"
            rows.append({"parameter": p, "current": current, "break_even": np.nan if tie is None else tie,
                         "factor": np.nan if tie is None or not current else tie / current,
                         "range_low": lo, "range_high": hi, "within_stated_range": tie is not None,
                         "note": (f"{b!r} ties with {a!r} ({how})" if tie is not None
                                  else f"no tie within [{lo:g}, {hi:g}] ({how})")})
        return rows

    def value_of_information(self, factors=(0.5, 1.0, 2.0), weights=(0.25, 0.5, 0.25)) -> dict:
        """Expected value of perfect information about the rate of falls (``factors`` x the estimate with
        ``weights``), and about every sampled input at once (from the joint samples).

        Parameters
        ----------
        factors : sequence of float, optional
            Multiples [-] of the estimated rate of falls (each > 0; default 0.5, 1, 2).
        weights : sequence of float, optional
            Their probabilities [-] (as many, >= 0, summing to 1; default 0.25, 0.5, 0.25).

        Returns
        -------
        dict
            ``evpi``, ``expected_cost_now`` and ``expected_cost_informed`` [study currency], ``best_now``,
            ``best_by_rate`` (factor -> best option), ``factors``, ``weights`` and ``evpi_all_sampled_inputs``
            [study currency].

        Raises
        ------
        MitigationError
            When ``factors`` and ``weights`` do not fit.

        References
        ----------
        Raiffa, H. & Schlaifer, R. (1961) Applied Statistical Decision Theory. Harvard, ch. 4.
        """
        f = np.asarray(factors, dtype=float)
        w = np.asarray(weights, dtype=float)
        if f.shape != w.shape or np.any(f <= 0) or np.any(w < 0) or abs(w.sum() - 1) > 1e-9:
            raise MitigationError(f"value_of_information: factors {f.tolist()} must be > 0 and weights {w.tolist()} "
                                  "non-negative, as many, summing to 1")
        r = self._central({"rate_factor": f})
        t = r.total
        names = r.names
        expected = w @ t
        now = int(np.argmin(expected))
        informed = float(w @ t.min(axis=1))
        return {"evpi": float(expected[now] - informed), "best_now": names[now],
                "expected_cost_now": float(expected[now]), "expected_cost_informed": informed,
                "best_by_rate": {f"x{x:g}": names[int(np.argmin(row))] for x, row in zip(f, t)},
                "factors": f.tolist(), "weights": w.tolist(),
                "evpi_all_sampled_inputs": self.uncertain["evpi"]}


__all__ = ["SensitivityMixin"]
