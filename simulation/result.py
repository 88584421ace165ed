"""Results of a simulation run: collector tables, runout, stop reasons, envelopes, paths."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import stats

from .kernel import EVENTS, MODE_FLIGHT, OUTCOMES, STOP_REASONS
from ._display import Displayed, short_repr
from .units import J_PER_KJ, kinetic_energy_kj


def wilson_interval(k, n, level: float = 0.95):
    """Wilson score interval of a binomial proportion k/n (Monte Carlo confidence interval).

    Parameters
    ----------
    k : int or array_like
        Successes (e.g. blocks reaching a line).
    n : int or array_like
        Trials (blocks released), > 0.
    level : float
        Confidence level, in (0, 1).

    Returns
    -------
    tuple of numpy.ndarray
        (lower, upper) bounds of the proportion [-], clipped to [0, 1].

    References
    ----------
    Wilson, E. B. (1927). Probable inference, the law of succession, and statistical inference. Journal of the
    American Statistical Association 22(158), 209-212.
    """
    k, n = np.asarray(k, dtype=float), np.asarray(n, dtype=float)
    z = stats.norm.isf((1 - level) / 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = k / n
        centre = (p + z * z / (2 * n)) / (1 + z * z / n)
        half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return np.clip(centre - half, 0, 1), np.clip(centre + half, 0, 1)



def _three_figures(v: float) -> str:
    """Three significant figures without exponent notation: 1,070 not 1.07e+03."""
    return f"{v:,.0f}" if abs(v) >= 100 else f"{v:.3g}"

@dataclass(frozen=True, repr=False)
class SimulationResult(Displayed):
    """Everything a run produced.  Units: m, m/s, rad/s, kg, kJ, s."""

    scenario: object
    n: int
    seed: object
    blocks: dict = field(repr=False)
    per_block: dict = field(repr=False)
    crossings: dict = field(repr=False)
    envelope_x: np.ndarray = field(repr=False, default=None)
    envelope_acc: np.ndarray = field(repr=False, default=None)
    paths: dict = field(repr=False, default=None)
    elapsed_s: float = 0.0

    # ---- collectors --------------------------------------------------------------
    def collector(self, name: str, *, first_only: bool = False) -> pd.DataFrame:
        """One row per crossing of collector ``name``.

        Columns: ``block``, ``time_s``, ``velocity_ms``, ``vx_ms``, ``vz_ms``,
        ``angular_velocity_rads``, ``height_m`` (of the block centre above the
        ground), ``mass_kg``, ``radius_m``, ``inertia_factor`` (I / m r^2), ``energy_translational_kj``,
        ``energy_rotational_kj``, ``energy_kj`` (total), ``crossing_angle_deg``
        (below horizontal), ``outcome`` (crossed / caught / through / over).
        With ``first_only`` only each block's first crossing is kept.

        Parameters
        ----------
        name : str
            The collector's name in the scenario.
        first_only : bool
            Keep only each block's first crossing.

        Returns
        -------
        pandas.DataFrame
            One row per crossing, the columns above (units in their names: m/s, rad/s, m, kg, kJ, deg).
        """
        j = self.scenario.collector_index(name)
        sel = self.crossings["coll"] == j
        blk = self.crossings["block"][sel]
        vx, vz, w = self.crossings["vx"][sel], self.crossings["vz"][sel], self.crossings["w"][sel]
        mass = self.blocks["mass"][blk]
        radius = self.blocks["radius"][blk]
        k_inertia = self.blocks["inertia_factor"][blk]
        v = np.hypot(vx, vz)
        e_t = kinetic_energy_kj(mass, v)
        e_r = kinetic_energy_kj(mass, 0.0, w, radius, k_inertia)
        df = pd.DataFrame({
            "block": blk, "time_s": self.crossings["t"][sel], "velocity_ms": v, "vx_ms": vx, "vz_ms": vz,
            "angular_velocity_rads": w, "height_m": self.crossings["h"][sel], "mass_kg": mass, "radius_m": radius,
            "inertia_factor": k_inertia,
            "energy_translational_kj": e_t, "energy_rotational_kj": e_r, "energy_kj": e_t + e_r,
            "crossing_angle_deg": np.degrees(np.arctan2(-vz, np.abs(vx))),
            "outcome": pd.Categorical.from_codes(self.crossings["outcome"][sel], [OUTCOMES[i] for i in range(4)]),
        })
        if first_only:
            df = df.sort_values(["block", "time_s"]).drop_duplicates("block", keep="first")
        return df.reset_index(drop=True)

    def reach_probability(self, name: str, level: float = 0.95):
        """Fraction of released blocks that cross collector ``name``, with its Wilson interval.

        Parameters
        ----------
        name : str
            The collector's name.
        level : float
            Confidence level of the interval.

        Returns
        -------
        tuple of float
            (probability, lower, upper) [-].
        """
        k = self.collector(name, first_only=True).shape[0]
        lo, hi = wilson_interval(k, self.n, level)
        return k / self.n, float(lo), float(hi)

    def exceedance(self, name: str, column: str, value, level: float = 0.95) -> pd.DataFrame:
        """P(column > value) among blocks reaching ``name`` (first crossings), with Monte Carlo intervals.

        Parameters
        ----------
        name : str
            The collector's name.
        column : str
            A column of :meth:`collector` (e.g. ``"energy_kj"``, ``"height_m"``).
        value : float or array_like
            Threshold(s), in the column's unit.
        level : float
            Confidence level of the Wilson intervals.

        Returns
        -------
        pandas.DataFrame
            One row per value: the value, ``probability`` [-], ``ci_low``, ``ci_high``, ``n_reaching``.
        """
        df = self.collector(name, first_only=True)
        if column not in df.columns:
            raise KeyError(f"column {column!r} not in collector table; columns are {list(df.columns)}")
        x = np.sort(df[column].to_numpy())
        values = np.atleast_1d(np.asarray(value, dtype=float))
        k = x.size - np.searchsorted(x, values, side="right")
        lo, hi = wilson_interval(k, max(x.size, 1), level)
        return pd.DataFrame({column: values, "probability": k / max(x.size, 1), "ci_low": lo, "ci_high": hi,
                             "n_reaching": x.size})

    # ---- runout and stops ---------------------------------------------------------
    @property
    def runout(self) -> pd.DataFrame:
        """Per block: where and why it stopped, impacts, travel time and mass."""
        reasons = self.per_block["reason"]
        return pd.DataFrame({
            "x_stop_m": self.per_block["x"], "z_stop_m": self.per_block["z"],
            "reason": pd.Categorical([STOP_REASONS.get(int(r), "running") for r in reasons]),
            "impacts": self.per_block["impacts"], "time_s": self.per_block["t"], "mass_kg": self.blocks["mass"]})

    @property
    def stop_reasons(self) -> pd.Series:
        """How many blocks ended for each reason (never a silent truncation)."""
        counts = pd.Series(self.per_block["reason"]).map(lambda r: STOP_REASONS.get(int(r), "running"))
        return counts.value_counts().rename("blocks")

    @property
    def n_impacts(self) -> int:
        """Total number of ground impacts over all blocks."""
        return int(self.per_block["impacts"].sum())

    # ---- envelopes and paths -----------------------------------------------------
    @property
    def envelopes(self) -> pd.DataFrame:
        """Per x bin: passages, maximum and mean speed [m/s], height [m] and energy [kJ]."""
        acc = self.envelope_acc
        n = np.maximum(acc[:, 0], 1)
        return pd.DataFrame({"x_m": self.envelope_x, "passages": acc[:, 0].astype(int),
                             "velocity_max_ms": acc[:, 1], "velocity_mean_ms": acc[:, 4] / n,
                             "height_max_m": acc[:, 2], "height_mean_m": acc[:, 5] / n,
                             "energy_max_kj": acc[:, 3], "energy_mean_kj": acc[:, 6] / n})

    def events(self, block: int) -> pd.DataFrame:
        """The events of one recorded block in time order, with its energies.

        One row per event: release, impact (state just after), take-off, ground contact, slope change,
        momentary rest, collector crossing (``collector crossing: NAME``), through barrier, caught by
        barrier, stop, left profile.  Columns ``t_s``, ``x_m``, ``z_m`` (the block's point, in the
        profile's datum), ``vx_ms``, ``vz_ms``, ``angular_velocity_rads``, ``kinetic_energy_kj``
        (1/2 m v^2 + 1/2 I w^2), ``potential_energy_kj`` (m g z), ``total_energy_kj``, ``event``.
        Without ``allow_energy_gain`` the total never increases from one row to the next.
        Blocks 0 .. ``record_paths`` - 1 of the run are recorded.

        Parameters
        ----------
        block : int
            Index of a recorded block.

        Returns
        -------
        pandas.DataFrame
            One row per event, the columns above.

        Raises
        ------
        KeyError
            The block was not recorded.
        """
        sel = self.paths["block"] == block
        if not sel.any():
            raise KeyError(f"block {block} was not recorded; run with record_paths > {block}")
        ev = pd.DataFrame({"t_s": self.paths["t"][sel], "x_m": self.paths["x"][sel], "z_m": self.paths["z"][sel],
                           "vx_ms": self.paths["vx"][sel], "vz_ms": self.paths["vz"][sel],
                           "angular_velocity_rads": self.paths["w"][sel],
                           "event": [EVENTS[int(e)] for e in self.paths["event"][sel]]})
        crossings = []
        for c in self.scenario.collectors:
            df = self.collector(c.name)
            df = df[df["block"] == block]
            if len(df):
                crossings.append(pd.DataFrame({
                    "t_s": df["time_s"], "x_m": c.x, "z_m": self.scenario.profile.ground(c.x) + df["height_m"],
                    "vx_ms": df["vx_ms"], "vz_ms": df["vz_ms"], "angular_velocity_rads": df["angular_velocity_rads"],
                    "event": f"collector crossing: {c.name}"}))
        if crossings:
            ev = pd.concat(crossings + [ev], ignore_index=True).sort_values("t_s", kind="stable")  # crossing first at a tie
        mass, radius = self.blocks["mass"][block], self.blocks["radius"][block]
        k_inertia = self.blocks["inertia_factor"][block]
        g = self.scenario.settings.gravity_ms2
        ev["kinetic_energy_kj"] = kinetic_energy_kj(mass, np.hypot(ev["vx_ms"], ev["vz_ms"]), ev["angular_velocity_rads"],
                                                    radius, k_inertia)
        ev["potential_energy_kj"] = mass * g * ev["z_m"] / J_PER_KJ
        ev["total_energy_kj"] = ev["kinetic_energy_kj"] + ev["potential_energy_kj"]
        cols = ["t_s", "x_m", "z_m", "vx_ms", "vz_ms", "angular_velocity_rads", "kinetic_energy_kj",
                "potential_energy_kj", "total_energy_kj", "event"]
        return ev[cols].reset_index(drop=True)

    def path(self, block: int, dt: float = 0.01) -> pd.DataFrame:
        """Sampled path (x, z) of one of the recorded blocks, exact between events.

        Parameters
        ----------
        block : int
            Index of a recorded block (one of the first ``record_paths``).
        dt : float
            Time step of the samples [s].

        Returns
        -------
        pandas.DataFrame
            Columns ``x_m``, ``z_m`` [m].
        """
        sel = self.paths["block"] == block
        if not sel.any():
            raise KeyError(f"block {block} was not recorded; run with record_paths > {block}")
        t, x, z = self.paths["t"][sel], self.paths["x"][sel], self.paths["z"][sel]
        vx, vz, mode = self.paths["vx"][sel], self.paths["vz"][sel], self.paths["mode"][sel]
        g = self.scenario.settings.gravity_ms2
        xs, zs = [x[:1]], [z[:1]]
        for i in range(len(t) - 1):
            span = t[i + 1] - t[i]
            if mode[i] == MODE_FLIGHT and span > 0:
                tt = np.arange(dt, span, dt)
                xs.append(x[i] + vx[i] * tt)
                zs.append(z[i] + vz[i] * tt - 0.5 * g * tt ** 2)
            xs.append(x[i + 1:i + 2])
            zs.append(z[i + 1:i + 2])
        return pd.DataFrame({"x_m": np.concatenate(xs), "z_m": np.concatenate(zs)})

    # ---- summary -------------------------------------------------------------------
    def __repr__(self) -> str:
        return short_repr(self, repr(self.scenario.name), n=self.n, seed=self.seed, elapsed_s=self.elapsed_s)

    def plot(self, ax=None, *, n_paths: int = 20):
        """The slope profile with up to ``n_paths`` recorded trajectories, the collectors and the release zone.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).
        n_paths : int
            Most trajectories drawn (those recorded with ``record_paths``).

        Returns
        -------
        matplotlib.axes.Axes
            x: horizontal distance [m]; z: elevation [m] (:func:`simulation.plotting.plot_profile`).
        """
        from .plotting import plot_profile
        return plot_profile(self, ax, n_paths=n_paths)

    def summary(self) -> pd.DataFrame:
        """Run facts and, per collector, reach probability and speed/height/energy percentiles.

        Returns
        -------
        pandas.DataFrame
            Index: quantity (with its unit: s, m/s, m, kJ); column ``value``.
        """
        rows = {"blocks": self.n, "seed": self.seed, "impacts": self.n_impacts,
                "run time [s]": round(self.elapsed_s, 3),
                "impacts per second": round(self.n_impacts / max(self.elapsed_s, 1e-9)),
                "blocks per second": round(self.n / max(self.elapsed_s, 1e-9))}
        for reason, count in self.stop_reasons.items():
            rows[f"stopped: {reason}"] = int(count)
        for c in self.scenario.collectors:
            df = self.collector(c.name, first_only=True)
            p = len(df) / self.n
            lo, hi = wilson_interval(len(df), self.n)
            rows[f"{c.name}: reach probability"] = f"{p:.4f} ({lo:.4f}-{hi:.4f})"
            if len(df):
                for col, unit in (("velocity_ms", "m/s"), ("height_m", "m"), ("energy_kj", "kJ")):
                    q = np.percentile(df[col], [50, 95, 99])
                    rows[f"{c.name}: {col} p50/p95/p99 [{unit}]"] = " / ".join(_three_figures(v) for v in q)
                if c.is_barrier:
                    rows[f"{c.name}: outcomes"] = ", ".join(f"{k} {v}" for k, v in
                                                           df["outcome"].value_counts().items() if v)
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})
