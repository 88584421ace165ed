"""The magnitude-frequency analysis of one inventory: power law, Gumbel and GEV side by side.

:func:`analyse_inventory` runs every fit the data allow and
:class:`FrequencyAnalysis` turns them into the design-mass table, figures and
machine-readable summaries written by ``riskrf fit``.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .extremes import MIN_MAXIMA, GEVFit, GumbelFit, fit_gev, fit_gumbel
from .inventory.record import Inventory
from ..io.outputs import write_json
from .power_law import (
    LARGE_SAMPLE,
    GutenbergRichterFit,
    PowerLawBootstrap,
    fit_gutenberg_richter,
)
from ..core.format import sig
from ..core.units import DESIGN_RETURN_PERIODS  # noqa: F401  (also importable from here, as before)
from ..core.validation import RiskrfWarning
from simulation._display import Displayed, short_repr



@dataclass(frozen=True, repr=False)
class FrequencyAnalysis(Displayed):
    """Every magnitude-frequency model fitted to one inventory.

    The fits, the comparison table and the bootstrap are computed when the object is built
    (:func:`analyse_inventory`).  The design-mass table is lazy: :meth:`design_masses` computes its
    intervals (profile likelihood and the fits' standard errors) on the first call for a given (T, level) and keeps
    them in a private cache; later calls, and :meth:`write`, return copies of the same table.  The
    object is otherwise immutable, so the cache never goes stale.
    """

    inventory: Inventory
    power_law: GutenbergRichterFit
    power_law_lsq: GutenbergRichterFit | None
    bootstrap_p: float | None
    n_bootstrap: int
    seed: int | None
    comparison: pd.DataFrame
    maxima: pd.Series | None = None
    gumbel: GumbelFit | None = None
    gev: GEVFit | None = None
    deviance: dict | None = None
    skipped: dict = field(default_factory=dict)
    warnings: tuple = ()
    bootstrap: PowerLawBootstrap | None = None
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def design_masses(self, T=DESIGN_RETURN_PERIODS, level: float = 0.95) -> pd.DataFrame:
        """Design masses [kg] by return period from each model, with intervals.

        Models: ``power law N(>=m)=1/T`` (Wyllie's return period of a mass),
        ``power law annual max`` (the T-year annual maximum the Poisson power law
        implies), ``Gumbel`` and ``GEV`` (annual maxima).  ``extrapolated`` marks
        return periods longer than twice the record.

        Parameters
        ----------
        T : float or sequence of float
            Return periods [yr] (default :data:`riskrf.core.units.DESIGN_RETURN_PERIODS`).
        level : float
            Confidence level of the intervals.

        Returns
        -------
        pandas.DataFrame
            One row per (model, return period): ``model``, ``T_years``, ``mass_kg``, ``ci_low_kg``,
            ``ci_high_kg``, ``volume_m3``, ``ci_method`` and ``extrapolated``.
        """
        key = (tuple(np.atleast_1d(T).tolist()), level)
        if key not in self._cache:          # profile-likelihood intervals are worth computing once
            self._cache[key] = self._design_masses(np.asarray(T, dtype=float), level)
        return self._cache[key].copy()

    def _design_masses(self, T, level):
        rows = []
        gr = self.power_law
        rho = self.inventory.density_kg_m3
        record = self.inventory.duration_years

        def add(model, values, lo, hi, how):
            for t, v, a, b in zip(T, values, lo, hi):
                rows.append({"model": model, "T_years": t, "mass_kg": v, "ci_low_kg": a, "ci_high_kg": b,
                             "volume_m3": v / rho, "ci_method": how, "extrapolated": bool(t > 2 * record)})

        valid = T * gr.rate_min >= 1
        if valid.any():
            Tv = T[valid]
            lo, hi = gr.return_level_ci(Tv, level)
            fill = np.full(T.size, np.nan)
            vals, los, his = fill.copy(), fill.copy(), fill.copy()
            vals[valid], los[valid], his[valid] = gr.mass_at_return_period(Tv), lo, hi
            add("power law N(>=m)=1/T", vals, los, his, "delta method (b, rate)")
        add("power law annual max", gr.annual_max_return_level(T), np.full(T.size, np.nan),
            np.full(T.size, np.nan), "")
        for name, fit in (("Gumbel", self.gumbel), ("GEV", self.gev)):
            if fit is None:
                continue
            lo, hi = fit.return_level_ci(T, level=level)
            add(f"{name} ({fit.method})", fit.return_level(T), lo, hi, fit.default_ci_method)
        return pd.DataFrame(rows)

    def preferred_model(self) -> dict:
        """Which annual-maximum model to use for design masses, and why, in words.

        Rules: when the deviance test does not reject the Gumbel (p >= 0.05) the
        simpler Gumbel is preferred.  When it does, the GEV is preferred only if
        its shape is plausible (xi < 0.5: finite mean and variance).  With
        0.5 <= xi < 1 the variance is infinite and with xi >= 1 even the mean
        is: no rock slope produces unboundedly large falls, so the GEV is then
        read as evidence of a heavy (power-law) size tail (maxima of
        power-law sizes are Fréchet with xi = 1/b: Embrechts, Klüppelberg &
        Mikosch 1997, section 3.3.1), and
        the power law, with an upper truncation m_max where one can be
        justified, is preferred for design masses; the GEV's return levels are
        not used beyond the record.

        Returns
        -------
        dict
            ``model`` (``"Gumbel"``, ``"GEV"`` or ``"power law"``), ``reason`` (a sentence),
            ``gev_shape_plausible`` (bool or None).

        References
        ----------
        Embrechts, P., Klüppelberg, C. & Mikosch, T. (1997). Modelling Extremal Events. Springer, section 3.3.1.
        Coles, S. (2001). An Introduction to Statistical Modeling of Extreme Values. Springer, §2.6.6 (deviance).
        """
        gr, gev, d = self.power_law, self.gev, self.deviance
        if gev is None or d is None:
            if self.gumbel is not None:
                return {"model": "Gumbel", "gev_shape_plausible": None,
                        "reason": "too few annual maxima for the GEV; the Gumbel is the only annual-maximum model"}
            return {"model": "power law", "gev_shape_plausible": None,
                    "reason": "no annual maxima (undated record); the power law is the only model"}
        xi = gev.shape
        implied = 1.0 / gr.b if gr.b > 0 else np.inf
        if d["gumbel_adequate"]:
            return {"model": "Gumbel", "gev_shape_plausible": bool(xi < 0.5),
                    "reason": f"the deviance test does not reject the Gumbel (D = {sig(d['deviance'], 4)}, "
                              f"p = {sig(d['p_value'], 2)}); the simpler model is preferred"}
        if xi < 0.5:
            return {"model": "GEV", "gev_shape_plausible": True,
                    "reason": f"the deviance test rejects the Gumbel (D = {sig(d['deviance'], 4)}, "
                              f"p = {sig(d['p_value'], 2)}) "
                              f"and the GEV shape xi = {xi:.3f} is plausible (finite mean and variance)"}
        what = "mean and variance are" if xi >= 1 else "variance is"
        return {"model": "power law", "gev_shape_plausible": False,
                "reason": f"the deviance test rejects the Gumbel (D = {sig(d['deviance'], 4)}, "
                          f"p = {sig(d['p_value'], 2)}), but "
                          f"the GEV shape xi = {xi:.2f} ± {gev.stderr[2]:.2f} is implausible: its {what} infinite, "
                          f"which no rock slope can produce.  It says the sizes have a heavy, power-law tail: "
                          f"power-law sizes give Fréchet maxima with xi = 1/b = {implied:.2f} (b = {gr.b:.3f}).  "
                          f"Use the power law for design masses (with m_max if a largest credible block can be "
                          f"justified) and read GEV return levels only within the "
                          f"{self.inventory.duration_years:.0f}-year record; the Gumbel understates the tail"
                          + (f".  Caution: the bootstrap rejects an exact power law "
                             f"(p = {sig(self.bootstrap_p, 2)}), so "
                             "the tail beyond the record is uncertain; compare the lognormal alternative"
                             if self.bootstrap_p is not None and self.bootstrap_p <= 0.1 else "")}

    def design_table(self, T=DESIGN_RETURN_PERIODS) -> pd.DataFrame:
        """Wide table of design masses [kg]: one row per return period, one column per model.

        Parameters
        ----------
        T : float or sequence of float
            Return periods [yr].

        Returns
        -------
        pandas.DataFrame
            Indexed by ``T_years``; one column of masses [kg] per model.
        """
        d = self.design_masses(T)
        return d.pivot(index="T_years", columns="model", values="mass_kg")

    def to_dict(self) -> dict:
        """The fits as plain JSON-ready values (for summary.json).

        Returns
        -------
        dict
            Inventory facts, units, each model's parameters, the design masses [kg] and the preferred model.
        """
        gr = self.power_law
        out = {
            "inventory": self.inventory.summary()["value"].to_dict(),
            "units": {"mass": "kg", "volume": "m3", "rate": "1/yr", "return_period": "yr"},
            "power_law": {
                "method": gr.method, "a": gr.a, "b": gr.b, "b_stderr": gr.b_stderr, "b_ci": list(gr.b_ci),
                "b_ci_method": gr.b_ci_method, "m_min_kg": gr.m_min, "m_min_method": gr.m_min_method,
                "m_max_kg": gr.m_max, "rate_min_per_year": gr.rate_min, "n_tail": gr.n_tail,
                "ks_distance": gr.ks_distance, "bootstrap_p_value": self.bootstrap_p,
                "n_bootstrap": self.n_bootstrap, "seed": self.seed,
                "bootstrap_threshold_grid": None if self.bootstrap is None else self.bootstrap.grid,
                "bootstrap_ks_distance": None if self.bootstrap is None else self.bootstrap.ks_distance,
                "likelihood_ratio_tests": self.comparison.reset_index().to_dict(orient="records"),
            },
            "design_masses": self.design_masses().to_dict(orient="records"),
            "skipped": self.skipped,
            "preferred_model": self.preferred_model(),
            "warnings": list(self.warnings),
        }
        if self.power_law_lsq is not None:
            lsq = self.power_law_lsq
            out["power_law_lsq"] = {"a": lsq.a, "b": lsq.b, "b_stderr": lsq.b_stderr, "m_min_kg": lsq.m_min,
                                    "note": "least squares on log cumulative frequency (practitioners' method)"}
        for name, fit in (("gumbel", self.gumbel), ("gev", self.gev)):
            if fit is not None:
                out[name] = {"method": fit.method, **dict(zip(fit.param_names, fit.params)),
                             "stderr": list(fit.stderr), "p_zero": fit.p_zero, "n_years": fit.n_years,
                             "n_maxima": int(fit.data.size), "loglik": fit.loglik,
                             "ci_method": fit.default_ci_method}
        if self.deviance is not None:
            out["gumbel_vs_gev"] = self.deviance
        return out

    def __repr__(self) -> str:
        gr = self.power_law
        fitted = ["power law"] + [n for n, f in (("Gumbel", self.gumbel), ("GEV", self.gev)) if f is not None]
        return short_repr(self, repr(Path(str(self.inventory.source)).name), "+".join(fitted), b=gr.b,
                          m_min=gr.m_min, bootstrap_p=self.bootstrap_p)

    def summary(self) -> pd.DataFrame:
        """One row per fitted model: its parameters, log-likelihood and how well it fits.

        Returns
        -------
        pandas.DataFrame
            Indexed by model (``power law``, ``power law (least squares)``, ``Gumbel``, ``GEV``), columns
            ``parameters`` (text, masses in kg), ``n`` (values fitted), ``loglik`` (NaN where not defined) and
            ``note`` (KS distance and bootstrap p-value of the power law; the method of the others).
        """
        gr = self.power_law
        rows = [("power law", f"a = {gr.a:.4g}, b = {gr.b:.4g} ± {gr.b_stderr:.3g}, m_min = {gr.m_min:.4g} kg",
                 gr.n_tail, np.nan, f"KS distance {gr.ks_distance:.4f}" + (
                     f"; bootstrap p = {self.bootstrap_p:.3f} ({self.n_bootstrap} replicates)"
                     if self.bootstrap_p is not None else ""))]
        if self.power_law_lsq is not None:
            lsq = self.power_law_lsq
            rows.append(("power law (least squares)", f"a = {lsq.a:.4g}, b = {lsq.b:.4g} ± {lsq.b_stderr:.3g}",
                         lsq.n_tail, np.nan, "practitioners' method, for comparison"))
        for name, fit in (("Gumbel", self.gumbel), ("GEV", self.gev)):
            if fit is not None:
                rows.append((name, ", ".join(f"{p} = {v:.4g}" for p, v in zip(fit.param_names, fit.params)),
                             int(fit.data.size), fit.loglik, f"{fit.method}; p_zero = {fit.p_zero:.3f}"))
        for name, why in self.skipped.items():
            rows.append((name, "", 0, np.nan, f"not fitted: {why}"))
        return pd.DataFrame(rows, columns=["model", "parameters", "n", "loglik", "note"]).set_index("model")

    def plot(self, ax=None):
        """The power law over the inventory's magnitude-frequency curve (:meth:`GutenbergRichterFit.plot`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            x: mass m [kg]; y: falls of at least m per year [1/yr], log-log.
        """
        return self.power_law.plot(ax)

    def summary_text(self) -> str:
        """A readable report of the fits (what ``riskrf fit`` prints).

        Returns
        -------
        str
            Several lines of text (masses in kg, rates per year).
        """
        inv, gr = self.inventory, self.power_law
        lines = [f"Inventory: {inv.source}" + (f"  ({inv.site})" if inv.site else ""),
                 f"  {inv.n_events} falls over {inv.duration_years:.3g} years (record period from "
                 f"{inv.period_source}); density {inv.density_kg_m3:g} kg/m3"
                 + (" (default)" if inv.density_is_default else ""), "",
                 "Power law  log10 N(>=m) = a - b log10 m   [N per year, m in kg]  (Wyllie 2014, 8.4.1)",
                 "  method   maximum likelihood (Aki 1965 / Clauset et al. 2009)" if gr.method == "mle" else
                 "  method   least squares (practitioners' method)",
                 f"  b        {gr.b:.4f} ± {gr.b_stderr:.4f}  ({gr.level:.0%} interval {gr.b_ci[0]:.4f} - "
                 f"{gr.b_ci[1]:.4f}, {gr.b_ci_method.split(' (')[0]})",
                 f"  a        {gr.a:.4f}",
                 f"  m_min    {gr.m_min:.5g} kg ({sig(gr.m_min / inv.density_kg_m3, 4)} m3), "
                 f"{'Kolmogorov-Smirnov search' if gr.m_min_method == 'ks' else 'given'}; "
                 f"{gr.n_tail} of {gr.n_total} falls above it, {sig(gr.rate_min, 4)} per year"]
        if gr.m_max is not None:
            lines.append(f"  m_max    {gr.m_max:.5g} kg (upper truncation)")
        if self.bootstrap_p is not None:
            verdict = "plausible" if self.bootstrap_p > 0.1 else "rejected"
            lines.append(f"  fit      KS distance {gr.ks_distance:.4f}; bootstrap p = {self.bootstrap_p:.3f} "
                         f"({self.n_bootstrap} replicates, seed {self.seed}): power law {verdict} (plausible when p > 0.1)")
            if self.bootstrap is not None and self.bootstrap.grid is not None:
                lines.append(f"           (above {LARGE_SAMPLE:,} falls the data and each replicate scan "
                             f"{self.bootstrap.grid:,} log-spaced thresholds, not every value: KS distance of the "
                             f"data on that grid {self.bootstrap.ks_distance:.4f}; --bootstrap-grid 0 for the full scan)")
        for alt, row in self.comparison.iterrows():
            lines.append(f"  vs {alt:<12} log-likelihood ratio R = {row['loglik_ratio_R']:+.2f}, "
                         f"p = {row['p_value']:.3f} -> {row['favoured']}")
        if self.power_law_lsq is not None:
            lsq = self.power_law_lsq
            lines.append(f"  least squares (for comparison): b = {lsq.b:.4f} ± {lsq.b_stderr:.4f}, a = {lsq.a:.4f}")
        for name, fit in (("Gumbel", self.gumbel), ("GEV", self.gev)):
            if fit is None:
                continue
            se = fit.stderr
            pars = ", ".join(f"{p} = {v:.5g} ± {s:.3g}" for p, v, s in zip(fit.param_names, fit.params, se))
            lines += ["", f"{name} of annual maxima ({fit.method}; {fit.data.size} maxima in {fit.n_years} years, "
                          f"p0 = {fit.p_zero:.3f} years without a fall)", f"  {pars}"]
        if self.deviance is not None:
            d = self.deviance
            lines.append(f"  deviance Gumbel vs GEV: D = {d['deviance']:.3f}, p = {d['p_value']:.3f} -> "
                         f"{'Gumbel adequate' if d['gumbel_adequate'] else 'GEV needed'}")
        for name, why in self.skipped.items():
            lines += ["", f"{name}: not fitted ({why})"]
        if inv.is_dated:
            every = inv.all_events()
            per_year = every.groupby(every["year"].astype("Int64")).size().reindex(inv.record_years(), fill_value=0)
            lines += ["", f"Completeness: events per year {per_year.index[0]}-{per_year.index[-1]} "
                          f"(all sizes, {inv.n_censored} censored or without size included; see completeness.csv):",
                      "  " + " ".join(str(int(n)) for n in per_year.to_numpy())]
        pref = self.preferred_model()
        lines += ["", f"Preferred model: {pref['model']}: {pref['reason']}."]
        table = self.design_table()
        lines += ["", "Design masses [kg] by return period (intervals in design_masses.csv):",
                  table.to_string(float_format=lambda v: sig(v, 4))]
        if self.warnings:
            lines += ["", "Warnings:"] + [f"  - {w}" for w in self.warnings]
        return "\n".join(lines)

    def write(self, out_dir, *, design_masses_name: str = "design_masses", basis: str | None = None) -> list[Path]:
        """Write summary.json, design_masses.csv and completeness.csv into ``out_dir``; returns the files written.
        The figures are drawn by :func:`riskrf.report.files.write_frequency_study`, which calls this first.

        ``basis``: what the design-mass table is, when it is not the site's own (``riskrf assess`` labels the
        whole wall's fit and another record's so): a ``basis`` column in the table, written as
        ``design_masses_name``.csv, and in summary.json the table under ``design_masses_name`` with
        ``design_masses_name``_basis.

        Parameters
        ----------
        out_dir : str or path
            An existing directory.
        design_masses_name : str
            File stem of the design-mass table.
        basis : str, optional
            What the design-mass table is, when it is not the site's own.

        Returns
        -------
        list of pathlib.Path
            The files written.
        """
        out = Path(out_dir)
        data, table = self.to_dict(), self.design_masses()
        if basis is not None:
            table = table.assign(basis=basis)
            data[design_masses_name] = [dict(r, basis=basis) for r in data.pop("design_masses")]
            data[design_masses_name + "_basis"] = basis
        write_json(data, out / "summary.json")
        table.to_csv(out / f"{design_masses_name}.csv", index=False)
        self.inventory.completeness().to_csv(out / "completeness.csv")
        return [out / "summary.json", out / f"{design_masses_name}.csv", out / "completeness.csv"]


def analyse_inventory(inventory: Inventory, *, m_min=None, method: str = "mle", m_max=None,
                      gumbel_method: str = "mle", n_bootstrap: int = 1000, seed: int | None = 1,
                      compare_lsq: bool = True, bootstrap_workers: int | None = None, progress=None,
                      bootstrap_grid="auto") -> FrequencyAnalysis:
    """Fit the power law to all masses and, when the inventory is dated, Gumbel and GEV to annual maxima.

    Every warning raised by the fits is collected in ``warnings``; models the
    data cannot support are listed in ``skipped`` with the reason.
    Parameters
    ----------
    inventory : Inventory
        The record (masses [kg], duration [yr]).
    m_min : float, optional
        Completeness threshold [kg]; None for the Kolmogorov-Smirnov search (Clauset et al. 2009).
    method : {"mle", "lsq"}
        Power-law fitting method.
    m_max : float, optional
        Upper truncation [kg].
    gumbel_method : {"mle", "moments", "lmoments"}
        Gumbel fitting method.
    n_bootstrap : int
        Replicates of the power law's goodness-of-fit bootstrap (0: none).
    seed : int, optional
        Seed of the bootstrap.
    compare_lsq : bool
        Also fit the least-squares power law, for comparison.
    bootstrap_workers, progress, bootstrap_grid
        Passed to :meth:`GutenbergRichterFit.bootstrap_test` (``workers``, ``progress``, ``grid``).

    Returns
    -------
    FrequencyAnalysis
        The fits, the comparison of the power law with its alternatives, the bootstrap and the warnings.

    References
    ----------
    Clauset, A., Shalizi, C. R. & Newman, M. E. J. (2009). Power-law distributions in empirical data. SIAM Review
    51(4), 661-703.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RiskrfWarning)
        gr = fit_gutenberg_richter(inventory.masses, inventory.duration_years, m_min=m_min, method=method,
                                   m_max=m_max)
        lsq = None
        if compare_lsq and method == "mle":
            try:
                lsq = fit_gutenberg_richter(inventory.masses, inventory.duration_years, m_min=gr.m_min,
                                            method="lsq")
            except ValueError:
                lsq = None
        boot = gr.bootstrap_test(n_bootstrap, seed=seed, workers=bootstrap_workers, progress=progress,
                                 grid=bootstrap_grid) if (n_bootstrap and method == "mle") else None
        p = None if boot is None else boot.p_value
        comparison = gr.compare()
        maxima = gumbel = gev = deviance = None
        skipped = {}
        if not inventory.has_dates:
            skipped["Gumbel/GEV"] = "the inventory has no dates, so there are no annual maxima"
        else:
            maxima = inventory.annual_maxima()
            n_max = int(maxima.notna().sum())
            if n_max >= MIN_MAXIMA["gumbel"]:
                gumbel = fit_gumbel(maxima, method=gumbel_method)
            else:
                skipped["Gumbel"] = f"{n_max} annual maxima; at least {MIN_MAXIMA['gumbel']} are needed"
            if n_max >= MIN_MAXIMA["gev"]:
                gev = fit_gev(maxima)
                deviance = gev.deviance_vs_gumbel()
            else:
                skipped["GEV"] = f"{n_max} annual maxima; at least {MIN_MAXIMA['gev']} are needed"
    notes = list(inventory.notes)
    for w in caught:
        msg = str(w.message)
        if msg not in notes:
            notes.append(msg)
    return FrequencyAnalysis(inventory=inventory, power_law=gr, power_law_lsq=lsq, bootstrap_p=p,
                             n_bootstrap=int(n_bootstrap or 0), seed=seed, comparison=comparison, maxima=maxima,
                             gumbel=gumbel, gev=gev, deviance=deviance, skipped=skipped, warnings=tuple(notes),
                             bootstrap=boot)
