"""Hazard rasters of a 3-D run aggregated chunk by chunk, in memory that does not grow with the blocks.

:func:`simulation.engine3d.run_terrain` with ``hazard=True`` keeps every pixel passage of the run (16 bytes
per pixel a block crosses, about 12 kB a block on a 1 m DEM) and aggregates them at the end
(:func:`simulation.engine3d.aggregate_passages`).  :class:`PassageAggregator` takes the passages of one
chunk of blocks at a time (``run_terrain(..., passage_sink=agg.add)``), and after each chunk keeps only:

* per pixel, exact running statistics: blocks that passed (a block re-entering a pixel counts once, with its
  largest energy and height there), largest energy [kJ] and largest height [m];
* the chunk's passages, reduced to one record per block and pixel (10 bytes: pixel index within its tile,
  energy, height as float32), appended to one scratch file per tile of 64 x 64 pixels on disk.

The chunk is then dropped.  :meth:`PassageAggregator.rasters` reads one tile file at a time and computes each
pixel's percentiles exactly (the values are the float32 values :func:`aggregate_passages` sorts; same
interpolation), so the rasters are *identical* to the unchunked ones for the same seed, whatever the chunk
size, the threads, or the order chunks arrive in.  Peak memory is the DEM-sized arrays (about 32 bytes a
pixel while running, and the rasters at the end), the chunks in flight and the largest tile's records, read
at once (10 bytes per block passing each of its 4,096 pixels: the only part that grows with the blocks, slowly);
the scratch files take 10 bytes per block and pixel crossed on disk (about 7 MB per 1,000 blocks on
a 1 km^2, 1 m DEM) and are removed when the rasters are made or the aggregator is closed.

Intensity-frequency layers: with the annual rate ``R`` [1/year] of releases the ``n`` simulated blocks stand
for, a block reaching a pixel with energy at least ``e`` occurs ``R / n`` times a year, so the energy reached or
exceeded with annual frequency ``f`` is the ``k``-th largest energy of the blocks that passed the pixel,
``k = ceil(f n / R)`` (:func:`energy_at_frequency_rank`); a pixel passed by fewer than ``k`` blocks is nodata
(its blocks are not frequent enough for that frequency).
"""
from __future__ import annotations

import math
import shutil
import tempfile
from pathlib import Path

import numpy as np
from numba import njit

from . import kernel3d
from .errors import RiskrfError

#: Side of a scratch tile [pixels]; a tile's pixel index fits an uint16.
TILE = 64
_REC = np.dtype([("c", "<u2"), ("e", "<f4"), ("h", "<f4")])       # 10 bytes a block and pixel
#: The percentiles of the energy and the height computed per pixel.
ENERGY_QUANTILES = (0.5, 0.95, 0.99)
HEIGHT_QUANTILE = 0.95


class HazardGridError(RiskrfError, ValueError):
    """Bad input to the hazard-raster aggregation (a rate, a frequency, passages of a block seen twice)."""


def frequency_rank(frequency_per_year: float, n: int, rate_per_year: float) -> int:
    """The rank ``k = ceil(f n / R)`` (from the largest) of the energy reached with annual frequency ``f``.

    Each of the ``n`` simulated blocks stands for ``R / n`` releases a year, so ``k`` blocks reaching a pixel
    with energy at least ``e`` give an annual frequency ``k R / n`` of energies >= ``e`` there; the smallest
    ``k`` with ``k R / n >= f`` is this rank.  A relative tolerance of 1e-12 keeps an exact integer ``f n / R``
    from rounding up.

    Parameters
    ----------
    frequency_per_year : float
        Annual frequency ``f`` [1/year], > 0.
    n : int
        Blocks simulated.
    rate_per_year : float
        Annual rate ``R`` of releases the ``n`` blocks stand for [1/year], > 0.

    Returns
    -------
    int
        The rank ``k`` >= 1.
    """
    x = float(frequency_per_year) * int(n) / float(rate_per_year)
    return max(1, int(math.ceil(x * (1.0 - 1e-12))))


def check_rate(rate_per_year, name: str = "rate_per_year") -> float:
    """``rate_per_year`` as a float, or a :class:`HazardGridError` naming ``name`` and the value.

    Parameters
    ----------
    rate_per_year : float
        Annual rate of releases [1/year].
    name : str, optional
        Where the value comes from (argument, file and field), for the message.

    Returns
    -------
    float
        The rate [1/year].
    """
    try:
        r = float(rate_per_year)
    except (TypeError, ValueError):
        raise HazardGridError(f"{name} must be an annual rate of releases > 0 [1/year]; got {rate_per_year!r}")
    if not (math.isfinite(r) and r > 0):
        raise HazardGridError(f"{name} must be an annual rate of releases > 0 [1/year]; got {rate_per_year!r}")
    return r


@njit(cache=True)
def _reduce_chunk(block, cell, e, h, mark, pos, count, e_max, h_max, nx, tnx, tile_size, n_tiles, rec_c, rec_e,
                  rec_h):
    """One record per (block, pixel) of some blocks' passages (largest energy and height), grouped by tile into
    ``rec_c`` (pixel within its tile), ``rec_e``, ``rec_h``; updates the running count and maxima per pixel.
    ``mark[c]`` holds the last block seen at pixel c (a block is never seen in two calls), ``pos[c]`` its
    record.  Returns the records per tile (their slices follow each other in tile order) and their number."""
    m = cell.shape[0]
    oc = np.empty(m, np.int64)
    oe = np.empty(m, np.float32)
    oh = np.empty(m, np.float32)
    k = 0
    for i in range(m):
        c = cell[i]
        if mark[c] == block[i]:
            j = pos[c]
            if e[i] > oe[j]:
                oe[j] = e[i]
            if h[i] > oh[j]:
                oh[j] = h[i]
        else:
            mark[c] = block[i]
            pos[c] = k
            oc[k] = c
            oe[k] = e[i]
            oh[k] = h[i]
            k += 1
    per_tile = np.zeros(n_tiles, np.int64)
    for j in range(k):
        c = oc[j]
        count[c] += 1
        if oe[j] > e_max[c]:
            e_max[c] = oe[j]
        if oh[j] > h_max[c]:
            h_max[c] = oh[j]
        r, q = c // nx, c % nx
        per_tile[(r // tile_size) * tnx + q // tile_size] += 1
    fill = np.zeros(n_tiles, np.int64)
    for t in range(1, n_tiles):
        fill[t] = fill[t - 1] + per_tile[t - 1]
    for j in range(k):
        c = oc[j]
        r, q = c // nx, c % nx
        t = (r // tile_size) * tnx + q // tile_size
        f = fill[t]
        rec_c[f] = (r % tile_size) * tile_size + q % tile_size
        rec_e[f] = oe[j]
        rec_h[f] = oh[j]
        fill[t] = f + 1
    return per_tile, k


@njit(cache=True)
def _quantile_sorted(v, n, q):
    """The q-quantile of the first n values of the sorted array v (linear interpolation, numpy's default)."""
    pos = q * (n - 1)
    lo = int(math.floor(pos))
    hi = min(lo + 1, n - 1)
    return v[lo] + (v[hi] - v[lo]) * (pos - lo)


@njit(cache=True)
def tile_statistics(local, e, h, ncell, qs_e, q_h, ranks):
    """Per pixel of one tile, from its records (one per block and pixel): quantiles ``qs_e`` of the energies,
    ``q_h`` of the heights and the ``ranks``-th largest energies (NaN where fewer blocks passed).

    Parameters
    ----------
    local : numpy.ndarray of int
        Pixel index within the tile of each record.
    e, h : numpy.ndarray of float32
        Largest energy [kJ] and height [m] of the record's block in the pixel.
    ncell : int
        Pixels of the tile.
    qs_e : numpy.ndarray of float
        Energy quantiles [-].
    q_h : float
        Height quantile [-].
    ranks : numpy.ndarray of int
        Ranks from the largest (1 = the largest) of the energies to return.

    Returns
    -------
    eq : numpy.ndarray
        Energy quantiles [kJ], shape (len(qs_e), ncell).
    hq : numpy.ndarray
        Height quantile [m], shape (ncell,).
    er : numpy.ndarray
        Energies of the ranks [kJ], shape (len(ranks), ncell).
    """
    count = np.zeros(ncell + 1, np.int64)
    for k in range(local.shape[0]):
        count[local[k] + 1] += 1
    start = np.cumsum(count)
    fill = start[:-1].copy()
    te = np.empty(local.shape[0], np.float32)
    th = np.empty(local.shape[0], np.float32)
    for k in range(local.shape[0]):
        c = local[k]
        te[fill[c]] = e[k]
        th[fill[c]] = h[k]
        fill[c] += 1
    eq = np.full((qs_e.shape[0], ncell), np.nan)
    hq = np.full(ncell, np.nan)
    er = np.full((ranks.shape[0], ncell), np.nan)
    for c in range(ncell):
        a, b = start[c], start[c + 1]
        m = b - a
        if m == 0:
            continue
        se = np.sort(te[a:b])
        sh = np.sort(th[a:b])
        for i in range(qs_e.shape[0]):
            eq[i, c] = _quantile_sorted(se, m, qs_e[i])
        hq[c] = _quantile_sorted(sh, m, q_h)
        for i in range(ranks.shape[0]):
            if ranks[i] <= m:
                er[i, c] = se[m - ranks[i]]
    return eq, hq, er


class PassageAggregator:
    """Per-pixel hazard statistics of a 3-D run fed one chunk of blocks at a time (see the module docstring).

    Parameters
    ----------
    shape : tuple of int
        The DEM's (ny, nx) in the terrain's internal order.
    scratch_dir : str or pathlib.Path, optional
        Where the scratch directory is made (default: the system's temporary directory, ``TMPDIR``).

    Notes
    -----
    Use as a context manager, or call :meth:`close`, to remove the scratch files if the run fails.
    """

    def __init__(self, shape, scratch_dir=None):
        self.ny, self.nx = (int(s) for s in shape)
        ncell = self.ny * self.nx
        self.count = np.zeros(ncell, np.int64)
        self.e_max = np.full(ncell, -np.inf, np.float32)
        self.h_max = np.full(ncell, -np.inf, np.float32)
        self._mark = np.full(ncell, -1, np.int64)       # the last block seen at each pixel
        self._pos = np.zeros(ncell, np.int64)
        self.tny, self.tnx = -(-self.ny // TILE), -(-self.nx // TILE)
        self._records = np.zeros(self.tny * self.tnx, np.int64)
        self._dir = Path(tempfile.mkdtemp(prefix="riskrf-hazard-", dir=scratch_dir))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Remove the scratch files (idempotent)."""
        if self._dir is not None:
            shutil.rmtree(self._dir, ignore_errors=True)
            self._dir = None

    @property
    def scratch_bytes(self) -> int:
        """Bytes written to the scratch files so far."""
        return int(self._records.sum()) * _REC.itemsize

    @property
    def largest_tile_bytes(self) -> int:
        """Bytes of the largest tile's scratch file (what :meth:`rasters` reads at once)."""
        return int(self._records.max(initial=0)) * _REC.itemsize

    def add(self, passages: dict) -> None:
        """Take the pixel passages of some blocks (every passage of each: ``block``, ``cell``, ``e`` [kJ],
        ``h`` [m], as the kernel records them); they may be dropped afterwards.

        Parameters
        ----------
        passages : dict of numpy.ndarray
            The passages of whole blocks, each block in one call only, its passages contiguous.
        """
        if self._dir is None:
            raise HazardGridError("this PassageAggregator is closed")
        cell = np.asarray(passages["cell"])
        if cell.size == 0:
            return
        block = np.asarray(passages["block"])
        rec = np.empty(cell.size, _REC)          # at most one record per passage
        per_tile, k = _reduce_chunk(block, cell, np.asarray(passages["e"], np.float32),
                                    np.asarray(passages["h"], np.float32), self._mark, self._pos, self.count,
                                    self.e_max, self.h_max, self.nx, self.tnx, TILE, self._records.size,
                                    rec["c"], rec["e"], rec["h"])
        a = 0
        for t in np.flatnonzero(per_tile):
            b = a + int(per_tile[t])
            with open(self._dir / f"{t}.bin", "ab") as f:
                rec[a:b].tofile(f)
            a = b
        self._records += per_tile

    def rasters(self, n: int, *, rate_per_year: float | None = None, frequencies=()) -> dict:
        """Per-pixel statistics (internal order, (ny, nx) float arrays; NaN where no block passed) and the scratch
        files removed.

        Parameters
        ----------
        n : int
            Blocks released in the run.
        rate_per_year : float, optional
            Annual rate of releases the ``n`` blocks stand for [1/year] (needed for ``frequencies``).
        frequencies : sequence of float, optional
            Annual frequencies [1/year] of the energies to return (``energy_at_frequency``).

        Returns
        -------
        dict of numpy.ndarray
            ``count`` blocks that passed (0 where none); ``energy_q`` energy quantiles [kJ] of
            :data:`ENERGY_QUANTILES` (3, ny, nx); ``height_q`` height quantile [m] of :data:`HEIGHT_QUANTILE`;
            ``energy_max`` [kJ], ``height_max`` [m]; ``energy_at_frequency`` (len(frequencies), ny, nx) [kJ].
        """
        if self._dir is None:
            raise HazardGridError("this PassageAggregator is closed")
        frequencies = tuple(float(f) for f in frequencies)
        if frequencies:
            if rate_per_year is None:
                raise HazardGridError("energies at annual frequencies need the annual rate of releases "
                                      "(rate_per_year)")
            rate_per_year = check_rate(rate_per_year)
            for f in frequencies:
                if not (math.isfinite(f) and f > 0):
                    raise HazardGridError(f"annual frequency {f!r} must be > 0 [1/year]")
        ranks = np.array([frequency_rank(f, n, rate_per_year) for f in frequencies], dtype=np.int64)
        ny, nx = self.ny, self.nx
        eq = np.full((len(ENERGY_QUANTILES), ny, nx), np.nan)
        hq = np.full((ny, nx), np.nan)
        er = np.full((len(frequencies), ny, nx), np.nan)
        qs = np.array(ENERGY_QUANTILES)
        try:
            for t in np.flatnonzero(self._records):
                rec = np.fromfile(self._dir / f"{t}.bin", dtype=_REC)
                r0, c0 = (t // self.tnx) * TILE, (t % self.tnx) * TILE
                r1, c1 = min(r0 + TILE, ny), min(c0 + TILE, nx)
                teq, thq, ter = tile_statistics(rec["c"], rec["e"], rec["h"], TILE * TILE, qs,
                                                HEIGHT_QUANTILE, ranks)
                del rec
                h, w = r1 - r0, c1 - c0
                eq[:, r0:r1, c0:c1] = teq.reshape(-1, TILE, TILE)[:, :h, :w]
                hq[r0:r1, c0:c1] = thq.reshape(TILE, TILE)[:h, :w]
                er[:, r0:r1, c0:c1] = ter.reshape(-1, TILE, TILE)[:, :h, :w]
        finally:
            self.close()
        reached = self.count > 0
        return {"count": self.count.reshape(ny, nx).astype(float), "energy_q": eq, "height_q": hq,
                "energy_max": np.where(reached, self.e_max, np.nan).astype(float).reshape(ny, nx),
                "height_max": np.where(reached, self.h_max, np.nan).astype(float).reshape(ny, nx),
                "energy_at_frequency": er}


def deposition_density(terrain, per_block: dict, n: int) -> np.ndarray:
    """Blocks stopped in each pixel per released block per m^2 [1/m^2] (internal order).

    Parameters
    ----------
    terrain : Terrain
        The DEM.
    per_block : dict of numpy.ndarray
        The run's per-block outputs (``x``, ``y`` [m], ``reason``).
    n : int
        Blocks released.

    Returns
    -------
    numpy.ndarray
        (ny, nx) density [1/m^2]: sum * cell area = share of the blocks that stopped on the DEM.
    """
    ny, nx = terrain.shape
    stopped = per_block["reason"] == kernel3d.STOPPED
    j = np.clip(np.floor((per_block["x"][stopped] - terrain.x0) / terrain.dx + 0.5).astype(np.int64), 0, nx - 1)
    i = np.clip(np.floor((per_block["y"][stopped] - terrain.y0) / terrain.dy + 0.5).astype(np.int64), 0, ny - 1)
    dep = np.bincount(i * nx + j, minlength=ny * nx).astype(float) / (n * terrain.dx * terrain.dy)
    return dep.reshape(ny, nx)


def mask_holes(grids: dict, terrain) -> dict:
    """The rasters with NaN (nodata) on the DEM's nodata holes (where a 0 would claim "no block passed").

    Parameters
    ----------
    grids : dict of numpy.ndarray
        (ny, nx) rasters in internal order.
    terrain : Terrain
        The DEM (holes are NaN in ``terrain.z``).

    Returns
    -------
    dict of numpy.ndarray
        The same rasters, float, NaN on the holes.
    """
    hole = np.isnan(terrain.z)
    if not hole.any():
        return grids
    return {k: np.where(hole, np.nan, np.asarray(v, dtype=float)) for k, v in grids.items()}
