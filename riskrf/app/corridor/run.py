"""Running a corridor: :func:`run_corridor`, every section as one task on a ``dask.distributed`` client.

Sections finish in any order; each finished row may be written at once as one Parquet partition (atomic, so
an interrupted run keeps its work and ``resume`` skips it); failed tasks are retried, then stop the run or,
with ``keep_going``, are listed.  Results do not depend on the number of workers (seeds per section id).
"""
from __future__ import annotations

import os
import time
import uuid
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from ..cluster import _shutdown, connect
from .model import Corridor, _section_key, _section_seed
from .result import CorridorResult
from .sections import assess_section


def _task(section, corridor, n_blocks):
    return assess_section(section, corridor, n_blocks)


def _write_partition(directory: Path, row: dict) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    name = f"section={_section_key(row['id']):08x}.parquet"
    tmp = directory / (name + ".partial")
    pd.DataFrame([row]).to_parquet(tmp, index=False)
    os.replace(tmp, directory / name)


def run_corridor(corridor: Corridor, *, client=None, scheduler: str | None = None, n_workers: int | None = None,
                 n_blocks: int | None = None, partitions: Path | None = None, resume: bool = False,
                 keep_going: bool = False, progress=None, retries: int = 1, log=None) -> CorridorResult:
    """Assess every section of ``corridor`` as a task on a ``dask.distributed`` client.

    ``client``: an existing Client (used as is); else :func:`connect` (``scheduler`` / DASK_SCHEDULER_ADDRESS, or
    a LocalCluster of ``n_workers``).  ``partitions``: a directory receiving one Parquet file per finished section
    (written atomically as sections finish, so memory stays flat and an interrupted run keeps its work);
    ``resume`` skips sections already there.  A task that fails (or whose worker dies) is retried ``retries``
    times; then the run stops, or with ``keep_going`` the failure is listed and the rest continue.
    ``progress(done, total, section_id)`` is called as each section finishes; ``log(text)`` once connected
    (the cluster's dashboard address).

    Parameters
    ----------
    corridor : Corridor
        From :func:`load_corridor`.
    client : distributed.Client, optional
        An existing client.
    scheduler : str, optional
        Address of a dask scheduler.
    n_workers : int, optional
        Workers of a new LocalCluster.
    n_blocks : int, optional
        Blocks simulated per run (default: the corridor's).
    partitions : pathlib.Path, optional
        Directory for one Parquet file per finished section.
    resume : bool, optional
        Skip the sections already in ``partitions``.
    keep_going : bool, optional
        List failed sections instead of stopping.
    progress : callable, optional
        ``progress(done, total, section_id)``.
    retries : int, optional
        Retries of a failed task.
    log : callable, optional
        ``log(text)``, called once connected.

    Returns
    -------
    CorridorResult
        One row per section, the failures and the run's figures.
    """
    from distributed import as_completed
    if n_blocks is not None and (isinstance(n_blocks, bool) or not isinstance(n_blocks, (int, np.integer))
                                 or n_blocks < 100):
        raise ValueError(f"n_blocks = {n_blocks!r} must be a whole number >= 100 (the mass-coupled hazard needs at "
                         "least 20 blocks in each of at least 4 mass classes)")
    t0 = time.perf_counter()
    own = client is None
    cluster = None
    if own:
        client, cluster = connect(scheduler, n_workers)
    if log is not None:
        log(f"dask dashboard (live progress per worker): {getattr(client, 'dashboard_link', None)}")
    try:
        todo = list(corridor.sections)
        done_rows = []
        if resume and partitions is not None and Path(partitions).exists():
            have = {}
            for f in sorted(Path(partitions).glob("section=*.parquet")):
                r = pd.read_parquet(f).iloc[0].to_dict()
                have[r["id"]] = r
            nb = int(n_blocks or corridor.n_blocks)
            keep = [s for s in todo if not (s.id in have and int(have[s.id]["n_blocks"]) == nb
                                            and int(have[s.id]["seed"]) == _section_seed(corridor.seed, s.id))]
            done_rows = [have[s.id] for s in todo if s not in keep]
            todo = keep
        # every worker gets the corridor-wide inputs once, without the sections (each task carries its own)
        c_future = client.scatter(replace(corridor, sections=()), broadcast=True) if todo else None
        run = uuid.uuid4().hex[:8]           # fresh keys: a rerun never picks up an earlier run's (failed) result
        futures = {client.submit(_task, s, c_future, n_blocks, key=f"riskrf-section-{s.id}-{run}", retries=retries):
                   s.id for s in todo}
        failures = []
        total = len(corridor.sections)
        count = len(done_rows)
        for fut in as_completed(futures):
            sid = futures[fut]
            try:
                row = fut.result()
            except Exception as exc:                      # noqa: BLE001 (reported per section)
                if not keep_going:
                    for f in futures:
                        f.cancel()
                    raise RuntimeError(f"section {sid!r} failed: {type(exc).__name__}: {exc} "
                                       "(use --keep-going to run the other sections)") from exc
                failures.append(f"section {sid!r}: {type(exc).__name__}: {exc}")
                continue
            if partitions is not None:
                _write_partition(Path(partitions), row)
            done_rows.append(row)
            count += 1
            if progress is not None:
                progress(count, total, sid)
        workers = len(client.scheduler_info().get("workers", {}))
    finally:
        if own:
            _shutdown(client, cluster)
    if not done_rows:
        raise RuntimeError("no section finished: " + "; ".join(failures))
    table = pd.DataFrame(done_rows).sort_values("chainage_from_m").reset_index(drop=True)
    return CorridorResult(corridor=corridor, table=table, failures=tuple(failures), workers=workers,
                          seconds=time.perf_counter() - t0, n_blocks=int(n_blocks or corridor.n_blocks))
