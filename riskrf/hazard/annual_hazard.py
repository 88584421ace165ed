"""Annual impact-energy hazard at a barrier line (Wyllie 2014, 8.1-8.3; Hantz et al. 2021).

    lambda(E > e) = rate of falls x P(a fall reaches the line) x P(E > e | reaches)

The rate and the mass distribution come from a magnitude-frequency fit (falls
at least m_min per year from the power law); the reach probability, velocities
(and rotation, and bounce heights) from a trajectory simulation or any velocity
model.  :class:`EnergyHazard` turns them into annual frequencies, return
periods, energies for a return period with intervals, and percentiles.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy import optimize

from .impact_energy import exceedance_function, exceedance_probability
from .mass_models import mass_model
from .velocity_models import PairedSamples, velocity_model
from ..core.format import sig
from ..core.units import DESIGN_RETURN_PERIODS, SPHERE_INERTIA
from ..core.validation import check_positive, check_probability_level, check_return_periods
from simulation._display import Displayed, short_repr


def inertia_factors(df) -> np.ndarray:
    """I / (m r^2) of each block in a collector table (0.4, a sphere, when the table does not say).

    Parameters
    ----------
    df : pandas.DataFrame
        A collector table (:meth:`simulation.SimulationResult.collector`).

    Returns
    -------
    numpy.ndarray
        k [-] per row.
    """
    return df["inertia_factor"].to_numpy(dtype=float) if "inertia_factor" in df else np.full(len(df), SPHERE_INERTIA)


def effective_speeds(df) -> np.ndarray:
    """Speed [m/s] of each row of a collector (or velocity) table with its rotational energy put in:
    v_eff = sqrt(v^2 + k (w r)^2), so that 1/2 m v_eff^2 is the translational plus rotational kinetic energy.

    Parameters
    ----------
    df : pandas.DataFrame
        Columns ``velocity_ms`` [m/s], ``angular_velocity_rads`` [rad/s], ``radius_m`` [m] and optionally
        ``inertia_factor`` (:func:`inertia_factors`).

    Returns
    -------
    numpy.ndarray
        v_eff [m/s] per row.

    References
    ----------
    Wyllie, D.C. (2014) Rock Fall Engineering, ch. 5 (rotational energy of a rolling block).
    """
    spin = df["angular_velocity_rads"].to_numpy(dtype=float) * df["radius_m"].to_numpy(dtype=float)
    return np.sqrt(df["velocity_ms"].to_numpy(dtype=float) ** 2 + inertia_factors(df) * spin ** 2)


_E_GRID = np.geomspace(1e-3, 1e12, 301)     # kJ: the grid on which hazard curves are inverted


@dataclass(frozen=True, repr=False)
class EnergyHazard(Displayed):
    """Impact-energy hazard at one barrier line.

    Attributes
    ----------
    mass : mass model (usually a :class:`~riskrf.GutenbergRichterFit`)
    velocity : velocity model: samples [m/s], scipy distribution, VelocityFit, PairedSamples or
        MassCoupledSamples (reach, speed and bounce height by block mass: :func:`riskrf.energy_hazard`).
        With samples from a simulation the effective speed includes rotation:
        v_eff^2 = v^2 + k (w r)^2 (k = I / m r^2: 0.4 sphere, 0.5 cylinder), so that
        1/2 m v_eff^2 is the total kinetic energy (exact for a rolling body, whose
        surface speed w r does not depend on its mass).
    rate_per_year : falls per year described by the mass model (power law: falls >= m_min).
    reach_probability : P(a fall reaches the barrier line) (simulation; averaged over the mass model when the
        velocity model is mass-coupled).
    n_released : number of simulated blocks behind ``reach_probability`` (for its uncertainty).
    heights_m : bounce heights [m] at the line (of the block centre above the ground), if known.
    """

    mass: object
    velocity: object
    rate_per_year: float
    reach_probability: float = 1.0
    n_released: int | None = None
    heights_m: np.ndarray | None = field(default=None, repr=False)
    collector: str = ""
    notes: tuple = ()

    def __post_init__(self):
        check_positive(self.rate_per_year, "rate_per_year")
        if not 0.0 < float(self.reach_probability) <= 1.0:
            raise ValueError(f"reach_probability must lie in (0, 1]; got {self.reach_probability!r}")
        mass_model(self.mass)      # validates the mass model

    @classmethod
    def from_simulation(cls, mass, result, collector: str, *, rate_per_year=None, rotational: bool = True,
                        condition_on_mass: bool = False) -> "EnergyHazard":
        """Build the hazard from a mass fit and a :class:`simulation.SimulationResult` (the mass-INDEPENDENT form).

        Uses each block's first crossing of ``collector``; the reach probability is
        the fraction of released blocks that crossed it, one value for every mass, and the
        velocities are pooled over the seeder's masses (``condition_on_mass`` classes them by the
        seeder's masses, without simulating beyond them).  The mass-coupled hazard, which simulates
        the whole range of the mass model, is :func:`riskrf.energy_hazard`.

        Parameters
        ----------
        mass : mass model
            Usually a :class:`~riskrf.GutenbergRichterFit` [kg].
        result : simulation.SimulationResult
            The run.
        collector : str
            The line.
        rate_per_year : float, optional
            Falls per year described by ``mass`` [1/yr] (default: the power law's rate above m_min).
        rotational : bool
            Include the rotational energy: v_eff² = v² + k (ω r)².
        condition_on_mass : bool
            Class the velocities by the seeder's masses (:class:`~riskrf.hazard.velocity_models.PairedSamples`).

        Returns
        -------
        EnergyHazard
        """
        if rate_per_year is None:
            rate_per_year = mass_model(mass).rate_per_year
            if rate_per_year is None:
                raise ValueError("rate_per_year is needed unless the mass model is a power-law fit")
        df = result.collector(collector, first_only=True)
        if df.empty:
            raise ValueError(f"no simulated block reached collector {collector!r}: the hazard there is nil "
                             "for the simulated release; check the scenario")
        v = effective_speeds(df) if rotational else df["velocity_ms"].to_numpy()
        velocity = PairedSamples(v, df["mass_kg"].to_numpy()) if condition_on_mass else v
        notes = ("mass-independent form: one reach probability and one velocity law for all masses"
                 + (" (velocities classed by the seeder's masses)" if condition_on_mass else ""),
                 f"velocities: first crossings of {collector!r} by {len(df):,} of {result.n:,} simulated blocks"
                 + ("; rotational energy included (v_eff^2 = v^2 + k (w r)^2)" if rotational else ""),)
        return cls(mass=mass, velocity=velocity, rate_per_year=float(rate_per_year),
                   reach_probability=len(df) / result.n, n_released=result.n,
                   heights_m=df["height_m"].to_numpy(), collector=collector, notes=notes)

    @property
    def mass_coupled(self) -> bool:
        """Whether reach, speed and bounce height depend on block mass (:func:`riskrf.energy_hazard`)."""
        return velocity_model(self.velocity).mass_coupled

    def with_mass(self, mass, rate_per_year: float | None = None) -> "EnergyHazard":
        """The same slope with another mass model (and rate): a mass-coupled reach probability is recomputed.

        Parameters
        ----------
        mass : mass model
            The new mass model [kg].
        rate_per_year : float, optional
            Its falls per year [1/yr] (default: unchanged).

        Returns
        -------
        EnergyHazard
        """
        rate = self.rate_per_year if rate_per_year is None else check_positive(rate_per_year, "rate_per_year")
        if self.mass_coupled:
            mm = mass_model(mass)
            vel = self.velocity.with_representative(mm)
            return replace(self, mass=mass, rate_per_year=float(rate), velocity=vel,
                           reach_probability=max(vel.reach_probability(mm), 1e-300), heights_m=vel.heights_m)
        return replace(self, mass=mass, rate_per_year=float(rate))

    # ---- per fall -------------------------------------------------------------------
    def exceedance_probability(self, energy_kj):
        """P(E > e) for one fall that reaches the line.

        Parameters
        ----------
        energy_kj : float or array_like
            Energies [kJ].

        Returns
        -------
        numpy.ndarray
            Probabilities [-].
        """
        return exceedance_probability(energy_kj, self.mass, self.velocity)

    def energy_percentile(self, q):
        """Energy [kJ] not exceeded by q % of the falls that reach the line (e.g. q = 95, 99).

        Parameters
        ----------
        q : float or array_like
            Percentiles, in (0, 100).

        Returns
        -------
        numpy.ndarray
            Energies [kJ].
        """
        q = np.atleast_1d(np.asarray(q, dtype=float))
        if np.any((q <= 0) | (q >= 100)):
            raise ValueError(f"percentiles must lie strictly between 0 and 100; got {q.tolist()}")
        return self._invert(1.0 - q / 100.0, scale=1.0)

    def velocity_percentile(self, q, mass_kg=None) -> float:
        """Velocity [m/s] not exceeded by q % of the falls reaching the line, whatever the velocity model.

        With a mass-coupled model and ``mass_kg``: of the simulated blocks of that mass (its mass class).

        Parameters
        ----------
        q : float
            Percentile, in [0, 100].
        mass_kg : float, optional
            Block mass [kg] (mass-coupled models only).

        Returns
        -------
        float
            Velocity [m/s].
        """
        return velocity_model(self.velocity).percentile(q, mass_kg)

    def height_percentile(self, q):
        """Bounce height [m] not exceeded by q % of the falls reaching the line (from simulated heights).

        Parameters
        ----------
        q : float or array_like
            Percentile(s), in [0, 100].

        Returns
        -------
        numpy.ndarray or float
            Height of the block centre above the ground [m].
        """
        if self.heights_m is None:
            raise ValueError("no bounce heights: build the hazard with EnergyHazard.from_simulation")
        return np.percentile(self.heights_m, q)

    def height_exceedance(self, height_m):
        """P(bounce height > h) for a fall reaching the line (the share that would pass over a fence).

        Parameters
        ----------
        height_m : float or array_like
            Height above the ground [m].

        Returns
        -------
        numpy.ndarray or float
            Share of the simulated arriving falls [-].
        """
        if self.heights_m is None:
            raise ValueError("no bounce heights: build the hazard with EnergyHazard.from_simulation")
        h = np.sort(self.heights_m)
        return 1.0 - np.searchsorted(h, np.asarray(height_m, dtype=float), side="right") / h.size

    # ---- per year -------------------------------------------------------------------
    @property
    def arrival_rate(self) -> float:
        """Falls reaching the line per year [1/yr]."""
        return self.rate_per_year * self.reach_probability

    def annual_frequency(self, energy_kj):
        """Impacts with energy above e per year at the line [1/yr].

        Parameters
        ----------
        energy_kj : float or array_like
            Energies [kJ].

        Returns
        -------
        numpy.ndarray
            lambda(e) = arrivals per year x P(E > e) [1/yr].
        """
        return self.arrival_rate * self.exceedance_probability(energy_kj)

    def return_period(self, energy_kj):
        """Mean time [yr] between impacts above e.

        Parameters
        ----------
        energy_kj : float or array_like
            Energies [kJ].

        Returns
        -------
        numpy.ndarray
            1 / lambda(e) [yr] (infinite where no impact exceeds e).
        """
        with np.errstate(divide="ignore"):
            return 1.0 / self.annual_frequency(energy_kj)

    def probability_in(self, years, energy_kj):
        """P(at least one impact above e in ``years``), Poisson: 1 - exp(-lambda(e) years).

        Parameters
        ----------
        years : float
            Period [yr], e.g. a design life.
        energy_kj : float or array_like
            Energies [kJ].

        Returns
        -------
        numpy.ndarray
            Probabilities [-].
        """
        return -np.expm1(-check_positive(years, "years") * self.annual_frequency(energy_kj))

    def energy_at_return_period(self, T):
        """Energy [kJ] exceeded on average once in T years at the line.

        Parameters
        ----------
        T : float or array_like
            Return period [yr], longer than the mean time between arrivals.

        Returns
        -------
        numpy.ndarray
            Energy e with lambda(e) = 1/T [kJ].
        """
        T = check_return_periods(T)
        p = 1.0 / (T * self.arrival_rate)
        if np.any(p >= 1):
            bad = np.atleast_1d(T)[np.atleast_1d(p) >= 1][0]
            raise ValueError(f"T = {bad:g} yr is shorter than the mean time between arrivals at the line "
                             f"({1 / self.arrival_rate:.3g} yr): every arriving fall exceeds the T-year energy")
        return self._invert(np.atleast_1d(p), scale=1.0).reshape(np.shape(T))

    def return_level(self, T):
        """Energy [kJ] exceeded on average once in T years: :meth:`energy_at_return_period` under the name the
        mass models use (:meth:`riskrf.GumbelFit.return_level`, :meth:`riskrf.GutenbergRichterFit.return_level`).

        Parameters
        ----------
        T : float or array_like
            Return period [yr].

        Returns
        -------
        numpy.ndarray
            Energy [kJ].
        """
        return self.energy_at_return_period(T)

    def return_level_ci(self, T, level: float = 0.95, n_bootstrap: int = 300, seed=None):
        """Interval of :meth:`return_level`: :meth:`energy_at_return_period_ci` under the mass models' name.

        Parameters
        ----------
        T : float or array_like
            Return period [yr].
        level : float
            Confidence level.
        n_bootstrap : int
            Replicates.
        seed : int, optional
            Seed of the replicates.

        Returns
        -------
        tuple of numpy.ndarray
            (lower, upper) energies [kJ].
        """
        return self.energy_at_return_period_ci(T, level, n_bootstrap, seed)

    def _invert(self, p, scale):
        """Energy where scale x P(E > e) = p: grid interpolation, then refined by root finding."""
        p = np.atleast_1d(p)
        fn = exceedance_function(self.mass, self.velocity)
        curve = fn(_E_GRID) * scale
        guess = _interp_log_inverse(curve, p)
        out = guess.copy()
        for i, (pi, g) in enumerate(zip(p, guess)):
            if not np.isfinite(g):
                continue
            f = lambda le: np.log(max(scale * fn(np.exp(le)).item(), 1e-300)) - np.log(pi)  # noqa: E731
            lo, hi = np.log(g) - 0.05, np.log(g) + 0.05
            for _ in range(40):
                if f(lo) > 0 >= f(hi):
                    out[i] = np.exp(optimize.brentq(f, lo, hi, xtol=1e-12))
                    break
                lo, hi = lo - 0.1, hi + 0.1
        return out

    # ---- uncertainty ----------------------------------------------------------------
    def energy_at_return_period_ci(self, T, level: float = 0.95, n_bootstrap: int = 300, seed=None):
        """Seeded interval of the T-year energy, drawing each uncertain input from its law.

        Sources included: the exponent b and the rate of the power law (b* =
        b x Gamma(n, 1)/n, the posterior of b under the Jeffreys prior 1/b given the
        MLE b from n masses, exact for the untruncated law; the MLE's own sampling law
        is the inverse, b n / Gamma(n, 1); rate* = rate x Gamma(n, 1)/n = Gamma(n)/T, the
        posterior of a Poisson rate of n falls in T years under the scale-invariant prior 1/rate),
        or the parameters of a Gumbel/GEV fit (normal with the fit's covariance);
        the finite number of simulated trajectories (velocities resampled with
        replacement, reach probability binomial; mass-coupled: the blocks of each
        mass class resampled).  Not included: the choice of model, the maximum
        credible block m_max and the rate share of the source (judgement inputs:
        see ``riskrf.hazard.energy_study.design_energy_sensitivity``), the simulation's
        physical parameters, the record's completeness.

        Parameters
        ----------
        T : float or array_like
            Return period [yr].
        level : float
            Confidence level.
        n_bootstrap : int
            Replicates.
        seed : int, optional
            Seed of the replicates.

        Returns
        -------
        tuple of numpy.ndarray
            (lower, upper) energies [kJ].

        References
        ----------
        Jeffreys, H. (1961). Theory of Probability, 3rd ed. Oxford University Press (the scale-invariant prior).
        """
        T = check_return_periods(T)
        level = check_probability_level(level)
        sims = self.energy_at_return_period_replicates(T, n_bootstrap, seed)
        q = (1 - level) / 2
        lo, hi = np.nanquantile(sims, q, axis=0), np.nanquantile(sims, 1 - q, axis=0)
        return lo.reshape(np.shape(T)), hi.reshape(np.shape(T))

    def energy_at_return_period_replicates(self, T, n_bootstrap: int = 300, seed=None) -> np.ndarray:
        """The bootstrap replicates behind :meth:`energy_at_return_period_ci`: T-year energies [kJ], an array
        (n_bootstrap, number of T); NaN where a replicate has fewer than one arrival in T years.

        Parameters
        ----------
        T : float or array_like
            Return period(s) [yr].
        n_bootstrap : int
            Replicates.
        seed : int, optional
            Seed of the replicates.

        Returns
        -------
        numpy.ndarray
            Energies [kJ].
        """
        Tv = np.atleast_1d(check_return_periods(T)).astype(float)
        sims = np.empty((int(n_bootstrap), Tv.size))
        for i, (curve, scale) in enumerate(self._bootstrap_curves(int(n_bootstrap), seed)):
            sims[i] = _interp_log_inverse(curve, 1.0 / (Tv * scale))
        return sims

    def _bootstrap_curves(self, n_bootstrap: int, seed):
        """Replicates (P(E > e) on the energy grid, arrivals per year) of the parametric bootstrap.

        With an integer seed they are kept on the object, so the design table and the exceedance figure
        draw on the same replicates instead of repeating them.
        """
        key = (n_bootstrap, seed) if isinstance(seed, (int, np.integer)) else None
        cache = self.__dict__.setdefault("_bootstrap_cache", {})
        if key is not None and key in cache:
            return cache[key]
        rng = np.random.default_rng(seed)
        out = []
        v_nodes = velocity_model(self.velocity).bootstrap_nodes()
        for _ in range(n_bootstrap):
            mass, rate = self._perturbed_mass(rng)
            if self.mass_coupled:       # blocks resampled within each mass class: reach and speed together
                out.append((self.velocity.resampled_joint_exceedance(rng, _E_GRID, mass_model(mass)), rate))
                continue
            reach = self.reach_probability
            if self.n_released:
                reach = max(rng.binomial(self.n_released, self.reach_probability), 1) / self.n_released
            vel = v_nodes.resample(rng)
            out.append((exceedance_probability(_E_GRID, mass, vel), rate * reach))
        if key is not None:
            cache[key] = out
        return out

    def _perturbed_mass(self, rng):
        return mass_model(self.mass).perturbed(rng, self.rate_per_year)

    # ---- tables ---------------------------------------------------------------------
    def design_table(self, T=DESIGN_RETURN_PERIODS, level: float = 0.95, n_bootstrap: int = 300,
                     seed=1) -> pd.DataFrame:
        """Energy [kJ] for each return period, with bootstrap intervals.

        Parameters
        ----------
        T : sequence of float
            Return periods [yr].
        level : float
            Confidence level.
        n_bootstrap : int
            Replicates of the intervals.
        seed : int
            Seed of the intervals.

        Returns
        -------
        pandas.DataFrame
            ``T_years``, ``annual_exceedance`` [1/yr], ``energy_kj``, ``ci_low_kj``, ``ci_high_kj``,
            ``probability_in_50_years``.
        """
        T = np.asarray(T, dtype=float)
        ok = T * self.arrival_rate > 1
        e = np.full(T.size, 0.0)
        lo, hi = np.full(T.size, 0.0), np.full(T.size, 0.0)
        if ok.any():
            e[ok] = self.energy_at_return_period(T[ok])
            lo[ok], hi[ok] = self.energy_at_return_period_ci(T[ok], level, n_bootstrap, seed)
        return pd.DataFrame({"T_years": T, "annual_exceedance": 1 / T, "energy_kj": e, "ci_low_kj": lo,
                             "ci_high_kj": hi, "probability_in_50_years": -np.expm1(-50 / T)})

    def summary(self) -> pd.DataFrame:
        """Key figures of the hazard at the line (one-column table): falls per year, reach probability, arrivals
        per year [1/yr], the mass model, mass coupling and the 95th/99th-percentile energies [kJ].

        Returns
        -------
        pandas.DataFrame
            Index: quantity; column ``value``.
        """
        rows = {"collector": self.collector, "falls per year (mass model)": self.rate_per_year,
                "reach probability": self.reach_probability, "arrivals per year": self.arrival_rate,
                "mass model": mass_model(self.mass).description,
                "mass coupling": ("reach, speed and bounce height by block mass (simulated "
                                  f"{sig(self.velocity.edges_kg[0])}-{sig(self.velocity.edges_kg[-1])} kg)")
                if self.mass_coupled else "none: one reach probability and velocity law for all masses"}
        for q, e in zip((95, 99), self.energy_percentile([95, 99])):
            rows[f"energy p{q} per arriving fall [kJ]"] = e
        if self.heights_m is not None:
            for q in (95, 99):
                rows[f"bounce height p{q} [m]"] = float(self.height_percentile(q))
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def __repr__(self) -> str:
        return short_repr(self, repr(self.collector) if self.collector else "",
                          f"{type(self.mass).__name__} x {type(self.velocity).__name__}",
                          rate_per_year=self.rate_per_year, reach_probability=self.reach_probability,
                          mass_coupled=self.mass_coupled)

    def plot(self, ax=None, **kwargs):
        """Annual frequency of impacts above an energy at the line [1/yr] against the energy [kJ], log-log, with the bootstrap band (drawn by :func:`riskrf.hazard.figures.plot_energy_exceedance`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).
        **kwargs
            Passed to the drawing function.

        Returns
        -------
        matplotlib.axes.Axes
        """
        from .figures import plot_energy_exceedance
        return plot_energy_exceedance(self, ax=ax, **kwargs)

def _interp_log_inverse(curve, p):
    """Energy on _E_GRID where the non-increasing curve P(E > e) crosses p (log-log interpolation)."""
    p = np.asarray(p, dtype=float)
    valid = curve > 0
    if not valid.any():
        return np.full(p.shape, np.nan)
    le = np.log(_E_GRID[valid])
    lp = np.log(np.maximum.accumulate(curve[valid][::-1])[::-1])   # enforce monotone
    # np.interp needs increasing x: use -log p.
    x = -lp
    order = np.argsort(x, kind="stable")
    x, le = x[order], le[order]
    x, idx = np.unique(x, return_index=True)
    return np.exp(np.interp(-np.log(p), x, le[idx], left=np.nan, right=np.nan))
