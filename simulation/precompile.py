"""The simulator compiled ahead of its first use, in a child process on the other core.

numba compiles the trajectory kernel on first use and caches the machine code on disk (``cache=True``); on a
fresh installation that first compilation takes 10-15 CPU-s.  :class:`Precompile` runs it in a fresh
interpreter while the caller does work that does not need the simulator; the child imports only numpy, numba
and the kernel (:func:`compile_kernel`), not pandas or scipy.stats.  This module imports neither numpy nor numba at
its top, so the ``riskrf`` command can start that child before its own imports (:func:`start_early`).
"""
from __future__ import annotations

import glob
import os
import subprocess
import sys
from pathlib import Path

_early = None


class Precompile:
    """The simulator compiled in a background process while the caller does other work.

    Started early (``Precompile()``), it runs on the second core; :meth:`wait` returns when the
    cache is written, after which the kernel loads in well under a second.  Where the on-disk cache is
    already there no child is started (``check_cache=False`` starts one anyway: it then finishes as soon as
    it has loaded the cache).  A failure in the child only means the kernel is compiled on first use instead.
    """

    def __init__(self, *, check_cache: bool = True):
        self._proc = None
        if disabled() or (check_cache and _cache_exists()):
            return
        # A fresh interpreter (not multiprocessing): it never re-imports the caller's main script, so a user's
        # script without an ``if __name__ == "__main__"`` guard works unchanged.
        try:
            self._proc = subprocess.Popen([sys.executable, "-c", "import simulation.precompile as p; "
                                           "p.compile_kernel()"],
                                          stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                          stderr=subprocess.DEVNULL)
        except OSError:
            self._proc = None

    @property
    def running(self) -> bool:
        """True while the compiling child runs (False where the cache was there or no child could start)."""
        return self._proc is not None and self._proc.poll() is None

    def wait(self, timeout: float | None = 300.0) -> bool:
        """Block until the compilation is done; True when the child finished cleanly (or was not needed).

        Parameters
        ----------
        timeout : float or None, optional
            Longest wait [s] (None: no limit); the child is killed after it.

        Returns
        -------
        bool
            True when the compilation finished cleanly or was not needed.
        """
        if self._proc is None:
            return True
        try:
            self._proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
            return False
        return self._proc.returncode == 0


def disabled() -> bool:
    """True when the environment variable ``RISKRF_NO_PRECOMPILE`` is set to anything but ``""``/``"0"``: no
    compiling child is started, the kernel compiles on first use in the run's own process (for measuring what the
    child saves, ``tests/benchmarks/bench_startup.py``, or where a second process is unwelcome).

    Returns
    -------
    bool
        Whether early compilation is switched off.
    """
    return os.environ.get("RISKRF_NO_PRECOMPILE", "0") not in ("", "0")


def _cache_exists() -> bool:
    """True when the kernel's on-disk cache index exists (numba internals; if they move, False: compile)."""
    try:
        from . import kernel
        return os.path.exists(kernel.simulate._cache._cache_file._index_path)
    except (AttributeError, TypeError):
        return False


def start_early() -> None:
    """Start compiling the simulator now, before this process imports anything heavy, when its cache is not
    there (checked by file name, without importing numba: ``simulation/__pycache__/kernel.simulate-*.nbi``;
    with ``NUMBA_CACHE_DIR`` set the child starts and finishes at once if the cache is warm).  The next
    :func:`precompile` call takes this child over.  Nothing is started with ``NUMBA_DISABLE_JIT``."""
    global _early
    if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0") or _early is not None or disabled():
        return
    if not os.environ.get("NUMBA_CACHE_DIR"):
        tag = f"py{sys.version_info[0]}{sys.version_info[1]}"
        if glob.glob(str(Path(__file__).parent / "__pycache__" / f"kernel.simulate-*.{tag}.nbi")):
            return
    _early = Precompile(check_cache=False)


def precompile() -> Precompile:
    """The compilation for a run about to simulate: nothing to do where the kernel's cache is there (numba's
    own lookup, which also knows ``NUMBA_CACHE_DIR`` and its fall-back folder: an early child is then stopped,
    it was only loading the cache), else the child :func:`start_early` started (taken over once), else a new
    :class:`Precompile`.

    Returns
    -------
    Precompile
        The compilation (possibly one that starts nothing).
    """
    global _early
    if _cache_exists():
        discard_early()
        return Precompile()                       # starts nothing: the cache is there
    if _early is not None:
        started, _early = _early, None
        return started
    return Precompile(check_cache=False)


def discard_early() -> None:
    """Stop the child :func:`start_early` started if no run took it over (a command that failed early, a site
    without a scenario), so that it does not keep compiling after the command has ended."""
    global _early
    if _early is not None and _early._proc is not None and _early._proc.poll() is None:
        _early._proc.terminate()
        try:
            _early._proc.wait(5)
        except subprocess.TimeoutExpired:
            _early._proc.kill()
            _early._proc.wait()          # reaped: no zombie, and poll() tells it has ended
    _early = None


def compile_kernel() -> None:
    """Compile the trajectory kernel (or load it from the cache) by calling it on no blocks, with arguments of
    the types :func:`simulation.engine.run` passes (``tests/test_startup.py`` checks that they are the same, so
    that the run finds this compiled version).  Imports numpy, numba and the kernel only."""
    from . import kernel
    kernel.simulate(**empty_kernel_arguments())


def empty_kernel_arguments() -> dict:
    """Arguments of :func:`simulation.kernel.simulate` for no blocks, by name: its records
    (:mod:`simulation.kernel_args`) of empty arrays of each field's dtype, the envelope accumulator 2-d, scalars of
    the run's types.

    Returns
    -------
    dict
        Argument name -> record, empty array or scalar.
    """
    import numpy as np

    from . import kernel_args as ka

    def f():
        return np.zeros(0)

    def i():
        return np.zeros(0, dtype=np.int64)

    def b():
        return np.zeros(0, dtype=np.bool_)

    # m_drag and sin_max_roll None: the specialisation of scenarios without rolling drag or steep faces
    # (simulation.engine.kernel_features), the one the demo and most sites run
    return {
        "blocks": ka.Blocks2D(i(), *(f() for _ in range(9))),
        "profile": ka.Profile2D(f(), f(), f(), 1, i(), i(), i()),
        "mats": ka.MaterialTable(i(), f(), f(), i(), f(), f(), f(), f(), f(), b(), f(), b(), *(f() for _ in range(10))),
        "m_drag": None,
        "collectors": ka.Collectors2D(f(), f(), f(), i()),
        "envelope": ka.Envelope2D(f(), np.zeros((0, 7))),
        "settings": ka.KernelSettings(9.81, 0.5, 0.1, 1, np.uint64(1), 0),
        "sin_max_roll": None,
        "stops": ka.Stops2D(f(), f(), i(), i(), f()),
        "crossings": ka.Crossings2D(i(), i(), f(), f(), f(), f(), f(), i(), i()),
        "paths": ka.Paths2D(i(), f(), f(), f(), f(), f(), f(), i(), i(), i()),
    }
