"""The ``dask.distributed`` client shared by the corridor and hazard-map runs: connect, and shut down quietly.

:func:`connect` reaches a running scheduler (or ``DASK_SCHEDULER_ADDRESS``) or starts a LocalCluster of
single-threaded workers; :func:`_shutdown` closes what riskrf started without the cluster's shutdown noise.
Times in seconds.
"""
from __future__ import annotations

import os


def connect(scheduler: str | None = None, n_workers: int | None = None, *, timeout_s: float = 10.0,
            processes: bool = True):
    """A ``dask.distributed`` client: to ``scheduler`` (or ``DASK_SCHEDULER_ADDRESS``) if given, used unchanged;
    else a new LocalCluster of ``n_workers`` single-threaded workers (default: one per core).

    Returns (client, cluster or None).  An unreachable scheduler raises ConnectionError within ``timeout_s``.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running dask scheduler.
    n_workers : int, optional
        Workers of a new LocalCluster (default: one per core).
    timeout_s : float, optional
        Time allowed to reach the scheduler [s].
    processes : bool, optional
        Workers as processes (True) or threads.

    Returns
    -------
    client : distributed.Client
        The client.
    cluster : distributed.LocalCluster or None
        The cluster started here (None when connected to ``scheduler``).
    """
    from distributed import Client, LocalCluster
    address = scheduler or os.environ.get("DASK_SCHEDULER_ADDRESS")
    if address:
        try:
            return Client(address, timeout=f"{timeout_s}s"), None
        except (OSError, TimeoutError) as exc:
            raise ConnectionError(f"cannot reach the dask scheduler at {address!r} within {timeout_s:g} s: {exc}") \
                from None
    n = int(n_workers or os.cpu_count() or 1)
    import logging
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=processes, dashboard_address=":0",
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


#: Loggers of dask.distributed that report a cluster's shutdown ("Worker process still alive ... killing",
#: cancelled futures): silenced while riskrf closes its own cluster, on success, error or Ctrl-C alike.
_DASK_LOGGERS = ("distributed", "distributed.nanny", "distributed.worker", "distributed.scheduler",
                 "distributed.core", "distributed.comm", "distributed.batched", "distributed.client", "tornado",
                 "asyncio")


def _shutdown(client, cluster, timeout_s: float = 10.0) -> None:
    """Close the client and (when riskrf started it) the local cluster without tracebacks or shutdown noise.

    Runs in a ``finally``: errors while closing (a cancelled future, a worker that will not stop) are not the
    user's concern and must not hide the run's own outcome, so they are dropped; the workers are killed by
    the cluster when they do not stop within ``timeout_s``."""
    import asyncio
    import logging
    loggers = [logging.getLogger(n) for n in _DASK_LOGGERS]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        for thing in (client, cluster):
            if thing is None:
                continue
            try:
                thing.close(timeout=timeout_s)
            except (Exception, asyncio.CancelledError):     # noqa: BLE001 (see above)
                pass
    finally:
        for lg, level in zip(loggers, levels):
            lg.setLevel(level)
