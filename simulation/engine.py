"""Running a scenario: seeding blocks, chunking, and collecting the kernel's outputs.

``run(scenario, n, seed)`` draws every block's initial state with NumPy
generators spawned from ``SeedSequence(seed)`` (one per quantity, so the draws
do not depend on chunking), runs the compiled kernel chunk by chunk (default
100,000 blocks per chunk), each chunk appending its collector crossings to one
set of buffers that the result keeps, and merges the envelopes.  Per-impact random
numbers come from a stream keyed by (seed, block index): the same seed gives
the same numbers whatever the chunk size.
"""
from __future__ import annotations

import sys
import time

import numpy as np

from . import kernel
from .kernel_args import (Blocks2D, Collectors2D, Crossings2D, Envelope2D, KernelSettings, MaterialTable, Paths2D,
                          Profile2D, Stops2D)
from .result import SimulationResult
from .scenario import Scenario

DEFAULT_CHUNK = 100_000
CROSSING_BLOCKS = 1_000_000    # crossing rows are allotted for this many blocks at a time (crossing_capacity)


def material_table(scenario: Scenario) -> tuple[MaterialTable, np.ndarray]:
    """The scenario's materials as the kernels take them: the :class:`~simulation.kernel_args.MaterialTable` (one
    entry per material index) and the per-material rolling drag [-].

    Parameters
    ----------
    scenario : Scenario or TerrainScenario
        The scenario about to be simulated.

    Returns
    -------
    tuple
        (MaterialTable, rolling drag per material).
    """
    mats = scenario.materials
    f = lambda attr: np.array([getattr(m, attr) for m in mats], dtype=float)  # noqa: E731
    table = MaterialTable(
        en_law=np.array([m.en_law for m in mats], dtype=np.int64), en_mean=f("en_mean"), en_std=f("en_std"),
        et_law=np.array([m.et_law for m in mats], dtype=np.int64), et_mean=f("et_mean"), et_std=f("et_std"),
        phi=f("friction_deg"), phi_std=f("friction_std_deg"), rough=f("roughness_m"),
        roll=np.array([m.ground_motion == "roll" for m in mats], dtype=np.bool_),
        mu_ground=np.tan(np.radians(f("ground_friction_deg"))),
        gain=np.array([m.allow_energy_gain for m in mats], dtype=np.bool_),
        en_v0=f("en_velocity_scale_ms"), hop=f("hop_height_m"), size_k=f("rolling_size_coefficient"),
        mu_cap=np.tan(np.radians(f("rolling_resistance_cap_deg"))), size_exp=f("rolling_size_exponent"),
        et_v0=f("et_normal_scale_ms"), phig=f("ground_friction_deg"), phig_std=f("ground_friction_std_deg"),
        dev=f("lateral_deviation"), dev_v=f("lateral_deviation_speed_ms"))
    return table, f("rolling_drag")


def kernel_settings(settings, key, n_path_blocks: int) -> KernelSettings:
    """The run's scalars as the kernels take them, each of the type the compiled kernel was built for (a float
    gravity typed as an integer would otherwise compile a second version).

    Parameters
    ----------
    settings : simulation.scenario.Settings
        The scenario's settings.
    key : numpy.uint64
        The run's random key.
    n_path_blocks : int
        The paths of the blocks with index below this are recorded.

    Returns
    -------
    KernelSettings
    """
    return KernelSettings(g=float(settings.gravity_ms2), v_contact=float(settings.contact_velocity_ms),
                          v_stop=float(settings.stop_velocity_ms), max_events=int(settings.max_events),
                          key=np.uint64(key), n_path_blocks=int(n_path_blocks))


def kernel_features(scenario: Scenario) -> tuple[bool, bool]:
    """Which optional contact features a scenario uses: (rolling drag, steep-face rule).

    :func:`run` passes ``m_drag`` = None to :func:`simulation.kernel.simulate` when no material has a rolling
    drag, and ``sin_max_roll`` = None when no segment of the profile is steeper than ``max_rolling_slope_deg``
    (less a margin of 1e-9 in the sine, so rounding never hides one); numba then compiles a specialisation of
    the kernel with that feature's code pruned, and the features cost nothing where they are not used.  The
    results are the same either way: with no drag the contact steps take c = 0 in both, and the steep-face
    tests are false on every segment.

    Parameters
    ----------
    scenario : Scenario
        The scenario about to be simulated.

    Returns
    -------
    tuple of bool
        (some material has ``rolling_drag`` > 0, some segment is steeper than ``max_rolling_slope_deg``).
    """
    drag = any(m.rolling_drag > 0.0 for m in scenario.materials)
    sin_max = scenario.settings.sin_max_roll
    prof = scenario.profile
    dx, dz = np.diff(prof.x), np.diff(prof.z)
    steep = sin_max < 1.0 and bool(np.any(np.abs(dz) / np.hypot(dx, dz) > sin_max - 1e-9))
    return drag, steep


def check_masses(masses_kg, n=None) -> np.ndarray:
    """Block masses [kg] given to :func:`run`: a 1-d array of finite values > 0 (n of them when n is given).

    Parameters
    ----------
    masses_kg : array_like
        Block masses [kg].
    n : int, optional
        The number of blocks they must number.

    Returns
    -------
    numpy.ndarray
        1-d float array [kg].

    Raises
    ------
    ValueError
        Naming the first bad mass and its position, or the count mismatch.
    """
    m = np.asarray(masses_kg, dtype=float)
    if m.ndim != 1 or m.size == 0:
        raise ValueError(f"masses_kg must be a non-empty 1-d array of masses [kg]; got shape {m.shape}")
    bad = ~np.isfinite(m) | (m <= 0)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"masses_kg[{i}] = {float(m[i])!r}: block masses must be finite and > 0 kg")
    if n is not None and m.size != n:
        raise ValueError(f"masses_kg has {m.size} masses but n = {n}: give one mass per block (or n=None)")
    return m


def seed_blocks(scenario: Scenario, n: int, seed, masses_kg=None) -> dict:
    """Initial state of n blocks: position [m], velocity [m/s], spin [rad/s], mass [kg], radius [m], I/(m r^2).

    With ``masses_kg`` the blocks get those masses and the seeder's mass distribution is not used (the other
    quantities are drawn exactly as without it, from the same streams).

    Parameters
    ----------
    scenario : Scenario
        Its seeder gives the release zone and the distributions.
    n : int
        Number of blocks.
    seed : int, numpy.random.SeedSequence or None
        Seed of the independent streams (one per quantity, :meth:`numpy.random.SeedSequence.spawn`).
    masses_kg : array_like, optional
        The mass of each block [kg].

    Returns
    -------
    dict of numpy.ndarray
        ``x``, ``z`` [m], ``vx``, ``vz`` [m/s], ``w`` [rad/s], ``mass`` [kg], ``radius`` [m], ``inertia_factor`` [-],
        one entry per block.
    """
    sd = scenario.seeder
    ss = np.random.SeedSequence(seed)
    g_x, g_h, g_m, g_vx, g_vz, g_w = (np.random.default_rng(c) for c in ss.spawn(6))
    x = g_x.uniform(sd.x_low, sd.x_high, n) if sd.x_high > sd.x_low else np.full(n, sd.x_low)
    h = sd.height_m.sample(g_h, n)
    mass = sd.mass_kg.sample(g_m, n) if masses_kg is None else check_masses(masses_kg, n).copy()
    vx, vz = sd.vx_ms.sample(g_vx, n), sd.vz_ms.sample(g_vz, n)
    if sd.downslope_speed_ms is not None:
        # a push along the ground under the release point, in its falling sense (+x on flat ground): a block
        # released on ground flatter than its rolling-resistance angle then still starts (its own stream)
        u = sd.downslope_speed_ms.sample(np.random.default_rng(ss.spawn(1)[0]), n)
        cos_b, sin_b = scenario.profile.downslope_direction(x)
        vx, vz = vx + u * cos_b, vz + u * sin_b
    return {"x": x, "z": scenario.profile.ground(x) + h, "vx": vx,
            "vz": vz, "w": sd.angular_velocity_rads.sample(g_w, n),
            "mass": mass, "radius": sd.radius(mass), "inertia_factor": np.full(n, sd.inertia_factor),
            "resistance_deviate": resistance_deviates(scenario, ss, n)}


def resistance_deviates(scenario, ss: np.random.SeedSequence, n: int) -> np.ndarray:
    """Each block's standard normal deviate z_b of its rolling resistance: it rolls with phi_g + z_b
    ``ground_friction_std_deg`` on every material (:class:`simulation.scenario.Material`).  Drawn from the next
    child stream of ``ss`` (after those of the other quantities, which are the same with and without it), and only
    where a material has a spread: zeros otherwise, so such runs draw nothing more.

    Parameters
    ----------
    scenario : Scenario or TerrainScenario
        The scenario (its materials).
    ss : numpy.random.SeedSequence
        The run's seed sequence, its other streams spawned.
    n : int
        Number of blocks.

    Returns
    -------
    numpy.ndarray
        z_b per block [-].
    """
    if not any(m.ground_friction_std_deg > 0.0 for m in scenario.materials):
        return np.zeros(n)
    return np.random.default_rng(ss.spawn(1)[0]).standard_normal(n)


_CROSSING_FIELDS = (("block", np.int64), ("coll", np.int64), ("t", float), ("vx", float), ("vz", float),
                    ("w", float), ("h", float), ("outcome", np.int64))


def crossing_capacity(n: int, n_collectors: int) -> int:
    """Rows first allotted to the collector crossings of ``n`` blocks: four per block and collector (a block crosses
    a collector once unless it rolls back over it), at least 16.  More rows are made when they are needed.

    Parameters
    ----------
    n : int
        Number of blocks.
    n_collectors : int
        Number of collectors.

    Returns
    -------
    int
        Number of rows.
    """
    return max(4 * n * max(n_collectors, 1), 16)


def _crossing_buffers(cap: int) -> dict:
    """Empty per-crossing arrays of ``cap`` rows (the kernel's ``Crossings2D`` fields)."""
    return {k: np.empty(cap, dtype=dt) for k, dt in _CROSSING_FIELDS}


def _grown(r: dict, keep: int, cap: int) -> dict:
    """New per-crossing arrays of ``cap`` rows holding the first ``keep`` rows of ``r``."""
    out = _crossing_buffers(cap)
    for k in out:
        out[k][:keep] = r[k][:keep]
    return out


def _merge_envelopes(total, chunk) -> None:
    """Add one chunk's envelope accumulators: counts and sums add, maxima take the larger."""
    for col in (0, 4, 5, 6):
        total[:, col] += chunk[:, col]
    for col in (1, 2, 3):
        np.maximum(total[:, col], chunk[:, col], out=total[:, col])


def _progress_bar(done: int, total: int, started: float, stream) -> None:
    frac = done / total
    bar = "#" * int(30 * frac)
    rate = done / max(time.perf_counter() - started, 1e-9)
    stream.write(f"\rsimulating [{bar:<30}] {done:>9,}/{total:,} blocks  {rate:,.0f} blocks/s")
    stream.flush()
    if done == total:
        stream.write("\n")


def run(scenario: Scenario, n: int | None = None, seed=None, *, masses_kg=None, chunk_size: int = DEFAULT_CHUNK,
        record_paths: int = 20, progress: bool | None = None) -> SimulationResult:
    """Simulate ``n`` blocks released by the scenario's seeder.

    Parameters
    ----------
    scenario : Scenario
        From :func:`simulation.load_scenario`.
    n : int
        Number of blocks (> 0; 10,000 when neither it nor ``masses_kg`` is given); with ``masses_kg`` it may be
        left out (one block per mass) or must equal their number.
    seed : int, optional
        Random seed; the same seed gives identical results for any ``chunk_size``.
    masses_kg : array, optional
        The mass [kg] of each block (finite, > 0); the seeder's mass distribution is then ignored
        (used to simulate across a mass model's whole range, e.g. ``riskrf.energy_hazard``).
    chunk_size : int
        Blocks per kernel call (memory bound; results do not depend on it).
    record_paths : int
        Keep the full event sequence of the first ``record_paths`` blocks for plotting.
    progress : bool, optional
        Show a progress bar on standard error (default: when n >= 200,000 and stderr is a terminal).

    Returns
    -------
    SimulationResult
        Every block's stop, the collectors' crossings (velocity [m/s], height [m], energy [kJ]), envelopes and
        the recorded paths.
    """
    if masses_kg is not None:
        masses_kg = check_masses(masses_kg, None if n is None else n)
        n = masses_kg.size
    elif n is None:
        n = 10_000
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n <= 0:
        raise ValueError(f"n must be a positive whole number of blocks; got {n!r}")
    if chunk_size <= 0:
        raise ValueError(f"chunk_size must be > 0; got {chunk_size!r}")
    n = int(n)
    if progress is None:
        progress = n >= 200_000 and sys.stderr.isatty()
    key = np.random.SeedSequence(seed).generate_state(1, dtype=np.uint64)[0]
    blocks = seed_blocks(scenario, n, seed, masses_kg)
    prof = scenario.profile
    st = scenario.settings
    mats, m_drag = material_table(scenario)
    uses_drag, uses_steep = kernel_features(scenario)
    if not uses_drag:
        m_drag = None                    # the kernel's specialisation without rolling drag (kernel_features)
    sin_max_roll = st.sin_max_roll if uses_steep else None
    cols = scenario.collectors
    c_x = np.array([c.x for c in cols], dtype=float)
    c_cap = np.array([np.nan if c.capacity_kj is None else c.capacity_kj for c in cols], dtype=float)
    c_h = np.array([np.nan if c.height_m is None else c.height_m for c in cols], dtype=float)
    c_order = np.argsort(c_x, kind="stable")     # collectors in x order: the order of crossing along the motion
    collectors = Collectors2D(c_x, c_cap, c_h, c_order)
    nb = st.envelope_bins
    edges = np.linspace(prof.x[0], prof.x[-1], nb + 1)
    env_x = 0.5 * (edges[:-1] + edges[1:]) if nb else np.empty(0)
    env_acc = np.zeros((env_x.size, 7))
    n_paths = min(int(record_paths), n)
    path_cap = max(n_paths * (st.max_events * 3 + 8), 1)
    settings = kernel_settings(st, key, n_paths)
    paths = {k: np.empty(path_cap, dtype=dt) for k, dt in
             (("block", np.int64), ("t", float), ("x", float), ("z", float), ("vx", float), ("vz", float),
              ("w", float), ("mode", np.int64), ("event", np.int64))}
    pcount = np.zeros(1, np.int64)
    per_block = {k: np.empty(n, dtype=dt) for k, dt in
                 (("x", float), ("z", float), ("reason", np.int64), ("impacts", np.int64), ("t", float))}
    # One set of crossing buffers for the whole run: each chunk's kernel call appends at the count the previous
    # chunks left (as the paths do), so the rows are written once, where the result keeps them (no copy per chunk
    # and no concatenation at the end).  Only the rows written are ever touched, so the generous capacity costs
    # address space, not memory; it is allotted for up to CROSSING_BLOCKS blocks at a time.
    r = _crossing_buffers(crossing_capacity(min(n, CROSSING_BLOCKS), len(cols)))
    r_count = np.zeros(2, np.int64)
    chunks = [(lo, min(lo + chunk_size, n)) for lo in range(0, n, chunk_size)]
    started = None
    for lo, hi in [(0, 0)] + chunks:     # an empty first call compiles (or loads) the kernel, untimed
        if started is None and hi > 0:
            started = time.perf_counter()
        p_start, r_start = int(pcount[0]), int(r_count[0])
        room = r["block"].shape[0] - r_start
        if room < crossing_capacity(hi - lo, len(cols)):
            r = _grown(r, r_start, max(2 * r["block"].shape[0],
                                       r_start + crossing_capacity(min(n - lo, CROSSING_BLOCKS), len(cols))))
        while True:
            # Every crossing is kept: when the buffers are too small for a chunk, they grow to hold the rows the
            # chunk needs (the earlier chunks' rows copied over) and the chunk is run again (trajectories depend
            # only on the seed and the block index, so the rerun gives the same numbers).
            env_chunk = np.zeros_like(env_acc)
            pcount[0] = p_start
            kernel.simulate(
                Blocks2D(np.arange(lo, hi, dtype=np.int64), *(blocks[k][lo:hi] for k in
                                                             ("x", "z", "vx", "vz", "w", "mass", "radius",
                                                              "inertia_factor", "resistance_deviate"))),
                Profile2D(prof.x, prof.z, prof.tree_offset, prof.n_leaves, prof.material_index, prof.run_first,
                          prof.run_last),
                mats, m_drag, collectors, Envelope2D(env_x, env_chunk), settings, sin_max_roll,
                Stops2D(*(per_block[k][lo:hi] for k in ("x", "z", "reason", "impacts", "t"))),
                Crossings2D(**r, count=r_count), Paths2D(**paths, count=pcount))
            if r_count[1] == 0:
                break
            need = int(r_count[0] + r_count[1])
            r = _grown(r, r_start, need + crossing_capacity(min(n - hi, CROSSING_BLOCKS), len(cols)))
            r_count[:] = (r_start, 0)
        _merge_envelopes(env_acc, env_chunk)
        if progress and hi > 0:
            _progress_bar(hi, n, started, sys.stderr)
    elapsed = time.perf_counter() - started
    k = int(r_count[0])
    merged = {name: arr[:k] for name, arr in r.items()}
    k = int(pcount[0])
    return SimulationResult(scenario=scenario, n=n, seed=seed, blocks=blocks, per_block=per_block,
                            crossings=merged, envelope_x=env_x, envelope_acc=env_acc,
                            paths={name: arr[:k] for name, arr in paths.items()}, elapsed_s=elapsed)

