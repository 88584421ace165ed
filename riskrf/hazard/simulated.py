"""The impact-energy hazard at a line from trajectories simulated across the whole mass range.

:func:`energy_hazard` runs the simulator (:mod:`simulation`) with block masses spread log-uniformly over the
mass model's range and builds an :class:`~riskrf.hazard.annual_hazard.EnergyHazard` whose velocity model is a
:class:`~riskrf.hazard.mass_coupling.MassCoupledSamples` (reach, speed and bounce height by mass class; the
method and its references are in :mod:`riskrf.hazard.mass_coupling`).  The only hazard module that runs the
simulator.
"""
from __future__ import annotations

import numpy as np

import simulation

from ..core.format import sig
from ..core.units import DESIGN_RETURN_PERIODS
from ..core.validation import check_positive
from .annual_hazard import EnergyHazard, effective_speeds
from .mass_models import mass_model
from .mass_coupling import MassCoupledSamples, NoArrivalsError, default_mass_range, stratified_log_uniform


def load_any_scenario(scenario):
    """A 2-D :class:`simulation.Scenario` or a 3-D :class:`simulation.TerrainScenario` as given, or read from a
    TOML file (a ``[terrain]`` table makes it 3-D, a ``[profile]`` table 2-D).

    Parameters
    ----------
    scenario : simulation.Scenario, simulation.TerrainScenario, str or path
        The scenario or its TOML file.

    Returns
    -------
    simulation.Scenario or simulation.TerrainScenario
    """
    if isinstance(scenario, (simulation.Scenario, simulation.TerrainScenario)):
        return scenario
    if simulation.is_terrain_scenario_file(scenario):
        return simulation.load_terrain_scenario(scenario)
    return simulation.load_scenario(scenario)


def run_any(scenario, *, seed, masses_kg, workers: int = 1):
    """Run a 2-D scenario (:func:`simulation.run`) or a 3-D one (:func:`simulation.run_terrain`, ``workers``
    threads) with the given block masses [kg]; both results give ``collector(name, first_only=True)`` rows with
    ``block``, ``velocity_ms``, ``angular_velocity_rads``, ``radius_m``, ``height_m``.

    Parameters
    ----------
    scenario : simulation.Scenario or simulation.TerrainScenario
        The scenario.
    seed : int
        Seed of the run.
    masses_kg : array_like
        One mass per block [kg].
    workers : int
        Threads of a 3-D run.

    Returns
    -------
    simulation.SimulationResult or simulation.TerrainResult
    """
    if isinstance(scenario, simulation.TerrainScenario):
        return simulation.run_terrain(scenario, seed=seed, masses_kg=masses_kg, workers=workers)
    return simulation.run(scenario, seed=seed, masses_kg=masses_kg)


def energy_hazard(mass, scenario, collector: str = "barrier", *, rate_per_year=None, n: int = 20_000, seed=1,
                  mass_range_kg=None, design_masses_kg=(), n_bins: int | None = None, rotational: bool = True,
                  return_periods=DESIGN_RETURN_PERIODS):
    """Annual impact-energy hazard at a line with reach, speed and bounce height coupled to block mass.

    Parameters
    ----------
    mass : GutenbergRichterFit (usually truncated at m_max), Gumbel/GEV fit or scipy distribution
        Mass model [kg] of the falls at the source.
    scenario : simulation.Scenario, simulation.TerrainScenario or path to a scenario TOML
        The slope, a 2-D profile or 3-D terrain (a ``[terrain]`` table: the 3-D kernel runs and the line is a
        plan polyline); its seeder's (sources') mass distribution is replaced by the simulated mass range.
    collector : str
        The line (a collector of the scenario).
    rate_per_year : float, optional
        Falls per year described by ``mass`` (default: the power law's rate above m_min).
    n : int
        Blocks simulated (masses log-uniform over the range, stratified).
    seed : int
        Seed of the simulation (same seed, same numbers).
    mass_range_kg : (low, high), optional
        Simulated masses [kg]; default :func:`default_mass_range`, widened to include ``design_masses_kg``.
    design_masses_kg : sequence of float
        Masses [kg] that design values will be read at (a design block, a larger m_max of a sensitivity
        study): they must lie inside the simulated range (an error names the first that does not).
    n_bins : int, optional
        Mass classes (default n // 400 within 4-24).
    rotational : bool
        Include the rotational energy (V_eff^2 = v^2 + k (w r)^2).
    return_periods : sequence of float
        Return periods [yr] whose T-year blocks at the source (``mass.isf(1 / (T rate))``) must also lie inside
        the simulated range.

    Returns
    -------
    EnergyHazard
        With ``velocity`` a :class:`~riskrf.hazard.mass_coupling.MassCoupledSamples` and the mass-averaged reach
        probability; energies in kJ, rates per year.
    """
    return simulate_energy_hazard(mass, scenario, collector, rate_per_year=rate_per_year, n=n, seed=seed,
                                  mass_range_kg=mass_range_kg, design_masses_kg=design_masses_kg, n_bins=n_bins,
                                  rotational=rotational, return_periods=return_periods)[0]


def coupled_samples(result, collector: str, masses_kg, edges_kg, mass_model, *, rotational: bool = True):
    """The :class:`MassCoupledSamples` of one collector of a run of blocks of given masses, or None when no block
    reached it.

    Each released block (``masses_kg``, in the order simulated) keeps its speed [m/s] and passing height [m] at its
    first crossing of ``collector`` (NaN when it never crossed); with ``rotational`` the speed is the effective one,
    v_eff^2 = v^2 + k (omega r)^2 (:func:`~riskrf.hazard.annual_hazard.effective_speeds`), so that 1/2 m v_eff^2 is
    the translational plus rotational energy.  ``edges_kg`` are the mass-class edges [kg]; the classes take their
    representative mass from ``mass_model``.

    Parameters
    ----------
    result : simulation.SimulationResult or simulation.TerrainResult
        The run.
    collector : str
        The line.
    masses_kg : array_like
        Each released block's mass [kg], in the order simulated.
    edges_kg : array_like
        Mass-class edges [kg].
    mass_model : _MassModel
        The mass model of the falls [kg].
    rotational : bool
        Use the effective speed including rotation.

    Returns
    -------
    MassCoupledSamples or None
    """
    df = result.collector(collector, first_only=True)
    if df.empty:
        return None
    speed = np.full(result.n, np.nan)
    height = np.full(result.n, np.nan)
    v = effective_speeds(df) if rotational else df["velocity_ms"].to_numpy()
    blk = df["block"].to_numpy()
    speed[blk] = v
    height[blk] = df["height_m"].to_numpy()
    return MassCoupledSamples(np.asarray(masses_kg, dtype=float), speed, height, np.asarray(edges_kg, dtype=float),
                              collector).with_representative(mass_model)


def simulate_energy_hazard(mass, scenario, collector: str = "barrier", *, rate_per_year=None, n: int = 20_000,
                           seed=1, mass_range_kg=None, design_masses_kg=(), n_bins: int | None = None,
                           rotational: bool = True, return_periods=DESIGN_RETURN_PERIODS, workers: int = 1):
    """:func:`energy_hazard` that also returns the run (a :class:`simulation.SimulationResult`, or a
    :class:`simulation.TerrainResult` on 3-D terrain, run on ``workers`` threads): (hazard, result).

    Parameters
    ----------
    mass, scenario, collector, rate_per_year, n, seed, mass_range_kg, design_masses_kg, n_bins, rotational, return_periods
        As for :func:`energy_hazard` (masses kg, rates per year, return periods yr).
    workers : int
        Threads of a 3-D run.

    Returns
    -------
    tuple of (EnergyHazard, simulation.SimulationResult or simulation.TerrainResult)
        The hazard and the run behind it (blocks of the simulated masses).
    """
    mm = mass_model(mass)
    if rate_per_year is None:
        rate_per_year = mm.rate_per_year
        if rate_per_year is None:
            raise ValueError("rate_per_year is needed unless the mass model is a power-law fit")
    rate = check_positive(rate_per_year, "rate_per_year")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 100:
        raise ValueError(f"n = {n!r}: simulate at least 100 blocks across the mass range")
    design = np.atleast_1d(np.asarray(design_masses_kg, dtype=float))
    if design.size and np.any(~np.isfinite(design) | (design <= 0)):
        raise ValueError(f"design_masses_kg = {design.tolist()}: masses must be finite and > 0 kg")
    T = np.atleast_1d(np.asarray(return_periods, dtype=float))
    T = T[T * rate > 1]
    t_blocks = np.asarray(mm.isf(1.0 / (T * rate)), dtype=float) if T.size else np.empty(0)
    if mass_range_kg is None:
        lo, hi = default_mass_range(mm, rate)
        hi = max([hi] + design.tolist())
        lo = min([lo] + design.tolist())
    else:
        try:
            lo, hi = (float(v) for v in mass_range_kg)
        except (TypeError, ValueError):
            raise ValueError(f"mass_range_kg = {mass_range_kg!r} must be (low, high) in kg") from None
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
            raise ValueError(f"mass_range_kg = {mass_range_kg!r} must satisfy 0 < low < high (finite, kg)")
        for what, values in (("design mass", design), ("T-year block", t_blocks)):
            for v in values:
                if not lo <= v <= hi:
                    raise ValueError(f"mass_range_kg = ({sig(lo, 4)}, {sig(hi, 4)}): the {what} {sig(v, 4)} kg lies outside the "
                                     "simulated masses; widen the range so that no design value is extrapolated")
    if n_bins is None:
        n_bins = int(np.clip(n // 400, 4, 24))
    if isinstance(n_bins, bool) or not isinstance(n_bins, (int, np.integer)) or not 1 <= n_bins <= n // 20:
        raise ValueError(f"n_bins = {n_bins!r} must be a whole number between 1 and n / 20 = {n // 20}")
    sc = load_any_scenario(scenario)
    sc.collector_index(collector)
    rng = np.random.default_rng(np.random.SeedSequence([0 if seed is None else int(seed), 10]))
    masses = stratified_log_uniform(lo, hi, int(n), rng)
    result = run_any(sc, seed=seed, masses_kg=masses, workers=workers)
    edges = np.exp(np.linspace(np.log(lo), np.log(hi), n_bins + 1))
    edges[0], edges[-1] = lo, hi
    samples = coupled_samples(result, collector, masses, edges, mm, rotational=rotational)
    if samples is None:
        raise NoArrivalsError(f"no simulated block reached collector {collector!r}: the hazard there is nil for "
                              "the simulated release; check the scenario")
    reach = samples.reach_probability(mm)
    below, above = samples.outside_range(mm)
    notes = [samples.description + "; the seeder's own mass distribution is not used"
             + ("; rotational energy included (v_eff^2 = v^2 + k (w r)^2)" if rotational else ""),
             f"reach probability {reach:.4f} averaged over the mass model (by mass class: "
             f"{samples.reach_by_class.min():.3f}-{samples.reach_by_class.max():.3f})"]
    if below > 1e-9 or above > 1e-9:
        notes.append(f"mass model beyond the simulated masses: P(M < {sig(edges[0])} kg) = {sig(below, 2)}, "
                     f"P(M > {sig(edges[-1])} kg) = {sig(above, 2)}; they take the behaviour of the nearest mass class "
                     "(an extrapolation, stated)")
    hz = EnergyHazard(mass=mass, velocity=samples, rate_per_year=rate, reach_probability=max(reach, 1e-300),
                      n_released=result.n, heights_m=samples.heights_m, collector=collector, notes=tuple(notes))
    return hz, result


__all__ = ["coupled_samples", "energy_hazard", "load_any_scenario", "run_any", "simulate_energy_hazard"]
