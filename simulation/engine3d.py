"""Running a 3-D terrain scenario: seeding, chunking (and threads), collecting the kernel's outputs.

As in 2-D (:mod:`simulation.engine`): every block's initial state is drawn up front with NumPy generators
spawned from ``SeedSequence(seed)`` (one per quantity), and per-impact random numbers come from a stream
keyed by (seed, block index), so results are identical whatever the chunk size or number of threads.
The compiled kernel releases the GIL, so ``workers`` threads run chunks in parallel.
"""
from __future__ import annotations

import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from numba import njit

from . import kernel3d
from .hazard_grids import deposition_density, mask_holes
from .engine import check_masses, kernel_settings, material_table, resistance_deviates
from .kernel import OUTCOMES
from .kernel_args import Blocks3D, Collectors3D, Crossings3D, Grid3D, Passages3D, Paths3D, Stops3D
from .scenario3d import TerrainScenario, _lipschitz, fall_line, sample_sources, source_point_index
from ._display import Displayed
from .units import J_PER_KJ, kinetic_energy_kj

DEFAULT_CHUNK_3D = 20_000


def _kernel_inputs(scenario: TerrainScenario):
    """The terrain, material table, rolling drag and collectors of ``scenario`` as the 3-D kernel takes them."""
    ter = scenario.terrain
    rough = np.zeros((0, 0)) if scenario.roughness_grid is None else scenario.roughness_grid
    grid = Grid3D(ter.z, float(ter.x0), float(ter.y0), float(ter.dx), float(ter.dy),
                  float(_lipschitz(ter.z, ter.dx, ter.dy)), scenario.material_grid.index, rough)
    mats, m_drag = material_table(scenario)
    return grid, mats, m_drag, _collector_segments(scenario)


def seed_blocks_3d(scenario: TerrainScenario, n: int, seed, masses_kg=None) -> dict:
    """Initial state of n blocks: plan position and elevation [m], velocity [m/s] (``speed_ms`` horizontally
    along the local fall line, ``vz_ms`` vertically, or each release point's ``velocity_ms``), spin [rad/s], mass
    [kg] (or each point's), radius [m] (or each point's ``radius_m``), I / (m r^2), and the block's lateral
    deviation factor s_b [-] (``sources.deviation_factor``, drawn from a seventh stream of the seed, so the other
    quantities are those drawn without it).

    Parameters
    ----------
    scenario : TerrainScenario
        The 3-D scenario (sources, DEM, blocks).
    n : int
        Number of blocks.
    seed : int or None
        Random seed.
    masses_kg : array_like, optional
        The mass of each block [kg] (the sources' mass distribution is then ignored).

    Returns
    -------
    dict of numpy.ndarray
        Per block: ``x``, ``y``, ``z`` [m], ``vx``, ``vy``, ``vz`` [m/s], spin [rad/s], mass [kg], radius [m],
        inertia factor [-] and deviation factor [-].
    """
    sd = scenario.sources
    ss = np.random.SeedSequence(seed)
    g_xy, g_h, g_m, g_v, g_vz, g_w, g_dev = (np.random.default_rng(c) for c in ss.spawn(7))
    per_point = any(v is not None for v in (sd.point_velocity, sd.point_mass, sd.point_radius))
    if per_point:                          # the same draw as sample_sources makes for points
        idx = source_point_index(sd, g_xy, n)
        xy = sd.points[idx]
    else:
        xy = sample_sources(sd, scenario.terrain, g_xy, n)
    x, y = xy[:, 0].copy(), xy[:, 1].copy()
    h = sd.height_m.sample(g_h, n)
    if masses_kg is not None:
        mass = check_masses(masses_kg, n).copy()
    elif sd.point_mass is not None:
        mass = sd.point_mass[idx]
    else:
        mass = sd.mass_kg.sample(g_m, n)
    if sd.point_velocity is not None:
        vx, vy, vz = sd.point_velocity[idx].T.copy()
    else:
        speed = sd.speed_ms.sample(g_v, n)
        ux, uy = fall_line(scenario.terrain, x, y)
        vx, vy, vz = speed * ux, speed * uy, sd.vz_ms.sample(g_vz, n)
    # a per-point radius belongs to the point's own mass: masses given here take the radius from mass and density
    radius = sd.point_radius[idx] if sd.point_radius is not None and masses_kg is None else sd.radius(mass)
    return {"x": x, "y": y, "z": scenario.terrain.elevation(x, y) + h, "vx": vx, "vy": vy, "vz": vz,
            "w": sd.angular_velocity_rads.sample(g_w, n), "mass": mass, "radius": radius,
            "inertia_factor": np.full(n, sd.inertia_factor),
            "deviation_factor": np.asarray(sd.deviation_factor.sample(g_dev, n), dtype=float),
            "resistance_deviate": resistance_deviates(scenario, ss, n)}


def _collector_segments(scenario: TerrainScenario):
    """The plan segments of every collector for the kernel; a barrier's segments carry its net height [m] and
    capacity [kJ] (NaN height: a plain collector; infinite capacity: a net that holds every block below its top)."""
    ax, ay, bx, by, cid, s0, cap, net = [], [], [], [], [], [], [], []
    for j, c in enumerate(scenario.collectors):
        cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(c.line, axis=0).T))])
        for k in range(len(c.line) - 1):
            ax.append(c.line[k, 0]), ay.append(c.line[k, 1]), bx.append(c.line[k + 1, 0]), by.append(c.line[k + 1, 1])
            cid.append(j), s0.append(cum[k])
            net.append(np.nan if c.height_m is None else c.height_m)
            cap.append(np.inf if c.capacity_kj is None else c.capacity_kj)
    f = lambda v: np.asarray(v, dtype=float)  # noqa: E731
    return Collectors3D(ax=f(ax), ay=f(ay), bx=f(bx), by=f(by), id=np.asarray(cid, dtype=np.int64), s0=f(s0),
                        cap=f(cap), net=f(net))


_CROSS = (("block", np.int64), ("coll", np.int64), ("s", float), ("t", float), ("x", float), ("y", float),
          ("vx", float), ("vy", float), ("vz", float), ("w", float), ("h", float), ("out", np.int64))
_PASS = (("block", np.int32), ("cell", np.int32), ("e", np.float32), ("h", np.float32))   # 16 bytes a passage
_PATH = (("block", np.int64), ("t", float), ("x", float), ("y", float), ("z", float), ("v", float),
         ("mode", np.int64))


def _run_chunk(lo, hi, blocks, inputs, st, key, n_paths, hazard, path_cap, hint=None, ids=None):
    """Run blocks lo..hi-1 (or, with ``ids``, the blocks of those indices: ``blocks`` then holds only theirs) on the
    kernel ``inputs`` of :func:`_kernel_inputs`."""
    grid, mats, m_drag, cols = inputs
    if ids is None:
        ids = np.arange(lo, hi, dtype=np.int64)
        sub = {k: v[lo:hi] for k, v in blocks.items()}
    else:
        ids = np.asarray(ids, dtype=np.int64)
        sub = blocks
    m = ids.size
    out = {k: np.empty(m, dtype=dt) for k, dt in (("x", float), ("y", float), ("z", float), ("reason", np.int64),
                                                   ("impacts", np.int64), ("t", float), ("excess", float),
                                                   ("events", np.int64))}
    cap_r = max(4 * m * max(len(cols.id), 1), 16)
    # pixel passages per block: a guess, then what the chunks run so far needed (a rerun when short)
    per_block = hint.get("passages", 300.0) if hint is not None else 300.0
    cap_p = max(int(per_block * m), 16) if hazard else 1
    pth_cap = path_cap if m > 0 and ids.min() < n_paths else 1
    while True:
        r = {k: np.empty(cap_r, dtype=dt) for k, dt in _CROSS}
        big = grid[0].size >= 2 ** 31          # pixel indices beyond int32: a DEM of more than 2.1e9 cells
        p = {k: np.empty(cap_p, dtype=np.int64 if (big and k == "cell") else dt) for k, dt in _PASS}
        pth = {k: np.empty(pth_cap, dtype=dt) for k, dt in _PATH}
        r_count, p_count, pcount = np.zeros(2, np.int64), np.zeros(2, np.int64), np.zeros(1, np.int64)
        kernel3d.simulate3d(
            Blocks3D(ids, *(sub[k] for k in ("x", "y", "z", "vx", "vy", "vz", "w", "mass", "radius", "inertia_factor",
                                             "resistance_deviate", "deviation_factor"))),
            grid, mats, m_drag, cols, kernel_settings(st, key, n_paths), st.sin_max_roll, hazard,
            Stops3D(*(out[k] for k in Stops3D._fields)),
            Crossings3D(*(r[k] for k, _ in _CROSS), r_count), Passages3D(*(p[k] for k, _ in _PASS), p_count),
            Paths3D(*(pth[k] for k, _ in _PATH), pcount))
        if r_count[1] == 0 and p_count[1] == 0:
            break
        # a buffer was too small: run the chunk again with the exact sizes (same numbers: keyed by block)
        cap_r = int(r_count.sum()) if r_count[1] else cap_r
        cap_p = int(p_count.sum()) if p_count[1] else cap_p
    k_r, k_p, k_t = int(r_count[0]), int(p_count[0]), int(pcount[0])
    if hazard and hint is not None and m > 0:
        hint["passages"] = max(hint.get("passages", 0.0), 1.25 * k_p / m)
    return (out, {k: v[:k_r].copy() for k, v in r.items()}, {k: v[:k_p].copy() for k, v in p.items()},
            {k: v[:k_t].copy() for k, v in pth.items()})


def run_terrain(scenario: TerrainScenario, n: int | None = None, seed=None, *, masses_kg=None,
                chunk_size: int = DEFAULT_CHUNK_3D, workers: int = 1, hazard: bool = False,
                record_paths: int = 20, passage_sink=None) -> "TerrainResult":
    """Simulate ``n`` blocks released from the scenario's sources on its DEM.

    Parameters
    ----------
    scenario : TerrainScenario
        From :func:`simulation.load_terrain_scenario`.
    n : int
        Number of blocks (10,000 when neither it nor ``masses_kg`` is given).
    seed : int, optional
        The same seed gives identical results for any ``chunk_size`` and ``workers``.
    masses_kg : array, optional
        The mass [kg] of each block (the sources' mass distribution is then ignored).
    chunk_size : int
        Blocks per kernel call.
    workers : int
        Threads running chunks (the kernel releases the GIL).
    hazard : bool
        Record every DEM pixel each block crosses (for :meth:`TerrainResult.hazard_grids`; about 16 bytes per
        pixel crossed).
    record_paths : int
        Keep the event sequence of the first ``record_paths`` blocks (plots, trajectory layers).
    passage_sink : callable, optional
        With ``hazard``: receives each chunk's pixel passages (a dict of arrays, whole blocks, in block order
        of the chunks) as soon as the chunk is run, and the result keeps none (``passages`` None); e.g.
        :meth:`simulation.hazard_grids.PassageAggregator.add`, so memory does not grow with the blocks.  At most
        ``workers`` chunks run while one is handed over.

    Returns
    -------
    TerrainResult
        Stops, collector crossings, recorded paths and (with ``hazard`` and no ``passage_sink``) the pixel
        passages of the run.
    """
    if masses_kg is not None:
        masses_kg = check_masses(masses_kg, None if n is None else n)
        n = masses_kg.size
    elif n is None:
        n = 10_000
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n <= 0:
        raise ValueError(f"n must be a positive whole number of blocks; got {n!r}")
    if chunk_size <= 0 or workers <= 0:
        raise ValueError(f"chunk_size and workers must be > 0; got {chunk_size!r}, {workers!r}")
    n = int(n)
    key = np.random.SeedSequence(seed).generate_state(1, dtype=np.uint64)[0]
    blocks = seed_blocks_3d(scenario, n, seed, masses_kg)
    inputs = _kernel_inputs(scenario)
    st = scenario.settings
    n_paths = min(int(record_paths), n)
    path_cap = max(n_paths * 4000, 16)
    # compile (or load from cache) untimed
    _run_chunk(0, 0, blocks, inputs, st, key, 0, hazard, 1)
    # with hazard pixels, a small first chunk measures how many pixels a block crosses (the buffer size of
    # the others); chunk boundaries do not change any result
    first = min(500, chunk_size, n) if hazard else min(chunk_size, n)
    chunks = [(0, first)] + [(lo, min(lo + chunk_size, n)) for lo in range(first, n, chunk_size)]
    started = time.perf_counter()
    hint = {}
    job = lambda c: _run_chunk(c[0], c[1], blocks, inputs, st, key, n_paths, hazard, path_cap, hint)  # noqa: E731
    sink = passage_sink if hazard else None

    def keep(part):
        if sink is None:
            return part
        sink(part[2])                          # the chunk's passages go to the sink, not into the result
        return part[0], part[1], None, part[3]
    if workers == 1 or len(chunks) == 1:
        parts = [keep(job(c)) for c in chunks]
    else:
        parts = [keep(job(chunks[0]))]
        with ThreadPoolExecutor(max_workers=workers) as pool:
            if sink is None:
                parts += list(pool.map(job, chunks[1:]))
            else:                              # a bounded window of chunks in flight, handed over in order
                pending, todo = [], iter(chunks[1:])
                for c in todo:
                    pending.append(pool.submit(job, c))
                    if len(pending) >= workers:
                        parts.append(keep(pending.pop(0).result()))
                parts += [keep(f.result()) for f in pending]
    elapsed = time.perf_counter() - started
    cat = lambda i: {k: np.concatenate([p[i][k] for p in parts]) for k in parts[0][i]}  # noqa: E731
    return TerrainResult(scenario=scenario, n=n, seed=seed, blocks=blocks, per_block=cat(0), crossings=cat(1),
                         passages=cat(2) if hazard and sink is None else None, paths=cat(3), elapsed_s=elapsed,
                         workers=workers)


# ---- tiles: the same run split by source, for a distributed engine ----------------------------------------------
@dataclass(frozen=True)
class TerrainRunPlan:
    """A run of ``n`` blocks prepared once (initial states, kernel inputs) and split into tiles of block indices
    grouped by where they start (:func:`plan_terrain_run`); each tile runs alone (:meth:`run_tile`, e.g. as a task
    of a dask.distributed cluster) and :meth:`merge` puts the tiles' outputs together in block order, so the result
    is the one :func:`run_terrain` gives, whatever the tiles and the order they finish in."""

    scenario: TerrainScenario
    n: int
    seed: object
    blocks: dict = field(repr=False)
    tiles: tuple = field(repr=False)
    key: int = 0
    hazard: bool = True
    record_paths: int = 20

    def tile_blocks(self, i: int) -> dict:
        """The initial states of tile ``i``'s blocks (what its task needs), with their indices under ``ids``.

        Parameters
        ----------
        i : int
            Index of the tile.

        Returns
        -------
        dict of numpy.ndarray
            Initial states of the tile's blocks (as :func:`seed_blocks_3d`) and their indices under ``ids``.
        """
        ids = self.tiles[i]
        return {"ids": ids, **{k: v[ids] for k, v in self.blocks.items()}}

    def run_tile(self, part: dict, chunk_size: int = DEFAULT_CHUNK_3D):
        """Run one tile (``part`` from :meth:`tile_blocks`); returns its outputs for :meth:`merge`.

        Parameters
        ----------
        part : dict
            A tile's blocks, from :meth:`tile_blocks`.
        chunk_size : int, optional
            Blocks per kernel call.

        Returns
        -------
        dict
            The tile's outputs (see :func:`run_tile`).
        """
        return run_tile(self.scenario, part, self.key, hazard=self.hazard, n_paths=min(self.record_paths, self.n),
                        chunk_size=chunk_size)

    def merge(self, outputs, elapsed_s: float = 0.0, workers: int = 1) -> "TerrainResult":
        """The :class:`TerrainResult` of the whole run from every tile's output (any order).

        Parameters
        ----------
        outputs : iterable of dict
            Every tile's output from :meth:`run_tile`, in any order.
        elapsed_s : float, optional
            Wall time of the run [s] (reported in the summary).
        workers : int, optional
            Number of workers that ran the tiles (reported in the summary).

        Returns
        -------
        TerrainResult
            The result of the whole run.
        """
        outputs = list(outputs)
        ids = np.concatenate([o["ids"] for o in outputs]) if outputs else np.empty(0, np.int64)
        if ids.size != self.n or np.unique(ids).size != self.n:
            raise ValueError(f"the tiles' outputs cover {np.unique(ids).size} of the {self.n} blocks; every tile must "
                             "be run once")
        per_block = {}
        for k in outputs[0]["per_block"]:
            vals = np.concatenate([o["per_block"][k] for o in outputs])
            arr = np.empty(self.n, dtype=vals.dtype)
            arr[ids] = vals
            per_block[k] = arr

        def in_block_order(name):
            cat = {k: np.concatenate([o[name][k] for o in outputs]) for k in outputs[0][name]}
            order = np.argsort(cat["block"], kind="stable")      # a block's rows stay in the kernel's order
            return {k: v[order] for k, v in cat.items()}
        return TerrainResult(scenario=self.scenario, n=self.n, seed=self.seed, blocks=self.blocks,
                             per_block=per_block, crossings=in_block_order("crossings"),
                             passages=in_block_order("passages") if self.hazard and "passages" in outputs[0]
                             else None,
                             paths=in_block_order("paths"), elapsed_s=elapsed_s, workers=workers)


def plan_terrain_run(scenario: TerrainScenario, n: int, seed=None, *, tile_m: float = 250.0, max_tile_blocks: int =
                     50_000, masses_kg=None, hazard: bool = True, record_paths: int = 20) -> TerrainRunPlan:
    """Seed ``n`` blocks as :func:`run_terrain` does and split them into tiles by source: squares of ``tile_m``
    metres of the release points (in plan, from the DEM's corner), each cut into pieces of at most
    ``max_tile_blocks`` blocks.  Tiles hold block indices in increasing order; their order is by square.

    Parameters
    ----------
    scenario : TerrainScenario
        The 3-D scenario.
    n : int
        Number of blocks.
    seed : int, optional
        Random seed.
    tile_m : float, optional
        Side of a tile's square in plan [m].
    max_tile_blocks : int, optional
        Largest number of blocks in one tile.
    masses_kg : array_like, optional
        The mass of each block [kg].
    hazard : bool, optional
        Record the DEM pixels each block crosses.
    record_paths : int, optional
        Keep the event sequence of the first ``record_paths`` blocks.

    Returns
    -------
    TerrainRunPlan
        The seeded blocks and their tiles.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n <= 0:
        raise ValueError(f"n must be a positive whole number of blocks; got {n!r}")
    if not (np.isfinite(tile_m) and tile_m > 0) or int(max_tile_blocks) < 1:
        raise ValueError(f"tile_m = {tile_m!r} must be > 0 m and max_tile_blocks = {max_tile_blocks!r} >= 1")
    n = int(n)
    blocks = seed_blocks_3d(scenario, n, seed, masses_kg)
    ter = scenario.terrain
    ti = np.floor((blocks["x"] - ter.x0) / tile_m).astype(np.int64)
    tj = np.floor((blocks["y"] - ter.y0) / tile_m).astype(np.int64)
    square = ti * (int(np.ceil(ter.shape[0] * ter.dy / tile_m)) + 1) + tj
    order = np.lexsort((np.arange(n), square))
    tiles = []
    for sq in np.unique(square):
        ids = order[square[order] == sq]
        for lo in range(0, ids.size, int(max_tile_blocks)):
            tiles.append(np.sort(ids[lo:lo + int(max_tile_blocks)]))
    key = int(np.random.SeedSequence(seed).generate_state(1, dtype=np.uint64)[0])
    return TerrainRunPlan(scenario=scenario, n=n, seed=seed, blocks=blocks, tiles=tuple(tiles), key=key,
                          hazard=hazard, record_paths=int(record_paths))


def run_tile(scenario: TerrainScenario, part: dict, key: int, *, hazard: bool = True, n_paths: int = 20,
             chunk_size: int = DEFAULT_CHUNK_3D) -> dict:
    """Run the blocks of one tile (``part``: their indices ``ids`` and initial states, from
    :meth:`TerrainRunPlan.tile_blocks`) with the run's ``key``; the kernel's outputs for the tile.

    Parameters
    ----------
    scenario : TerrainScenario
        The 3-D scenario.
    part : dict
        The tile's block indices ``ids`` and initial states.
    key : int
        The run's random key.
    hazard : bool, optional
        Record the DEM pixels each block crosses.
    n_paths : int, optional
        Keep the paths of the blocks with index below ``n_paths``.
    chunk_size : int, optional
        Blocks per kernel call.

    Returns
    -------
    dict of numpy.ndarray
        ``ids``, ``per_block``, ``crossings``, ``passages`` and ``paths`` of the tile.
    """
    inputs = _kernel_inputs(scenario)
    st = scenario.settings
    ids = np.asarray(part["ids"], dtype=np.int64)
    hint = {}
    outs = []
    for lo in range(0, ids.size, int(chunk_size)):
        sel = slice(lo, lo + int(chunk_size))
        sub = {k: np.ascontiguousarray(part[k][sel]) for k in part if k != "ids"}
        outs.append(_run_chunk(0, 0, sub, inputs, st, np.uint64(key), n_paths, hazard,
                               max(n_paths * 4000, 16), hint, ids=ids[sel]))
    cat = lambda i: {k: np.concatenate([o[i][k] for o in outs]) for k in outs[0][i]}  # noqa: E731
    return {"ids": ids, "per_block": cat(0), "crossings": cat(1), "passages": cat(2), "paths": cat(3)}


@njit(cache=True)
def _quantile_sorted(v, n, q):
    """The q-quantile of the first n values of the sorted array v (linear interpolation, numpy's default)."""
    pos = q * (n - 1)
    lo = int(math.floor(pos))
    hi = min(lo + 1, n - 1)
    return v[lo] + (v[hi] - v[lo]) * (pos - lo)


@njit(cache=True)
def aggregate_passages(cell, block, e, h, ncell, qs_e, q_h):
    """Per pixel: blocks that passed (a block re-entering a pixel counts once, with its largest energy and
    height), quantiles ``qs_e`` of their energies and ``q_h`` of their heights (NaN where none passed).

    A counting sort by pixel keeps the passages' block order, which is non-decreasing (chunks are
    concatenated in block order), so a block's visits to one pixel are adjacent and merge in one pass.

    Parameters
    ----------
    cell : numpy.ndarray of int
        Pixel index of each passage.
    block : numpy.ndarray of int
        Block index of each passage (non-decreasing).
    e : numpy.ndarray of float
        Kinetic energy of each passage [kJ].
    h : numpy.ndarray of float
        Height of the block centre above the ground at each passage [m].
    ncell : int
        Number of pixels of the grid.
    qs_e : numpy.ndarray of float
        Quantiles of the energy to compute [-].
    q_h : float
        Quantile of the height to compute [-].

    Returns
    -------
    count : numpy.ndarray
        Blocks that passed each pixel.
    eq : numpy.ndarray
        Energy quantiles per pixel [kJ], shape (len(qs_e), ncell).
    hq : numpy.ndarray
        Height quantile per pixel [m].
    """
    count_raw = np.zeros(ncell + 1, np.int64)
    for k in range(cell.shape[0]):
        count_raw[cell[k] + 1] += 1
    start = np.cumsum(count_raw)
    fill = start[:-1].copy()
    order = np.empty(cell.shape[0], np.int32)         # < 2^31 passages (34 GB of them) by far
    for k in range(cell.shape[0]):
        c = cell[k]
        order[fill[c]] = k
        fill[c] += 1
    count = np.zeros(ncell)
    eq = np.full((qs_e.shape[0], ncell), np.nan)
    hq = np.full(ncell, np.nan)
    longest = 0
    for c in range(ncell):
        longest = max(longest, start[c + 1] - start[c])
    te = np.empty(longest, np.float32)
    th = np.empty(longest, np.float32)
    for c in range(ncell):
        a, b = start[c], start[c + 1]
        if a == b:
            continue
        m = 0
        last = -1
        for idx in range(a, b):
            k = order[idx]
            if block[k] == last:
                te[m - 1] = max(te[m - 1], e[k])
                th[m - 1] = max(th[m - 1], h[k])
            else:
                te[m], th[m] = e[k], h[k]
                last = block[k]
                m += 1
        count[c] = m
        se = np.sort(te[:m])
        sh = np.sort(th[:m])
        for i in range(qs_e.shape[0]):
            eq[i, c] = _quantile_sorted(se, m, qs_e[i])
        hq[c] = _quantile_sorted(sh, m, q_h)
    return count, eq, hq


@dataclass(frozen=True)
class TerrainResult(Displayed):
    """Everything a 3-D run produced.  Units: m, m/s, rad/s, kg, kJ, s; plan coordinates in the DEM's CRS."""

    scenario: object
    n: int
    seed: object
    blocks: dict = field(repr=False)
    per_block: dict = field(repr=False)
    crossings: dict = field(repr=False)
    passages: dict | None = field(repr=False, default=None)
    paths: dict | None = field(repr=False, default=None)
    elapsed_s: float = 0.0
    workers: int = 1

    def stops(self) -> pd.DataFrame:
        """One row per block: release point, final point (x_m, y_m, z_m), reason, impacts, time, mass, and
        the horizontal runout from the release point [m].

        Returns
        -------
        pandas.DataFrame
            One row per block.
        """
        pb, b = self.per_block, self.blocks
        reasons = [kernel3d.STOP_REASONS[i] for i in sorted(kernel3d.STOP_REASONS)]
        return pd.DataFrame({
            "block": np.arange(self.n), "x0_m": b["x"], "y0_m": b["y"], "x_m": pb["x"], "y_m": pb["y"], "z_m": pb["z"],
            "runout_m": np.hypot(pb["x"] - b["x"], pb["y"] - b["y"]),
            "reason": pd.Categorical.from_codes(pb["reason"] - 1, reasons), "impacts": pb["impacts"],
            "time_s": pb["t"], "mass_kg": b["mass"]})

    def reach_probability(self, name: str) -> float:
        """Share of the released blocks that reached the line ``name`` (crossed it or met it, at a barrier).

        Parameters
        ----------
        name : str
            Name of a collector or barrier.

        Returns
        -------
        float
            Share of the released blocks that reached it [-].
        """
        j = self.scenario.collector_index(name)
        return np.unique(self.crossings["block"][self.crossings["coll"] == j]).size / self.n

    def barrier(self, name: str) -> pd.DataFrame:
        """Blocks meeting the barrier ``name`` (first meeting each): :meth:`collector` rows, with ``outcome``
        "caught", "through" or "over"; the summary of shares is :meth:`barrier_summary`.

        Parameters
        ----------
        name : str
            Name of a barrier.

        Returns
        -------
        pandas.DataFrame
            One row per block meeting the barrier, with ``outcome``.
        """
        c = self.scenario.collectors[self.scenario.collector_index(name)]
        if c.height_m is None:
            raise KeyError(f"{self.scenario.source}: collector {name!r} is not a barrier (it has no height_m)")
        return self.collector(name, first_only=True)

    def barrier_summary(self, name: str) -> pd.DataFrame:
        """Per outcome at barrier ``name``: blocks, share of the blocks meeting it, share of the blocks
        released, and the largest energy [kJ] and centre height [m] among them.

        Parameters
        ----------
        name : str
            Name of a barrier.

        Returns
        -------
        pandas.DataFrame
            One row per outcome, indexed by ``outcome``.
        """
        df = self.barrier(name)
        rows = []
        for o in ("caught", "through", "over"):
            s = df[df["outcome"] == o]
            rows.append({"outcome": o, "blocks": len(s), "share_of_arrivals": len(s) / max(len(df), 1),
                         "share_of_released": len(s) / self.n,
                         "max_energy_kj": float(s["energy_kj"].max()) if len(s) else float("nan"),
                         "max_height_m": float(s["height_m"].max()) if len(s) else float("nan")})
        return pd.DataFrame(rows).set_index("outcome")

    def energy_excess_j(self) -> np.ndarray:
        """Per block, the largest rise [J] of its total energy (kinetic + m g z) from one impact or contact step
        to the next (the energy audit: 0 or rounding-small unless a material allows energy gain).

        Returns
        -------
        numpy.ndarray
            Largest energy rise per block [J].
        """
        return self.per_block["excess"]

    def collector(self, name: str, *, first_only: bool = False) -> pd.DataFrame:
        """One row per crossing of the plan collector ``name``: ``block``, ``position_m`` (distance along the
        line), ``x_m``, ``y_m``, ``time_s``, ``velocity_ms``, ``vx_ms``, ``vy_ms``, ``vz_ms``,
        ``angular_velocity_rads``, ``height_m`` (centre above the ground), ``mass_kg``, ``radius_m``,
        ``inertia_factor``, ``energy_kj`` and ``outcome`` ("crossed" at a plain collector; at a barrier
        "caught", "through" or "over", :func:`simulation.kernel.barrier_outcome`).

        Parameters
        ----------
        name : str
            Name of a collector or barrier.
        first_only : bool, optional
            Keep only each block's first crossing.

        Returns
        -------
        pandas.DataFrame
            One row per crossing, columns as above.
        """
        j = self.scenario.collector_index(name)
        c = self.crossings
        sel = c["coll"] == j
        blk = c["block"][sel]
        v = np.sqrt(c["vx"][sel] ** 2 + c["vy"][sel] ** 2 + c["vz"][sel] ** 2)
        mass, radius, k = self.blocks["mass"][blk], self.blocks["radius"][blk], self.blocks["inertia_factor"][blk]
        df = pd.DataFrame({"block": blk, "position_m": c["s"][sel], "x_m": c["x"][sel], "y_m": c["y"][sel],
                           "time_s": c["t"][sel], "velocity_ms": v, "vx_ms": c["vx"][sel], "vy_ms": c["vy"][sel],
                           "vz_ms": c["vz"][sel], "angular_velocity_rads": c["w"][sel], "height_m": c["h"][sel],
                           "mass_kg": mass, "radius_m": radius, "inertia_factor": k,
                           "energy_kj": kinetic_energy_kj(mass, v, c["w"][sel], radius, k),
                           "outcome": pd.Categorical.from_codes(c["out"][sel], list(OUTCOMES.values()))})
        df = df.sort_values(["block", "time_s"])
        if first_only:
            df = df.drop_duplicates("block", keep="first")
        return df.reset_index(drop=True)

    def summary(self) -> pd.DataFrame:
        """Runout quantiles, stop reasons, impacts, energy audit and speed of the run, one row per quantity.

        Returns
        -------
        pandas.DataFrame
            Columns ``quantity``, ``value`` and ``unit``.
        """
        st = self.stops()
        rows = [("blocks", self.n, ""), ("seconds", self.elapsed_s, "s"),
                ("trajectories per second", self.n / max(self.elapsed_s, 1e-12), "1/s")]
        for q in (0.5, 0.95, 0.99):
            rows.append((f"runout p{int(q * 100)}", float(np.quantile(st["runout_m"], q)), "m"))
        for reason, cnt in st["reason"].value_counts(sort=False).items():
            rows.append((f"blocks {reason}", int(cnt), ""))
        rows.append(("mean impacts per block", float(st["impacts"].mean()), ""))
        rows.append(("mean events per block (impacts and contact steps)", float(self.per_block["events"].mean()), ""))
        rows.append(("largest energy rise between events", float(np.max(self.energy_excess_j())) / J_PER_KJ, "kJ"))
        for c in self.scenario.collectors:
            first = self.collector(c.name, first_only=True)
            rows.append((f"reach {c.name}", first.shape[0] / self.n, ""))
            if c.is_barrier:
                for o in ("caught", "through", "over"):
                    rows.append((f"{o} at barrier {c.name} (share of released)",
                                 float((first["outcome"] == o).sum()) / self.n, ""))
        return pd.DataFrame(rows, columns=["quantity", "value", "unit"])

    def __repr__(self) -> str:
        return (f"TerrainResult({self.scenario.name!r}, n={self.n}, seed={self.seed}, "
                f"{self.elapsed_s:.2f} s, {len(self.scenario.collectors)} collectors)")

    # ---- hazard rasters ----------------------------------------------------------------------------
    def hazard_grids(self) -> dict:
        """Hazard rasters on the DEM's grid (internal order; NaN on the DEM's nodata holes, and in the
        percentile layers where no block passed), from the pixels each block crossed (run with ``hazard=True``
        and no ``passage_sink``; a streamed run aggregates with :class:`simulation.hazard_grids.PassageAggregator`):

        ``passage_count`` blocks that passed through the pixel (each counted once); ``reach_probability`` that
        count / n; ``energy_p50_kj``, ``energy_p95_kj``, ``energy_p99_kj`` percentiles over those blocks of each
        block's largest kinetic energy in the pixel [kJ]; ``jump_height_p95_m`` the 95th percentile of each
        block's largest height of its centre above the ground there [m]; ``deposition_density`` blocks stopped
        in the pixel per released block per m^2 [1/m^2].

        Returns
        -------
        dict of numpy.ndarray
            The rasters named above, each of the DEM's shape.
        """
        if self.passages is None:
            raise ValueError("this run recorded no pixel passages: run_terrain(..., hazard=True)")
        ter = self.scenario.terrain
        ny, nx = ter.shape
        ncell = ny * nx
        p = self.passages
        count, eq, hq = aggregate_passages(p["cell"], p["block"], p["e"], p["h"], ncell,
                                           np.array([0.5, 0.95, 0.99]), 0.95)
        out = {"passage_count": count.reshape(ny, nx), "reach_probability": (count / self.n).reshape(ny, nx)}
        for name, row in (("energy_p50_kj", eq[0]), ("energy_p95_kj", eq[1]), ("energy_p99_kj", eq[2]),
                          ("jump_height_p95_m", hq)):
            out[name] = row.reshape(ny, nx)
        out["deposition_density"] = deposition_density(ter, self.per_block, self.n)
        return mask_holes(out, ter)

    def plot(self, ax=None, paths: bool = True):
        """Plan view: hillshade of the DEM, recorded paths, stop points and collectors (matplotlib axes).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).
        paths : bool, optional
            Draw the recorded paths.

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        import matplotlib.pyplot as plt
        ter = self.scenario.terrain
        if ax is None:
            _, ax = plt.subplots(figsize=(7, 6))
        x0, y0, x1, y1 = ter.bounds
        ext = (x0 - ter.dx / 2, x1 + ter.dx / 2, y0 - ter.dy / 2, y1 + ter.dy / 2)
        ax.imshow(ter.hillshade(), origin="lower", extent=ext, cmap="gray", vmin=0, vmax=1)
        if paths and self.paths is not None and len(self.paths["block"]):
            for b in np.unique(self.paths["block"]):
                s = self.paths["block"] == b
                ax.plot(self.paths["x"][s], self.paths["y"][s], lw=0.6, color="tab:blue", alpha=0.7)
        st = self.stops()
        ax.scatter(st["x_m"], st["y_m"], s=3, color="tab:red", label="simulated stops", zorder=3)
        for c in self.scenario.collectors:
            ax.plot(c.line[:, 0], c.line[:, 1], color="gold", lw=2, label=c.name)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal")
        ax.legend(loc="best", fontsize=8)
        return ax
