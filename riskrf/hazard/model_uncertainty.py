"""Design energies under the trajectory model's uncertainty: how much of an interval is the slope model's.

The interval of a design energy (:meth:`~riskrf.hazard.annual_hazard.EnergyHazard.design_table`) covers the
sampling of the power law's b and rate and the finite number of simulated trajectories, with the slope's
material parameters held at one set of values.  Here the slope is re-simulated for K draws of those parameters
(a posterior sample of a pooled calibration, or the presets' spread: :mod:`simulation.material_uncertainty`),
each draw gives its own hazard, and the T-year energy's spread is split by the law of total variance
(e.g. Saltelli et al. 2008, *Global Sensitivity Analysis: The Primer*, eq. 1.19, the first-order index of a group
of inputs)::

    Var(E_T) = Var_theta( E[E_T | theta] )  +  E_theta( Var[E_T | theta] )
               trajectory model (materials)     statistical: b, rate, finite trajectories

over the pooled bootstrap replicates of every draw (B replicates per draw; the identity is exact for the
population variances of equal groups).  Three intervals are reported beside the shares: the **combined** one
(quantiles of all replicates of all draws), the **trajectory model's** (quantiles of the K draws' point
estimates, the statistical part held at each draw's central value) and the **statistical** one (the replicates'
deviations from their own draw's mean, pooled over draws and put around the mean of the draws: the bootstrap
interval with the model averaged out).

Caveats stated in every output: K draws resolve the model's quantiles coarsely (the extremes of K values at
K < 40 for a 95 % interval); a draw's point estimate carries the Monte Carlo noise of its ``n`` blocks, which
adds to the between-draw variance (common random numbers -- the same seed for every draw -- keep that noise
largely common to all draws, so it moves every draw alike rather than spreading them).

References
----------
Saltelli, A. et al. (2008) Global Sensitivity Analysis: The Primer. Wiley, ch. 1.  Efron, B. & Tibshirani, R.
(1993) An Introduction to the Bootstrap, ch. 13.  Glasserman, P. (2004) Monte Carlo Methods in Financial
Engineering, sec. 4.2 (common random numbers).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from simulation._display import Displayed, short_repr

from ..core.format import sig
from ..core.units import DESIGN_RETURN_PERIODS
from ..core.validation import RiskrfError
from .annual_hazard import EnergyHazard


class ModelUncertaintyError(RiskrfError, ValueError):
    """Model-uncertainty inputs that do not fit (a posterior not matching the scenario, too few draws); the
    message names the file, column or argument."""


#: What the split's "statistical" part covers (stated beside every split).
STATISTICAL_PART = ("statistical: the power law's b and rate (posterior draws) and the finite number of simulated "
                    "trajectories per draw (bootstrap)")
#: What the split's "trajectory model" part covers.
MODEL_PART = "trajectory model: the slope's material parameters (draws re-simulated with the same seed)"


@dataclass(frozen=True)
class DesignEnergySplit(Displayed):
    """T-year energies at a line over K draws of the trajectory model, with the interval split by source.

    ``table``: one row per return period T [yr]: ``energy_kj_reference`` (the hazard at the scenario's own
    values, NaN without one), ``energy_kj_mean`` (mean of the draws' point estimates), the ``combined``,
    ``model`` and ``statistical`` intervals (``*_low_kj``, ``*_high_kj``), the variances [kJ^2] and
    ``share_from_trajectory_model`` = Var_theta(E[E_T|theta]) / Var(E_T).  ``per_draw``: each draw's point
    estimate and bootstrap interval [kJ] per T.  ``basis``: where the draws come from.
    """

    table: pd.DataFrame
    per_draw: pd.DataFrame = field(repr=False)
    n_draws: int
    n_bootstrap: int
    level: float
    basis: str = ""
    notes: tuple = ()

    def __repr__(self) -> str:
        return short_repr(self, f"{self.n_draws} draws", f"T={[float(t) for t in self.table['T_years']]}",
                          n_bootstrap=self.n_bootstrap, level=self.level)

    def summary(self) -> pd.DataFrame:
        """The split per return period.

        Returns
        -------
        pandas.DataFrame
            A copy of :attr:`table` (energies [kJ], variances [kJ^2], share 0-1).
        """
        return self.table.copy()

    def row(self, T: float) -> pd.Series:
        """The split of the T-year energy.

        Parameters
        ----------
        T : float
            Return period [yr], one of the table's.

        Returns
        -------
        pandas.Series
            The table's row for ``T``.

        Raises
        ------
        KeyError
            No row for ``T`` (the message names the return periods there are).
        """
        hit = self.table[np.isclose(self.table["T_years"], float(T))]
        if hit.empty:
            raise KeyError(f"no {T:g}-year row; return periods: {self.table['T_years'].tolist()}")
        return hit.iloc[0]

    def text(self, T: float | None = None) -> list[str]:
        """Plain-text lines for reports: per return period (or only ``T``), the combined interval and the shares
        of its variance from the trajectory model and from the statistical sources.

        Parameters
        ----------
        T : float, optional
            Only this return period [yr]; None for every row.

        Returns
        -------
        list of str
            One line per return period.
        """
        lvl = f"{self.level:.0%}"
        rows = self.table if T is None else self.table[np.isclose(self.table["T_years"], float(T))]
        out = []
        for _, r in rows.iterrows():
            if not np.isfinite(r["variance_total_kj2"]) or r["variance_total_kj2"] <= 0:
                out.append(f"{r['T_years']:g}-year energy: not defined in every draw (fewer than one arrival in T "
                           "years)")
                continue
            out.append(f"{r['T_years']:g}-year energy {sig(r['energy_kj_mean'], 4)} kJ (mean of {self.n_draws} "
                       f"draws), {lvl} interval {sig(r['combined_low_kj'], 3)}-{sig(r['combined_high_kj'], 3)} kJ: "
                       f"{r['share_from_trajectory_model']:.0%} of its variance from the trajectory model "
                       f"(model alone {sig(r['model_low_kj'], 3)}-{sig(r['model_high_kj'], 3)} kJ), "
                       f"{1 - r['share_from_trajectory_model']:.0%} statistical (alone "
                       f"{sig(r['statistical_low_kj'], 3)}-{sig(r['statistical_high_kj'], 3)} kJ)")
        return out

    def to_dict(self) -> dict:
        """JSON-ready: the table, what each part covers, the draws' basis and the notes.

        Returns
        -------
        dict
            ``rows`` (the table as records), ``draws``, ``bootstrap_per_draw``, ``level``, ``basis``,
            ``model_part``, ``statistical_part``, ``notes``.
        """
        return {"rows": self.table.to_dict(orient="records"), "draws": self.n_draws,
                "bootstrap_per_draw": self.n_bootstrap, "level": self.level, "basis": self.basis,
                "model_part": MODEL_PART, "statistical_part": STATISTICAL_PART, "notes": list(self.notes)}

    def plot(self, T: float | None = None, ax=None):
        """Each draw's T-year energy with its bootstrap interval (points and bars), the combined interval
        (band) and the reference value (line).

        Parameters
        ----------
        T : float, optional
            Return period [yr]; None for the largest return period defined in every draw.
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
        """
        from .figures import plot_design_energy_split
        return plot_design_energy_split(self, T=T, ax=ax)


def _check_hazards(hazards) -> list:
    hazards = list(hazards)
    if len(hazards) < 2:
        raise ModelUncertaintyError(f"hazards: give at least 2 draws of the trajectory model; got {len(hazards)}")
    for i, h in enumerate(hazards):
        if not isinstance(h, EnergyHazard):
            raise ModelUncertaintyError(f"hazards[{i}] is a {type(h).__name__}, not an EnergyHazard")
    return hazards


def design_energy_split(hazards, T=DESIGN_RETURN_PERIODS, *, n_bootstrap: int = 100, seed=1, level: float = 0.95,
                        reference: EnergyHazard | None = None, basis: str = "") -> DesignEnergySplit:
    """Split the interval of T-year energies [kJ] into the trajectory model's part and the statistical part.

    Parameters
    ----------
    hazards : sequence of EnergyHazard
        One hazard per draw of the material parameters (the same line, mass model and rate; e.g.
        :func:`energy_hazard_ensemble`).
    T : sequence of float
        Return periods [yr].  Where a draw has fewer than one arrival in T years its energy is 0 kJ (as in
        :meth:`EnergyHazard.design_table`).
    n_bootstrap : int
        Bootstrap replicates per draw (b, rate, trajectories).
    seed : int
        Seed of the bootstrap (the same for every draw).
    level : float
        Level of the intervals.
    reference : EnergyHazard, optional
        The hazard at the scenario's own values (its point estimate is reported beside the draws).
    basis : str
        Where the draws come from (stated in the outputs).

    Returns
    -------
    DesignEnergySplit
    """
    hazards = _check_hazards(hazards)
    if isinstance(n_bootstrap, bool) or not isinstance(n_bootstrap, (int, np.integer)) or n_bootstrap < 10:
        raise ModelUncertaintyError(f"n_bootstrap = {n_bootstrap!r} must be a whole number >= 10")
    if not (isinstance(level, (int, float)) and 0 < level < 1):
        raise ModelUncertaintyError(f"level = {level!r} must lie in (0, 1)")
    Tv = np.atleast_1d(np.asarray(T, dtype=float))
    K, B = len(hazards), int(n_bootstrap)
    point = np.zeros((K, Tv.size))
    reps = np.zeros((K, B, Tv.size))
    per_draw = []
    q = (1.0 - level) / 2.0
    for j, hz in enumerate(hazards):
        ok = Tv * hz.arrival_rate > 1
        if ok.any():
            point[j, ok] = hz.energy_at_return_period(Tv[ok])
            r = hz.energy_at_return_period_replicates(Tv[ok], B, seed)
            reps[j][:, ok] = np.nan_to_num(r, nan=0.0)
        for i, t in enumerate(Tv):
            per_draw.append({"draw": j, "T_years": t, "energy_kj": point[j, i],
                             "ci_low_kj": float(np.quantile(reps[j, :, i], q)),
                             "ci_high_kj": float(np.quantile(reps[j, :, i], 1 - q)),
                             "reach_probability": hz.reach_probability, "arrivals_per_year": hz.arrival_rate})
    rows = []
    for i, t in enumerate(Tv):
        e = reps[:, :, i]                                       # (K, B)
        group_mean = e.mean(axis=1)
        within = float(np.mean(e.var(axis=1)))                  # E_theta Var[E | theta]
        between = float(np.var(group_mean))                     # Var_theta E[E | theta]
        total = within + between                                # = e.var() over all K x B (equal groups)
        centred = (e - group_mean[:, None]).ravel() + point[:, i].mean()
        ref = np.nan
        if reference is not None:
            ref = float(reference.energy_at_return_period(t)) if t * reference.arrival_rate > 1 else 0.0
        rows.append({"T_years": t, "energy_kj_reference": ref, "energy_kj_mean": float(point[:, i].mean()),
                     "combined_low_kj": float(np.quantile(e, q)), "combined_high_kj": float(np.quantile(e, 1 - q)),
                     "model_low_kj": float(np.quantile(point[:, i], q)),
                     "model_high_kj": float(np.quantile(point[:, i], 1 - q)),
                     "statistical_low_kj": float(np.quantile(centred, q)),
                     "statistical_high_kj": float(np.quantile(centred, 1 - q)),
                     "variance_total_kj2": total, "variance_trajectory_model_kj2": between,
                     "variance_statistical_kj2": within,
                     "share_from_trajectory_model": between / total if total > 0 else np.nan})
    notes = [f"{K} draws of the trajectory model, {B} bootstrap replicates each (seed {seed}); {MODEL_PART}; "
             f"{STATISTICAL_PART}"]
    if K < 40:
        notes.append(f"the trajectory model's {level:.0%} interval rests on {K} draws: its ends are close to the "
                     "extreme draws (a coarse quantile)")
    notes.append("each draw's point estimate carries the Monte Carlo noise of its simulated blocks; with the same "
                 "seed for every draw that noise is largely common to the draws")
    return DesignEnergySplit(table=pd.DataFrame(rows), per_draw=pd.DataFrame(per_draw), n_draws=K, n_bootstrap=B,
                             level=float(level), basis=basis, notes=tuple(notes))


@dataclass(frozen=True)
class EnergyHazardEnsemble(Displayed):
    """Energy hazards at one line for K draws of the slope's material parameters (:func:`energy_hazard_ensemble`).

    ``draws``: the material values of each draw (one row per draw, dotted ``materials.NAME.FIELD`` columns);
    ``hazards``: the :class:`EnergyHazard` of each draw; ``reference``: the hazard at the scenario's own values
    (or None); ``basis``: where the draws come from.
    """

    draws: pd.DataFrame = field(repr=False)
    hazards: tuple = field(repr=False)
    reference: EnergyHazard | None = field(default=None, repr=False)
    basis: str = ""
    n: int = 0
    seed: object = 1

    def __repr__(self) -> str:
        return short_repr(self, f"{len(self.hazards)} draws", repr(self.basis) if self.basis else "", n=self.n,
                          seed=self.seed if isinstance(self.seed, (int, np.integer)) else None,
                          reference=self.reference is not None)

    def summary(self) -> pd.DataFrame:
        """One row per draw.

        Returns
        -------
        pandas.DataFrame
            The draw's material values (``materials.NAME.FIELD`` columns), ``reach_probability`` and
            ``arrivals_per_year`` [1/yr].
        """
        return self.draws.assign(reach_probability=[h.reach_probability for h in self.hazards],
                                 arrivals_per_year=[h.arrival_rate for h in self.hazards])

    def design_energies(self, T=DESIGN_RETURN_PERIODS, *, n_bootstrap: int = 100, seed=1,
                        level: float = 0.95) -> DesignEnergySplit:
        """The T-year energies with their interval split (:func:`design_energy_split`).

        Parameters
        ----------
        T : sequence of float
            Return periods [yr].
        n_bootstrap : int
            Bootstrap replicates per draw.
        seed : int
            Seed of the bootstrap.
        level : float
            Level of the intervals.

        Returns
        -------
        DesignEnergySplit
        """
        return design_energy_split(self.hazards, T, n_bootstrap=n_bootstrap, seed=seed, level=level,
                                   reference=self.reference, basis=self.basis)

    def plot(self, T: float = 100.0, ax=None):
        """The T-year energy of each draw with its bootstrap interval (:meth:`DesignEnergySplit.plot`, 50
        bootstrap replicates per draw).

        Parameters
        ----------
        T : float
            Return period [yr].
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
        """
        return self.design_energies([T], n_bootstrap=50).plot(T, ax=ax)


def energy_hazard_ensemble(mass, scenario, collector: str = "barrier", *, posterior=None, draws: int = 8,
                           rate_per_year=None, n: int = 2_000, seed=1, reference: bool = True,
                           **kwargs) -> EnergyHazardEnsemble:
    """:func:`~riskrf.hazard.simulated.energy_hazard` over K draws of the slope's material parameters.

    Parameters
    ----------
    mass, collector, rate_per_year
        As for :func:`~riskrf.hazard.simulated.energy_hazard`.
    scenario : path to a scenario TOML (or a Scenario loaded from one)
        The slope; each draw's values are put into its materials (:func:`simulation.scenario_with_values`).
    posterior : path, DataFrame or None
        A posterior sample (a file written by :meth:`simulation.PooledCalibration.write`, checked against the
        scenario by :func:`simulation.read_posterior`, or its DataFrame); None: the presets' spread
        (:func:`simulation.preset_spread`, ASSUMED ranges unless a data-derived source is plugged in).
    draws : int
        Number of draws K (each re-simulated).
    n : int
        Blocks per draw (modest: the draws' spread, not each curve's precision, is the point).
    seed : int
        Seed of every draw's simulation (common random numbers) and of the choice of draws.
    reference : bool
        Also simulate the scenario at its own values.
    **kwargs
        Passed to :func:`~riskrf.hazard.simulated.energy_hazard` (``mass_range_kg``, ``design_masses_kg``, ...).

    Returns
    -------
    EnergyHazardEnsemble
    """
    import simulation
    from simulation.materials import parameter_sets_any
    from .simulated import energy_hazard

    path = scenario if not isinstance(scenario, simulation.Scenario) else scenario.source
    post = read_model_posterior(posterior, path) if posterior is not None and not isinstance(
        posterior, pd.DataFrame) else posterior
    try:
        table = simulation.material_draws(path, draws, posterior=post, seed=seed)
    except ValueError as exc:
        raise ModelUncertaintyError(str(exc)) from None
    materials = [m.name for m in simulation.load_scenario(path).materials]
    for col in table.columns:                     # a posterior given as a table: checked before any simulation
        if not parameter_sets_any(col, materials):
            raise ModelUncertaintyError(f"posterior column {col!r}: not a parameter 'materials.NAME.FIELD' of a "
                                        f"material of {path} (materials: {materials})")
    for i, row in table.iterrows():
        try:
            simulation.scenario_with_values(path, row.to_dict())
        except ValueError as exc:
            raise ModelUncertaintyError(f"posterior draw {i}: {exc}") from None
    hazards = tuple(energy_hazard(mass, simulation.scenario_with_values(path, row.to_dict()), collector,
                                  rate_per_year=rate_per_year, n=n, seed=seed, **kwargs)
                    for _, row in table.iterrows())
    ref = energy_hazard(mass, path, collector, rate_per_year=rate_per_year, n=n, seed=seed, **kwargs) \
        if reference else None
    return EnergyHazardEnsemble(draws=table, hazards=hazards, reference=ref, basis=table.attrs.get("basis", ""),
                                n=int(n), seed=seed)


def read_model_posterior(path, scenario) -> pd.DataFrame:
    """A posterior sample file checked against the scenario's materials before any simulation
    (:func:`simulation.read_posterior`).

    Parameters
    ----------
    path : str or pathlib.Path
        The posterior file (written by :meth:`simulation.PooledCalibration.write`).
    scenario : str, pathlib.Path or Scenario
        The scenario whose materials the columns must name.

    Returns
    -------
    pandas.DataFrame
        One row per draw, ``materials.NAME.FIELD`` columns.

    Raises
    ------
    FileNotFoundError
        No such file.
    ModelUncertaintyError
        A bad column or value (the message names the file and the column).
    """
    import simulation
    try:
        return simulation.read_posterior(path, scenario)
    except FileNotFoundError:
        raise
    except (ValueError, TypeError) as exc:
        raise ModelUncertaintyError(f"posterior {exc}" if str(exc).startswith(str(path)) else
                                    f"posterior {path}: {exc}") from None


__all__ = ["DesignEnergySplit", "EnergyHazardEnsemble", "MODEL_PART", "ModelUncertaintyError", "STATISTICAL_PART",
           "design_energy_split", "energy_hazard_ensemble", "read_model_posterior"]
