"""Rock fall hazard maps on 3-D terrain: a ``[terrain]`` scenario run with the 3-D kernel, written as GIS layers.

``hazard_map(scenario, n, seed)`` runs :func:`simulation.run_terrain` recording every DEM pixel each block
crosses and returns a :class:`HazardMap`; :meth:`HazardMap.write` writes, all or nothing:

* GeoTIFFs on the DEM's grid and CRS (float32, nodata NaN on the DEM's nodata holes and, in the energy and
  height layers, where no block passed; each band carries its quantity as description and its unit, also as
  band tags ``quantity`` and ``unit``): ``passage_count.tif`` (blocks through the pixel), ``reach_probability.tif``
  (that / n released), ``energy_p50_kj.tif``, ``energy_p95_kj.tif``, ``energy_p99_kj.tif`` (percentiles over the
  blocks that passed of each block's largest kinetic energy in the pixel, translational + rotational [kJ]),
  ``energy_max_kj.tif`` (the largest), ``jump_height_p95_m.tif`` (95th percentile of the block centre's largest
  height above the ground [m]), ``deposition_density.tif`` (blocks stopped in the pixel per released block per
  m^2);
* with the annual rate of releases ``rate_per_year`` (``--rate-per-year``; a scenario does not carry one), the
  intensity-frequency layers ``energy_1in30_kj.tif``, ``energy_1in100_kj.tif``, ``energy_1in300_kj.tif``: per
  pixel, the kinetic energy [kJ] reached or exceeded with annual frequency 1/30, 1/100 and 1/300 (the
  probability classes of Swiss hazard-map practice), the ``ceil(f n / R)``-th largest energy of the blocks
  that passed; nodata where too few blocks pass for that frequency;
* ``hazard_map.gpkg`` (GeoPackage, written with pyogrio) with layers ``stop_points`` (every block's final
  point, reason, mass, runout) and ``trajectories`` (the recorded sample of paths as 3-D lines);
* ``hillshade.png``: the reach probability over a hillshade of the DEM with the stop points and paths;
* ``trajectory_model.txt``: whether the trajectory model is calibrated, in the sentence every output carries (the
  rasters' tag ``riskrf_trajectory_model`` holds its status; an uncalibrated model is stamped on the figure);
* ``summary.csv`` and ``crossings.csv`` (one row per crossing of each plan collector, with its outcome at a
  barrier); ``barriers.csv`` (per barrier: blocks caught, through and over, shares, largest energy and height).

The percentiles are those of the blocks that reached the pixel (conditional on reaching it); combine them
with ``reach_probability`` for unconditional figures.

Memory: the pixel passages are aggregated chunk by chunk (:class:`simulation.hazard_grids.PassageAggregator`):
each chunk's passages are reduced to one 10-byte record per block and pixel on scratch files on disk
(``scratch_dir``, default the system's temporary directory; 10 bytes per block and pixel crossed), then dropped;
the percentiles are computed exactly one 64 x 64-pixel tile at a time, so the rasters are identical to the
unchunked ones and peak memory does not grow with the number of blocks.

Large source sets: ``hazard_map(..., dask=True)`` (``riskrf hazard-map --dask``) splits the blocks into tiles by
source (squares of ``tile_m`` metres of release points, :func:`simulation.engine3d.plan_terrain_run`) and runs
each tile as a task on the same dask.distributed engine as the corridor (:func:`riskrf.app.corridor.connect`: a
scheduler address, or a LocalCluster).  Every block's initial state and random numbers depend only on the seed
and its index, and the tiles' outputs are merged in block order, so the rasters are identical to a one-machine
run and for any number of workers.  The client aggregates each tile's pixel passages as the tile
arrives (as above) and drops them.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

#: The raster layers always written, with units, in the order of the summary.
RASTERS = {"passage_count": "blocks", "reach_probability": "-", "energy_p50_kj": "kJ", "energy_p95_kj": "kJ",
           "energy_p99_kj": "kJ", "energy_max_kj": "kJ", "jump_height_p95_m": "m",
           "deposition_density": "1/m2 per block"}
#: The intensity-frequency layers (written with an annual rate of releases): name -> annual frequency [1/year].
FREQUENCY_RASTERS = {"energy_1in30_kj": 1 / 30, "energy_1in100_kj": 1 / 100, "energy_1in300_kj": 1 / 300}
#: The quantity of each layer (band description and tag ``quantity``).
DESCRIPTIONS = {
    "passage_count": "blocks passing the cell",
    "reach_probability": "reach probability per released block",
    "energy_p50_kj": "passing energy p50", "energy_p95_kj": "passing energy p95",
    "energy_p99_kj": "passing energy p99", "energy_max_kj": "passing energy max",
    "jump_height_p95_m": "jump height p95 (block centre above ground)",
    "deposition_density": "blocks stopped per released block per m2",
    "energy_1in30_kj": "passing energy reached or exceeded 1/30 per year",
    "energy_1in100_kj": "passing energy reached or exceeded 1/100 per year",
    "energy_1in300_kj": "passing energy reached or exceeded 1/300 per year",
}


@dataclass(frozen=True)
class HazardMap:
    """Hazard rasters of a 3-D run (``grids``: name -> (ny, nx) array in the terrain's internal order), the
    run itself (``result``, a :class:`simulation.TerrainResult`) and the annual rate of releases [1/year] the
    intensity-frequency layers were made with (None: no such layers)."""

    result: object = field(repr=False)
    grids: dict = field(repr=False)
    rate_per_year: float | None = None

    @property
    def scenario(self):
        """The :class:`simulation.TerrainScenario` that was run."""
        return self.result.scenario

    @property
    def trajectory_model(self):
        """Is the scenario's trajectory model calibrated?  (:class:`~riskrf.hazard.trajectory_status.
        TrajectoryModelStatus` of the scenario's materials: "uncalibrated" when they are presets.)"""
        from ..hazard.trajectory_status import trajectory_model_status
        sc = self.scenario
        if sc.source == "<dict>" or not Path(sc.source).is_file():
            return trajectory_model_status(None)
        from simulation.parameters import scenario_dict
        return trajectory_model_status(scenario_dict(sc.source)[0])

    def summary(self) -> pd.DataFrame:
        """One row per raster: unit, pixels reached, largest value, and the run's runout quantiles.

        Returns
        -------
        pandas.DataFrame
            Columns ``layer``, ``unit``, ``pixels_with_value`` and ``max``, one row per raster.
        """
        rows = []
        units = {**RASTERS, **dict.fromkeys(FREQUENCY_RASTERS, "kJ")}
        for name, unit in units.items():
            if name not in self.grids:
                continue
            g = self.grids[name]
            reached = np.isfinite(g) & (g > 0)
            rows.append({"layer": name, "unit": unit, "pixels_with_value": int(reached.sum()),
                         "max": float(np.nanmax(g)) if reached.any() else float("nan")})
        return pd.DataFrame(rows)

    def plot(self, ax=None):
        """Reach probability over the DEM's hillshade, with stop points and the recorded paths.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        import matplotlib.pyplot as plt
        from matplotlib.colors import LogNorm
        ter = self.scenario.terrain
        if ax is None:
            _, ax = plt.subplots(figsize=(8, 7))
        self.result.plot(ax=ax)
        x0, y0, x1, y1 = ter.bounds
        ext = (x0 - ter.dx / 2, x1 + ter.dx / 2, y0 - ter.dy / 2, y1 + ter.dy / 2)
        p = np.where(self.grids["reach_probability"] > 0, self.grids["reach_probability"], np.nan)
        if np.isfinite(p).any():
            im = ax.imshow(p, origin="lower", extent=ext, cmap="magma_r", alpha=0.6,
                           norm=LogNorm(vmin=max(np.nanmin(p), 1e-4), vmax=1.0))
            ax.figure.colorbar(im, ax=ax, label="reach probability (per released block)")
        ax.set_title(f"{self.scenario.name}: {self.result.n:,} blocks, seed {self.result.seed}")
        return ax

    def write(self, out, *, overwrite: bool = False) -> Path:
        """Write every layer to directory ``out`` (all or nothing; see the module docstring).

        Parameters
        ----------
        out : str or pathlib.Path
            Output directory.
        overwrite : bool, optional
            Replace an existing output directory.

        Returns
        -------
        pathlib.Path
            The output directory.
        """
        from ..io.outputs import atomic_output_dir
        out = Path(out)
        ter = self.scenario.terrain
        with atomic_output_dir(out, overwrite=overwrite) as tmp:
            units = {**RASTERS, **dict.fromkeys(FREQUENCY_RASTERS, "kJ")}
            status = self.trajectory_model
            tags = {"riskrf_scenario": self.scenario.name, "riskrf_blocks": self.result.n,
                    "riskrf_seed": self.result.seed, "riskrf_trajectory_model": status.status,
                    "riskrf_rate_per_year": "none" if self.rate_per_year is None else repr(self.rate_per_year)}
            for name, unit in units.items():
                if name in self.grids:
                    ter.write_geotiff(tmp / f"{name}.tif", self.grids[name], description=DESCRIPTIONS[name],
                                      unit=unit, tags=tags)
            write_geopackage(self.result, tmp / "hazard_map.gpkg")
            self.summary().to_csv(tmp / "summary.csv", index=False)
            (tmp / "trajectory_model.txt").write_text(status.text + "\n", encoding="utf-8")
            self.result.summary().to_csv(tmp / "run_summary.csv", index=False)
            tables = [self.result.collector(c.name).assign(collector=c.name) for c in self.scenario.collectors]
            if tables:
                pd.concat(tables, ignore_index=True).to_csv(tmp / "crossings.csv", index=False)
            barriers = [self.result.barrier_summary(c.name).assign(barrier=c.name, line=c.description())
                        for c in self.scenario.collectors if c.is_barrier]
            if barriers:
                pd.concat(barriers).reset_index().to_csv(tmp / "barriers.csv", index=False)
            from ..report.files import figure_note, save_figure
            with figure_note(status.figure_note):
                save_figure(self.plot().figure, tmp / "hillshade.png", dpi=130)
        return out


def _wkb_points(x, y, z) -> np.ndarray:
    """ISO WKB Point Z geometries (little endian, type 1001) of coordinate arrays."""
    return np.array([struct.pack("<BI3d", 1, 1001, a, b, c) for a, b, c in zip(x, y, z)], dtype=object)


def _wkb_linestring(x, y, z) -> bytes:
    """One ISO WKB LineString Z (type 1002)."""
    xyz = np.column_stack([x, y, z]).astype("<f8")
    return struct.pack("<BII", 1, 1002, len(xyz)) + xyz.tobytes()


def write_geopackage(result, path) -> Path:
    """Stop points (layer ``stop_points``) and the recorded trajectories (layer ``trajectories``) of a
    :class:`simulation.TerrainResult` as a GeoPackage in the DEM's CRS (pyogrio).

    Parameters
    ----------
    result : TerrainResult
        A 3-D run.
    path : str or pathlib.Path
        GeoPackage file to write.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    from pyogrio.raw import write
    path = Path(path)
    crs = result.scenario.terrain.crs
    crs_wkt = crs.to_wkt() if crs is not None else None
    st = result.stops()
    write(path, _wkb_points(st["x_m"], st["y_m"], st["z_m"]),
          [st["block"].to_numpy(), st["reason"].astype(str).to_numpy(dtype=object), st["mass_kg"].to_numpy(),
           st["runout_m"].to_numpy(), st["impacts"].to_numpy(), st["time_s"].to_numpy()],
          ["block", "reason", "mass_kg", "runout_m", "impacts", "time_s"], geometry_type="Point Z", crs=crs_wkt,
          driver="GPKG", layer="stop_points")
    pth = result.paths
    blocks = np.unique(pth["block"]) if pth is not None else np.empty(0, dtype=np.int64)
    geoms, ids = [], []
    for b in blocks:
        s = pth["block"] == b
        if s.sum() >= 2:
            geoms.append(_wkb_linestring(pth["x"][s], pth["y"][s], pth["z"][s]))
            ids.append(int(b))
    if geoms:
        write(path, np.array(geoms, dtype=object), [np.array(ids, dtype=np.int64)], ["block"],
              geometry_type="LineString Z", crs=crs_wkt, driver="GPKG", layer="trajectories", append=True)
    return path


def hazard_map(scenario, n: int = 10_000, seed=1, *, crs=None, workers: int = 1, record_paths: int = 50,
               masses_kg=None, chunk_size: int = 2_000, dask: bool = False, client=None, scheduler: str | None = None,
               tile_m: float = 250.0, max_tile_blocks: int = 50_000, rate_per_year: float | None = None,
               scratch_dir=None, log=None) -> HazardMap:
    """Run a 3-D scenario for hazard rasters, aggregating the pixel passages chunk by chunk.

    Parameters
    ----------
    scenario : str, Path or simulation.TerrainScenario
        A scenario TOML file with a ``[terrain]`` table, or a loaded scenario.
    n : int
        Blocks released (> 0).
    seed : int
        Random seed; results are identical for any ``workers`` and ``chunk_size``.
    crs : str, optional
        The DEM's CRS when its file has none (e.g. ``"EPSG:2154"``).
    workers : int
        Threads running the kernel.
    record_paths : int
        Trajectories kept for the ``trajectories`` layer and the figure.
    masses_kg : array, optional
        Block masses [kg] instead of the sources' distribution.
    chunk_size : int
        Blocks per kernel call (the unit of work of a thread and of the aggregation: about ``workers + 1``
        chunks' pixel passages are in memory at a time, 16 bytes per pixel crossed; results do not depend on it).
    dask : bool
        Run tiles by source on a dask.distributed cluster (see the module docstring): ``client`` (used as is),
        else ``scheduler`` (an address, or DASK_SCHEDULER_ADDRESS), else a LocalCluster of ``workers`` processes.
    tile_m, max_tile_blocks : float, int
        Tile size: squares of release points [m], at most this many blocks a tile.
    rate_per_year : float, optional
        Annual rate of releases from the scenario's sources [1/year] that the ``n`` blocks stand for (each block
        ``rate_per_year / n`` releases a year).  Given, the map has the intensity-frequency layers of
        :data:`FREQUENCY_RASTERS`; a scenario file does not carry a rate.
    scratch_dir : str or Path, optional
        Directory for the aggregation's scratch files (default: the system's temporary directory); they take
        10 bytes per block and pixel crossed and are removed at the end.
    log : callable, optional
        Receives progress lines (tiles done).

    Returns
    -------
    HazardMap
        The run and its hazard rasters (reach probability [-], energy percentiles [kJ], jump height [m],
        deposition density [1/m^2], and with a rate the energies at annual frequencies [kJ]).

    Raises
    ------
    simulation.hazard_grids.HazardGridError
        A rate that is not a finite number > 0 (named ``rate_per_year`` with its value), before any work.
    """
    import simulation
    from simulation.hazard_grids import PassageAggregator, check_rate
    if rate_per_year is not None:
        rate_per_year = check_rate(rate_per_year, "rate_per_year (--rate-per-year)")
    if isinstance(scenario, (str, Path)):
        scenario = simulation.load_terrain_scenario(scenario, crs=crs)
    with PassageAggregator(scenario.terrain.shape, scratch_dir=scratch_dir) as agg:
        if dask or client is not None or scheduler is not None:
            result = run_tiled(scenario, n, seed, client=client, scheduler=scheduler, n_workers=workers,
                               tile_m=tile_m, max_tile_blocks=max_tile_blocks, record_paths=record_paths,
                               masses_kg=masses_kg, chunk_size=chunk_size, log=log, passage_sink=agg.add)
        else:
            result = simulation.run_terrain(scenario, n, seed, workers=workers, hazard=True,
                                            record_paths=record_paths, masses_kg=masses_kg, chunk_size=chunk_size,
                                            passage_sink=agg.add)
        stats = agg.rasters(result.n, rate_per_year=rate_per_year,
                            frequencies=tuple(FREQUENCY_RASTERS.values()) if rate_per_year is not None else ())
    return HazardMap(result=result, grids=grids_from_statistics(stats, result, FREQUENCY_RASTERS
                                                                if rate_per_year is not None else {}),
                     rate_per_year=rate_per_year)


def grids_from_statistics(stats: dict, result, frequency_layers: dict) -> dict:
    """The named hazard rasters from :meth:`simulation.hazard_grids.PassageAggregator.rasters`, NaN on the
    DEM's holes.

    Parameters
    ----------
    stats : dict of numpy.ndarray
        The aggregator's per-pixel statistics.
    result : simulation.TerrainResult
        The run (blocks released, stop points).
    frequency_layers : dict
        Name -> annual frequency [1/year] of the layers in ``stats["energy_at_frequency"]``, in its order.

    Returns
    -------
    dict of numpy.ndarray
        The layers of :data:`RASTERS` (and ``frequency_layers``), (ny, nx) in internal order.
    """
    from simulation.hazard_grids import deposition_density, mask_holes
    ter = result.scenario.terrain
    eq = stats["energy_q"]
    grids = {"passage_count": stats["count"], "reach_probability": stats["count"] / result.n,
             "energy_p50_kj": eq[0], "energy_p95_kj": eq[1], "energy_p99_kj": eq[2],
             "energy_max_kj": stats["energy_max"], "jump_height_p95_m": stats["height_q"],
             "deposition_density": deposition_density(ter, result.per_block, result.n)}
    for k, name in enumerate(frequency_layers):
        grids[name] = stats["energy_at_frequency"][k]
    return mask_holes(grids, ter)


def _tile_task(scenario, part, key, n_paths, chunk_size):
    from simulation.engine3d import run_tile
    return run_tile(scenario, part, key, hazard=True, n_paths=n_paths, chunk_size=chunk_size)


def run_tiled(scenario, n: int, seed=1, *, client=None, scheduler: str | None = None, n_workers: int | None = None,
              tile_m: float = 250.0, max_tile_blocks: int = 50_000, record_paths: int = 50, masses_kg=None,
              chunk_size: int = 5_000, log=None, passage_sink=None):
    """A 3-D run recording hazard pixels, tiled by source on a dask.distributed client (see the module
    docstring); the :class:`simulation.TerrainResult` equals :func:`simulation.run_terrain`'s with
    ``hazard=True``.  ``client`` is used as is; else :func:`riskrf.app.corridor.connect` (``scheduler``, or a
    LocalCluster of ``n_workers``), closed at the end.

    Parameters
    ----------
    scenario : str, pathlib.Path or TerrainScenario
        The 3-D scenario.
    n : int
        Blocks released.
    seed : int, optional
        Random seed.
    client : distributed.Client, optional
        An existing dask client.
    scheduler : str, optional
        Address of a dask scheduler.
    n_workers : int, optional
        Workers of a new LocalCluster.
    tile_m : float, optional
        Side of a tile's square of release points [m].
    max_tile_blocks : int, optional
        Largest number of blocks in one tile.
    record_paths : int, optional
        Trajectories kept.
    masses_kg : array_like, optional
        Block masses [kg] instead of the sources' distribution.
    chunk_size : int, optional
        Blocks per kernel call.
    log : callable, optional
        Receives progress lines.
    passage_sink : callable, optional
        Receives each tile's pixel passages as the tile arrives (e.g.
        :meth:`simulation.hazard_grids.PassageAggregator.add`); the result then keeps none.

    Returns
    -------
    TerrainResult
        The run, with the pixel passages recorded (none with ``passage_sink``).
    """
    import time
    import uuid

    from distributed import as_completed

    from simulation.engine3d import plan_terrain_run
    from .corridor import _shutdown, connect
    plan = plan_terrain_run(scenario, n, seed, tile_m=tile_m, max_tile_blocks=max_tile_blocks, masses_kg=masses_kg,
                            hazard=True, record_paths=record_paths)
    own = client is None
    cluster = None
    if own:
        client, cluster = connect(scheduler, n_workers)
    t0 = time.perf_counter()
    try:
        sc_future = client.scatter(scenario, broadcast=True)
        run = uuid.uuid4().hex[:8]
        n_paths = min(plan.record_paths, plan.n)
        futures = [client.submit(_tile_task, sc_future, plan.tile_blocks(i), plan.key, n_paths, chunk_size,
                                 key=f"riskrf-tile-{i}-{run}", retries=1) for i in range(len(plan.tiles))]
        outputs, n_tiles = [], len(futures)
        pending = as_completed(futures)
        del futures                            # a tile's data are released once it is consumed
        for k, fut in enumerate(pending, start=1):
            out = fut.result()
            if passage_sink is not None:
                passage_sink(out.pop("passages"))
            outputs.append(out)
            del fut
            if log is not None:
                log(f"tile {k}/{n_tiles} done")
        workers = len(client.scheduler_info().get("workers", {}))
    finally:
        if own:
            _shutdown(client, cluster)
    return plan.merge(outputs, elapsed_s=time.perf_counter() - t0, workers=workers)
