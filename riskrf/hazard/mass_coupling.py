"""Impact-energy hazard coupled to block mass: trajectories simulated across the whole mass range.

A heavier block in the simulator rolls and flies differently (contact roughness
scales with the radius, rotation stores a share of the energy that depends on
r, a longer run-out favours larger blocks), so its speed, bounce height and the
probability that it reaches a barrier line all depend on its mass.  Taking them
as independent of mass (one pooled velocity sample, one reach probability)
biases the design energy.  Here the blocks are released with masses spread
log-uniformly over the range of the mass model (stratified in ln m, one block
per slice), and the annual frequency integrates over mass with mass-dependent
reach and speed (Hantz et al. 2021; Wyllie 2014, 8.1-8.3)::

    lambda(E > e) = rate x  integral f_M(m) P(reach | m) P(V_eff > sqrt(2000 e / m) | m, reach) dm

P(reach | m) and the speed law are estimated per mass class (``n_bins`` classes of
equal width in ln m); within a class the mass model's own law is integrated
exactly (Gauss-Legendre in its survival probability), so the curve is smooth in
e and non-increasing by construction.  V_eff includes rotation:
V_eff^2 = v^2 + k (w r)^2 (k = I / m r^2), so that 1/2 m V_eff^2 is the total
kinetic energy of the simulated block.

Masses of the mass model outside the simulated range take the behaviour of the
nearest class; :func:`riskrf.hazard.simulated.energy_hazard` chooses the range so that this concerns
at most the mass beyond the 10,000-year fall (or nothing, for a truncated law),
states the share in the notes, and refuses a range that leaves a design mass
unsimulated.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import pandas as pd

from ..core.validation import RiskrfError
from ..core.format import sig
from ..core.units import J_PER_KJ, kinetic_energy_kj
from simulation._display import Displayed, short_repr

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(8)
#: Return period [yr] of the largest fall at the source that the default simulated range must include
#: (when the mass model is not truncated).
RANGE_RETURN_PERIOD_YEARS = 10_000.0


class NoArrivalsError(RiskrfError, ValueError):
    """No simulated block reached the collector: the hazard there is nil for the simulated release (a corridor
    section takes it as such; elsewhere it is an error naming the collector)."""


@dataclass(frozen=True, eq=False, repr=False)
class MassCoupledSamples(Displayed):
    """Simulated blocks across a mass range: each block's mass and what it did at one line.

    Attributes
    ----------
    mass_kg : masses [kg] of all released blocks.
    speed_ms : effective speed V_eff [m/s] at the block's first crossing of the line (NaN: it never got there).
    height_m : height [m] of the block centre above the ground at that crossing (NaN: never got there).
    edges_kg : boundaries [kg] of the mass classes (increasing, equal width in ln m).
    representative : indices into the arriving blocks that represent the arriving falls under a mass model
        (systematic resampling with class weights); pooled samples (``velocity_ms``, ``heights_m``) use them.

    The per-class tables are computed on first use and cached (the fields are never changed).
    """

    #: Declares the mass-coupled velocity model (:func:`riskrf.hazard.velocity_models.is_mass_coupled`).
    mass_coupled_velocity = True

    mass_kg: np.ndarray = field(repr=False)
    speed_ms: np.ndarray = field(repr=False)
    height_m: np.ndarray = field(repr=False)
    edges_kg: np.ndarray
    collector: str = ""
    representative: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self):
        m, s, h = (np.asarray(a, dtype=float) for a in (self.mass_kg, self.speed_ms, self.height_m))
        if not (m.shape == s.shape == h.shape) or m.ndim != 1:
            raise ValueError(f"mass_kg, speed_ms and height_m must be 1-d arrays of one length; got {m.shape}, "
                             f"{s.shape}, {h.shape}")
        if np.any(~np.isfinite(m) | (m <= 0)):
            i = int(np.argmax(~np.isfinite(m) | (m <= 0)))
            raise ValueError(f"mass_kg[{i}] = {float(m[i])!r}: masses must be finite and > 0 kg")
        e = np.asarray(self.edges_kg, dtype=float)
        if e.ndim != 1 or e.size < 2 or np.any(np.diff(e) <= 0) or e[0] <= 0:
            raise ValueError(f"edges_kg must be at least two increasing masses > 0 kg; got {e!r}")
        counts = np.bincount(self.class_of(m), minlength=e.size - 1)
        if np.any(counts == 0):
            raise ValueError(f"mass class {int(np.argmin(counts))} ({e[np.argmin(counts)]:.4g}-"
                             f"{e[np.argmin(counts) + 1]:.4g} kg) holds no simulated block")
        for name, arr in (("mass_kg", m), ("speed_ms", s), ("height_m", h), ("edges_kg", e)):
            object.__setattr__(self, name, arr)

    # ---- classes --------------------------------------------------------------------------------
    @property
    def n_bins(self) -> int:
        """Number of mass classes."""
        return self.edges_kg.size - 1

    @property
    def reached(self) -> np.ndarray:
        """Boolean array: which released blocks reached the line (a finite speed)."""
        return np.isfinite(self.speed_ms)

    def class_of(self, mass_kg) -> np.ndarray:
        """Mass class of each mass (masses outside the simulated range take the nearest class).

        Parameters
        ----------
        mass_kg : float or array_like
            Masses [kg].

        Returns
        -------
        numpy.ndarray of int
            Class index, 0 .. n_bins - 1.
        """
        k = np.searchsorted(self.edges_kg, np.asarray(mass_kg, dtype=float), side="right") - 1
        return np.clip(k, 0, self.edges_kg.size - 2)

    @cached_property
    def _classes(self):
        """Per class: number released, sorted arriving speeds, arriving heights."""
        k = self.class_of(self.mass_kg)
        out = []
        for c in range(self.n_bins):
            sel = k == c
            arrived = sel & self.reached
            out.append((int(sel.sum()), np.sort(self.speed_ms[arrived]), self.height_m[arrived]))
        return out

    @property
    def reach_by_class(self) -> np.ndarray:
        """P(reach the line | mass class) for each class."""
        return np.array([s.size / n for n, s, _ in self._classes])

    # ---- pooled samples (what a mass-independent consumer sees) -----------------------------------
    @property
    def velocity_ms(self) -> np.ndarray:
        """Speeds [m/s] of the arriving falls (representative of the mass model when ``representative`` is set)."""
        v = self.speed_ms[self.reached]
        return v if self.representative is None else v[self.representative]

    @property
    def heights_m(self) -> np.ndarray:
        """Heights [m] paired with :attr:`velocity_ms`."""
        h = self.height_m[self.reached]
        return h if self.representative is None else h[self.representative]

    @property
    def arriving_mass_kg(self) -> np.ndarray:
        """Masses [kg] paired with :attr:`velocity_ms`."""
        m = self.mass_kg[self.reached]
        return m if self.representative is None else m[self.representative]

    # ---- integration over the mass model ---------------------------------------------------------
    def _nodes(self, mm):
        """Quadrature nodes over the mass model: masses [kg], probability weights, class of each."""
        P = np.asarray(mm.sf(self.edges_kg), dtype=float)
        P[0] = 1.0                     # mass below the simulated range: the lowest class
        hi_p, lo_p = P[:-1], P[1:]
        cls = np.flatnonzero(hi_p - lo_p > 0)
        # each class's probability interval in 4 panels of Gauss-Legendre nodes, all classes at once
        frac = np.linspace(0.0, 1.0, 5)
        edges = lo_p[cls, None] + (hi_p - lo_p)[cls, None] * frac[None, :]
        half = 0.5 * np.diff(edges, axis=1)
        mid = 0.5 * (edges[:, :-1] + edges[:, 1:])
        p = (mid[:, :, None] + half[:, :, None] * _GL_NODES[None, None, :]).reshape(cls.size, 4 * _GL_NODES.size)
        w_all = [(half[:, :, None] * _GL_WEIGHTS[None, None, :]).ravel()]
        p_all = [p.ravel()]
        c_all = [np.repeat(cls, p.shape[1])]
        if P[-1] > 0:                  # mass above the simulated range (an untruncated law): the top class
            lp = np.linspace(np.log(max(P[-1] * 1e-12, 1e-300)), np.log(P[-1]), 33)
            half = 0.5 * np.diff(lp)
            mid = 0.5 * (lp[:-1] + lp[1:])
            p = np.exp((mid[:, None] + half[:, None] * _GL_NODES[None, :]).ravel())
            p_all.append(p)
            w_all.append((half[:, None] * _GL_WEIGHTS[None, :]).ravel() * p)
            c_all.append(np.full(p.size, self.n_bins - 1))
        p = np.concatenate(p_all)
        return np.asarray(mm.isf(p), dtype=float), np.concatenate(w_all), np.concatenate(c_all)

    def _groups(self, mm, arrivals=None):
        """Per mass class with arriving blocks: quadrature masses [kg], their weights, blocks released, sorted
        arriving speeds [m/s] and the cumulative count of arrivals up to each speed; and P(reach) under ``mm``
        (the quadrature prepared once for many energies).  ``arrivals``: per class, how many times each sorted
        arriving speed counts (a bootstrap replicate; default once each)."""
        m, w, cls = self._nodes(mm)
        groups, reach_by_class = [], np.zeros(self.n_bins)
        for c, (n_c, speeds, _) in enumerate(self._classes):
            cum = np.arange(speeds.size + 1.0) if arrivals is None else np.concatenate([[0.0], np.cumsum(arrivals[c])])
            reach_by_class[c] = cum[-1] / n_c
            sel = cls == c
            if sel.any() and cum[-1] > 0:
                m_c, w_c = np.maximum(m[sel], 1e-300), w[sel]
                # below the class's smallest kinetic energy every arrival exceeds e, above its largest none does
                # (the bounds widened by 1e-9 against rounding): only energies between need the speed search
                e_low = kinetic_energy_kj(m_c.min(), speeds[0]) * (1.0 - 1e-9)
                e_high = kinetic_energy_kj(m_c.max(), speeds[-1]) * (1.0 + 1e-9)
                groups.append((m_c, w_c, n_c, speeds, cum, e_low, e_high, cum[-1] / n_c * w_c.sum()))
        reach = float(np.clip(np.sum(w * reach_by_class[cls]), 0.0, 1.0))
        return groups, reach

    @staticmethod
    def _joint(e, groups) -> np.ndarray:
        flat = e.ravel()
        if flat.size == 1:
            return MassCoupledSamples._joint_one(flat, groups).reshape(e.shape)
        return MassCoupledSamples._joint_many(flat, groups).reshape(e.shape)

    @staticmethod
    def _joint_many(flat, groups) -> np.ndarray:
        """:meth:`_joint` at the energies ``flat`` (1-d [kJ]), all classes' speed searches at once."""
        out = np.zeros(flat.size)
        for m, w, n_c, speeds, cum, e_low, e_high, all_above in groups:
            out[flat < e_low] += all_above
            mid = np.flatnonzero((flat >= e_low) & (flat <= e_high))
            if mid.size:
                vstar = np.sqrt(2.0 * J_PER_KJ * flat[mid, None] / m[None, :])
                above = cum[-1] - cum[np.searchsorted(speeds, vstar.ravel(), side="right")].reshape(vstar.shape)
                out[mid] += (above / n_c) @ w
        return np.clip(out, 0.0, 1.0)

    @staticmethod
    def _joint_one(flat, groups) -> np.ndarray:
        """:meth:`_joint` at one energy (``flat``, one element [kJ]; what root finding asks): the same operations
        in the same order, so the same float, without the masks and index arrays of many energies."""
        x = flat[0]
        total = 0.0
        for m, w, n_c, speeds, cum, e_low, e_high, all_above in groups:
            if x < e_low:
                total += all_above
            elif x <= e_high:
                vstar = np.sqrt(2.0 * J_PER_KJ * flat[:, None] / m[None, :])
                above = cum[-1] - cum[speeds.searchsorted(vstar.ravel(), side="right")].reshape(vstar.shape)
                total += ((above / n_c) @ w)[0]
        return np.clip(np.array([total]), 0.0, 1.0)

    def joint_exceedance(self, energy_kj, mm) -> np.ndarray:
        """P(a fall reaches the line with energy above e) [-] under mass model ``mm`` (a ``mass_model``).

        Parameters
        ----------
        energy_kj : float or array_like
            Energies [kJ].
        mm : _MassModel
            Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].

        Returns
        -------
        numpy.ndarray
            Probabilities [-].
        """
        e = np.asarray(energy_kj, dtype=float)
        return self._joint(np.atleast_1d(e), self._groups(mm)[0]).reshape(e.shape)

    def exceedance_function(self, mm):
        """e [kJ] -> P(E > e) [-] for a fall reaching the line under ``mm``: the joint exceedance over P(reach),
        with the mass-model quadrature prepared once (for root finding and repeated evaluation).

        Parameters
        ----------
        mm : _MassModel
            Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].

        Returns
        -------
        callable
            ``f(energy_kj) -> P(E > e)``.
        """
        groups, reach = self._groups(mm)
        if reach <= 0:
            raise ValueError("no simulated block of the mass model's range reached the line")

        def fn(energy_kj):
            e = np.asarray(energy_kj, dtype=float)
            return (self._joint(np.atleast_1d(e), groups) / reach).reshape(e.shape)
        return fn

    def reach_probability(self, mm) -> float:
        """P(a fall reaches the line) under mass model ``mm``: sum over classes of P(M in class) P(reach | class).

        Parameters
        ----------
        mm : _MassModel
            Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].

        Returns
        -------
        float
            Probability [-].
        """
        return self._groups(mm)[1]

    def arrival_sf(self, mass_kg, mm) -> float:
        """P(a fall is heavier than m and reaches the line) [-] under ``mm`` (reach constant within a class).

        Parameters
        ----------
        mass_kg : float
            Mass m [kg].
        mm : _MassModel
            Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].

        Returns
        -------
        float
            Probability [-].
        """
        m = float(mass_kg)
        lo = self.edges_kg[:-1].copy()
        lo[0] = 0.0                                   # the end classes take the mass outside the range
        hi = self.edges_kg[1:]
        sf_lo = np.asarray(mm.sf(np.maximum(m, lo)), dtype=float)
        sf_hi = np.asarray(mm.sf(hi), dtype=float)
        sf_hi[-1] = 0.0
        return float(np.sum(self.reach_by_class * np.clip(sf_lo - sf_hi, 0.0, None)))

    def class_weights(self, mm) -> np.ndarray:
        """P(M in class) under ``mm`` (the classes at the ends take the mass outside the simulated range).

        Parameters
        ----------
        mm : _MassModel
            Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].

        Returns
        -------
        numpy.ndarray
            One probability [-] per class, summing to 1.
        """
        m, w, cls = self._nodes(mm)
        return np.bincount(cls, weights=w, minlength=self.n_bins)

    def outside_range(self, mm) -> tuple:
        """(P(M < lowest simulated class), P(M > highest)) under ``mm``.

        Parameters
        ----------
        mm : _MassModel
            Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].

        Returns
        -------
        tuple of float
            Probabilities [-].
        """
        return float(1.0 - mm.sf(self.edges_kg[0])), float(mm.sf(self.edges_kg[-1]))

    def with_representative(self, mm) -> "MassCoupledSamples":
        """A copy whose pooled samples represent the arriving falls under ``mm`` (systematic resampling).

        Parameters
        ----------
        mm : _MassModel
            Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].

        Returns
        -------
        MassCoupledSamples
        """
        arrived_cls = self.class_of(self.mass_kg[self.reached])
        n_c = np.array([n for n, _, _ in self._classes], dtype=float)
        w = self.class_weights(mm)[arrived_cls] / n_c[arrived_cls]
        if w.sum() <= 0:
            raise ValueError("no simulated block of the mass model's range reached the line")
        cdf = np.cumsum(w) / w.sum()
        k = w.size
        idx = np.minimum(np.searchsorted(cdf, (np.arange(k) + 0.5) / k), k - 1)
        return replace(self, representative=idx)

    @cached_property
    def _bootstrap_layout(self):
        """Per class: the number of blocks released, and for each released block (in the class's order) its
        position among the class's sorted arriving speeds (-1: it did not arrive)."""
        k = self.class_of(self.mass_kg)
        out = []
        for c in range(self.n_bins):
            members = np.flatnonzero(k == c)
            s = self.speed_ms[members]
            position = np.full(members.size, -1)
            arrived = np.flatnonzero(np.isfinite(s))
            position[arrived[np.argsort(s[arrived], kind="stable")]] = np.arange(arrived.size)
            out.append((members.size, position, arrived.size))
        return out

    def resampled_joint_exceedance(self, rng, energy_kj, mm) -> np.ndarray:
        """:meth:`joint_exceedance` of one bootstrap replicate: the blocks of each mass class drawn with
        replacement (reach and speed together), counted as multiplicities of the simulated blocks.

        Parameters
        ----------
        rng : numpy.random.Generator
            Stream of the replicate.
        energy_kj : array_like
            Energies [kJ].
        mm : _MassModel
            Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].

        Returns
        -------
        numpy.ndarray
            Probabilities [-].
        """
        arrivals = []
        for n_c, position, n_arrived in self._bootstrap_layout:
            drawn = position[rng.integers(0, n_c, n_c)]
            arrivals.append(np.bincount(drawn[drawn >= 0], minlength=n_arrived))
        e = np.asarray(energy_kj, dtype=float)
        return self._joint(np.atleast_1d(e), self._groups(mm, arrivals)[0]).reshape(e.shape)

    # ---- conditional percentiles and tables -----------------------------------------------------
    def velocity_percentile(self, q, mass_kg) -> float:
        """Speed [m/s] not exceeded by q % of the arriving blocks of the class of ``mass_kg``.

        Parameters
        ----------
        q : float
            Percentile, in [0, 100].
        mass_kg : float
            Block mass [kg].

        Returns
        -------
        float
            Speed [m/s].
        """
        return self._class_percentile(q, mass_kg, 1)

    def height_percentile(self, q, mass_kg) -> float:
        """Bounce height [m] not exceeded by q % of the arriving blocks of the class of ``mass_kg``.

        Parameters
        ----------
        q : float
            Percentile, in [0, 100].
        mass_kg : float
            Block mass [kg].

        Returns
        -------
        float
            Height of the block centre above the ground [m].
        """
        return self._class_percentile(q, mass_kg, 2)

    def _class_percentile(self, q, mass_kg, column: int) -> float:
        """q-th percentile of column ``column`` (1: speed, 2: height) of the arrivals in the class of ``mass_kg``
        (NaN when the class has none)."""
        values = self._classes[int(self.class_of(mass_kg))][column]
        return float(np.percentile(values, q)) if values.size else float("nan")

    def contains(self, mass_kg) -> bool:
        """Whether ``mass_kg`` lies inside the simulated mass range.

        Parameters
        ----------
        mass_kg : float
            Mass [kg].

        Returns
        -------
        bool
        """
        return bool(self.edges_kg[0] <= float(mass_kg) <= self.edges_kg[-1])

    def class_table(self) -> pd.DataFrame:
        """Per mass class: range [kg], blocks released and arriving, P(reach), speed p50/p95 [m/s], height p95 [m].

        Returns
        -------
        pandas.DataFrame
            One row per class: ``mass_low_kg``, ``mass_high_kg``, ``released``, ``reached``, ``reach_probability``,
            ``velocity_p50_ms``, ``velocity_p95_ms``, ``height_p95_m``.
        """
        rows = []
        for c, (n_c, s, h) in enumerate(self._classes):
            rows.append({"mass_low_kg": self.edges_kg[c], "mass_high_kg": self.edges_kg[c + 1], "released": n_c,
                         "reached": s.size, "reach_probability": s.size / n_c,
                         "velocity_p50_ms": float(np.median(s)) if s.size else np.nan,
                         "velocity_p95_ms": float(np.percentile(s, 95)) if s.size else np.nan,
                         "height_p95_m": float(np.percentile(h, 95)) if h.size else np.nan})
        return pd.DataFrame(rows)

    def summary(self) -> pd.DataFrame:
        """Per mass class: what the blocks of that class did at the line (the :meth:`class_table`).

        Returns
        -------
        pandas.DataFrame
            One row per mass class: ``mass_low_kg``, ``mass_high_kg`` [kg], ``released``, ``reached``,
            ``reach_probability``, ``velocity_p50_ms``, ``velocity_p95_ms`` [m/s], ``height_p95_m`` [m].
        """
        return self.class_table()

    def __repr__(self) -> str:
        return short_repr(self, repr(self.collector) if self.collector else "",
                          f"{self.mass_kg.size} blocks, {int(self.reached.sum())} reached",
                          f"{sig(self.edges_kg[0])}-{sig(self.edges_kg[-1])} kg in {self.n_bins} classes")

    def plot(self, ax=None, **kwargs):
        """Reach probability and median speed [m/s] at the line by mass class [kg] (drawn by :func:`riskrf.hazard.figures.plot_mass_classes`).

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
        from .figures import plot_mass_classes
        return plot_mass_classes(self, ax=ax, **kwargs)

    @property
    def description(self) -> str:
        """One sentence for reports: blocks simulated, mass range [kg], classes, and how reach probability and
        median speed [m/s] change from the lightest to the heaviest class.
        """
        t = self.class_table()
        return (f"mass-coupled: {self.mass_kg.size:,} blocks released with masses log-uniform over "
                f"{sig(self.edges_kg[0])}-{sig(self.edges_kg[-1])} kg in {self.n_bins} classes; P(reach) "
                f"{t['reach_probability'].iloc[0]:.3f} -> {t['reach_probability'].iloc[-1]:.3f} and median speed "
                f"{sig(t['velocity_p50_ms'].iloc[0])} -> {sig(t['velocity_p50_ms'].iloc[-1])} m/s from the lightest "
                "to the heaviest class")


def stratified_log_uniform(low_kg: float, high_kg: float, n: int, rng) -> np.ndarray:
    """n masses [kg], one uniformly in each of n equal slices of ln m over [low, high], in random order.

    Parameters
    ----------
    low_kg, high_kg : float
        Mass range [kg].
    n : int
        Masses drawn.
    rng : numpy.random.Generator
        The stream.

    Returns
    -------
    numpy.ndarray
        Masses [kg].
    """
    u = (np.arange(n) + rng.uniform(size=n)) / n
    m = np.exp(np.log(low_kg) + u * (np.log(high_kg) - np.log(low_kg)))
    return rng.permutation(m)


def default_mass_range(mm, rate_per_year: float) -> tuple:
    """The simulated mass range [kg] for mass model ``mm``: its lower end, and its upper end when finite
    (a truncated law), else the mass exceeded once in RANGE_RETURN_PERIOD_YEARS at ``rate_per_year``.

    Parameters
    ----------
    mm : _MassModel
        Mass model of the falls (:func:`riskrf.hazard.mass_models.mass_model`) [kg].
    rate_per_year : float
        Falls per year described by the mass model [1/yr].

    Returns
    -------
    tuple of float
        (low, high) [kg].
    """
    lo, hi = (float(v) for v in mm.support)
    if not np.isfinite(lo) or lo <= 0:
        lo = float(mm.isf(1.0 - 1e-6))
    if not np.isfinite(hi):
        hi = float(mm.isf(min(1.0 / (RANGE_RETURN_PERIOD_YEARS * rate_per_year), 1e-3)))
    return lo, hi


__all__ = ["MassCoupledSamples", "NoArrivalsError", "default_mass_range", "stratified_log_uniform"]
