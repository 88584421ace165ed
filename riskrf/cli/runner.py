"""The command line's process machinery: which work runs on which core, and what a signal does.

Nothing outside ``riskrf.cli`` starts a process or asks how many cores there are; this module holds all of it:

- :func:`_compile_early`: ``riskrf demo`` / ``riskrf assess`` start compiling the simulator in a child before the
  command imports pandas, scipy and numba (``simulation.precompile.start_early``);
- :class:`TwoCores`: the runner ``riskrf assess`` hands to :func:`riskrf.app.assess.run.run_assessment` and
  ``write_assessment`` (the ``runner=`` hook of :mod:`riskrf.app.scheduling`): it takes over that compilation
  (``simulation.precompile.precompile``), does this core's share of the work while it runs, and forks the rate
  model and each stage's figure writers to the other core;
- :class:`InBackground`: one piece of work in a forked child (also used by ``riskrf simulate``'s figures);
- :func:`_terminate_as_interrupt`, :func:`_end_if_terminated`, :func:`_interrupted`: SIGTERM handled like Ctrl-C,
  the one-line message and the exit status (130, 143).
"""
from __future__ import annotations

import contextlib
import os
import select
import signal
import sys
import time

from ..app.scheduling import quietly as _quietly


#: Longest wait for a background child [s]; past it the child is stopped and the work runs in this process.
#: A child forked from a process whose native threads held a lock can wait on that lock for ever; this
#: bounds the cost of that rare case to a repeat of the work instead of a hung run.
CHILD_TIMEOUT_S = 240.0


#: The signals a background child leaves to its parent (riskrf ends a run on them and stops the child).
_PARENTS_SIGNALS = frozenset({signal.SIGINT, signal.SIGTERM})


class InBackground:
    """Run ``work()`` (returning a picklable value) in a forked child on the other core; :meth:`result` returns it.

    ``riskrf assess`` (through :class:`TwoCores`) uses it for work a run needs only later: the site's rate model (the hazard's rate, the
    closure options; fitted while the inventory fits and the simulation run) and each stage's figures and
    tables (drawn while the next stages compute; their work only writes files and returns None).  Forking only
    where it is safe (POSIX, no other thread, e.g. not inside a notebook kernel with threads); otherwise, or if
    the child dies, ``work`` runs in this process at :meth:`result`.  An exception raised by ``work`` in the
    child is raised again by :meth:`result`.  The value and the files are the same either way.
    ``fork=False`` keeps the work in this process (run at :meth:`result`): for when the other core is taken; the
    environment variable ``RISKRF_NO_FORK=1`` does the same for every instance.
    Warnings the work raises are not passed on, wherever it ran (a forked child cannot pass them on): work
    whose warnings matter returns them (the rate model keeps them in its notes).
    """

    def __init__(self, work, *, fork: bool = True):
        import gc
        import os
        import threading
        self.work, self.proc, self.conn, self._done = work, None, None, None
        fork = fork and os.environ.get("RISKRF_NO_FORK", "0") in ("", "0")
        if fork and hasattr(os, "fork") and threading.active_count() == 1:
            import multiprocessing
            try:
                ctx = multiprocessing.get_context("fork")
                self.conn, child = ctx.Pipe(duplex=False)
                self.proc = ctx.Process(target=_send_result, args=(work, child), daemon=True)
                # The objects alive now are frozen out of the garbage collector for the fork: the child's
                # collections then never walk (and so never copy) the pages it shares with this process.
                freeze = gc.get_freeze_count() == 0 and os.environ.get("RISKRF_NO_GC_FREEZE", "0") in ("", "0")
                if freeze:
                    gc.freeze()
                # SIGINT and SIGTERM are blocked across the fork: the child starts with riskrf's handlers and
                # must not run them before _send_result has set its own (the signals wait until then)
                blocked = signal.pthread_sigmask(signal.SIG_BLOCK, _PARENTS_SIGNALS)
                try:
                    self.proc.start()
                finally:
                    signal.pthread_sigmask(signal.SIG_SETMASK, blocked)   # a signal that came meanwhile acts now
                    if freeze:
                        gc.unfreeze()
                child.close()
            except (OSError, ValueError):
                self.proc = None

    def result(self):
        """The work's return value: waits for the background process (or runs the work here when no process
        could be started or it failed) and re-raises an exception the work raised.  Computed once, then kept.

        Returns
        -------
        object
            What the work returned.
        """
        if self._done is not None:
            return self._done[0]
        value = None
        if self.proc is not None:
            status = "failed"
            try:
                if self.conn.poll(CHILD_TIMEOUT_S):
                    status, value = self.conn.recv()
            except (EOFError, OSError):
                status = "failed"
            self.proc.join(timeout=5.0)
            if self.proc.is_alive():          # hung (or slow past the limit): stopped, the work is done here
                self.proc.kill()
                self.proc.join(timeout=5.0)
            self.conn.close()
            if status == "error":
                raise value
            if status != "ok":
                value = _quietly(self.work)
        else:
            value = _quietly(self.work)
        self._done = (value,)
        return value


class Gate:
    """A signal from this process to the work it forked beside it: :meth:`open` (here, once), :meth:`wait` (in
    the child: returns once this process opened the gate, or ended).

    The report's PDF is forked before the decision's figures are finished, so that it lays out the pages before
    them (fonts, title page, tables) on the other core; at each figure not finished at the fork it waits until
    that figure's file appears (figures are renamed into place whole) or the gate opens.  A pipe: the child's
    first :meth:`wait` closes its copy of the write end, so that the read end becomes readable (EOF) if this
    process ends without opening the gate.  Work that runs in this process (no fork, or the fork failed) runs
    at its ``result()``, after :meth:`open`, and never waits.
    """

    #: How often [s] a child waiting for a file looks for it.
    POLL_S = 0.01

    def __init__(self):
        self._pid = os.getpid()
        self._read, self._write = os.pipe()
        self._opened = False           # this process: open() was called; a child: it saw the gate open
        self._write_closed = False     # a child: its copy of the write end is closed

    def open(self) -> None:
        """Let the work waiting in children go on (once; later calls do nothing)."""
        if os.getpid() == self._pid and not self._opened:
            self._opened = True
            try:
                os.write(self._write, b"1")
            finally:
                os.close(self._write)

    def wait(self, path=None) -> bool:
        """In a forked child: wait until the gate is open (or the process that made it ended), or until the file
        ``path`` exists; here: return at once.

        Parameters
        ----------
        path : str or path, optional
            A file whose appearance also ends the wait (default: only the gate does).

        Returns
        -------
        bool
            True when the gate is open (always in this process), False when ``path`` appeared first.
        """
        if os.getpid() == self._pid or self._opened:
            return True
        if not self._write_closed:
            self._write_closed = True
            os.close(self._write)      # this child's copy: EOF when the parent's is closed
        while path is None or not os.path.exists(path):
            ready, _, _ = select.select([self._read], [], [], None if path is None else self.POLL_S)
            if ready:                  # the byte written by open(), or EOF: the parent ended
                self._opened = True
                return True
        return False

    def close(self) -> None:
        """Open the gate if it is not yet, and close this process's read end (after the work's result)."""
        if os.getpid() == self._pid:
            self.open()
            if self._read is not None:
                os.close(self._read)
                self._read = None


def _send_result(work, conn):
    """The child's body.  The signals are the parent's to answer: the child was forked with riskrf's SIGTERM
    handler (which raises KeyboardInterrupt), and Ctrl-C at a terminal reaches the whole process group.  Here
    SIGTERM ends the child at once, silently (the parent stops it so on the way out), and SIGINT is ignored;
    otherwise the child would print its own traceback after the parent's one line."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _PARENTS_SIGNALS)     # blocked by the parent across the fork
    try:
        value = _quietly(work)
    except Exception as exc:          # noqa: BLE001  (sent back and raised in the parent)
        conn.send(("error", exc))
    else:
        conn.send(("ok", value))
    conn.close()


class TwoCores:
    """The runner of ``riskrf assess`` (see :mod:`riskrf.app.scheduling`): the simulator's first compilation on the
    other core while this one fits, then the work needed later forked there.

    On a fresh installation the simulator is compiled once (numba, cached on disk): that takes the other core
    (:meth:`start`, taking over the child :func:`_compile_early` started) while this one fits, fits the rate
    model and draws the fits' figures (:meth:`before_simulation` finishes them here, then waits for the
    compilation); otherwise, and from the simulation on, work handed to :meth:`beside` goes to forked children
    on the other core (:class:`InBackground`).
    """

    def __init__(self):
        #: the compilation under way (``simulation.precompile.precompile``), None without a scenario
        self.compiling = None
        #: True when work may be forked to the other core (no compilation running there)
        self.fork = True
        self._here: list = []            # work kept on this core while the compilation takes the other

    def start(self, simulates: bool, log) -> None:
        """Take over (or start) the simulator's compilation when the run simulates.

        Parameters
        ----------
        simulates : bool
            Whether the run will simulate trajectories.
        log : callable
            ``log(str)`` for progress lines.
        """
        if simulates:
            from simulation.precompile import precompile
            self.compiling = precompile()
        self.fork = self.compiling is None or not self.compiling.running
        if not self.fork:
            log("      first run of this installation: the simulator is compiled once on the other core (numba, "
                "cached on disk for later runs)")

    def beside(self, work) -> InBackground:
        """``work`` in a forked child on the other core (here, at its result, while that core compiles).

        Parameters
        ----------
        work : callable
            Called with no arguments; returns a picklable value.

        Returns
        -------
        InBackground
            Its value on demand (``result()``).
        """
        part = InBackground(work, fork=self.fork)
        if not self.fork:
            self._here.append(part)
        return part

    def gate(self) -> Gate:
        """A :class:`Gate` for work forked beside this process that must wait for something it finishes later.

        Returns
        -------
        Gate
        """
        return Gate()

    def before_simulation(self, timings: dict) -> None:
        """Wait for the simulator's compilation, if one runs, doing this core's share of the work meanwhile.

        Parameters
        ----------
        timings : dict
            Stage timings [s]; ``"compilation"`` is added when there was a compilation to wait for.
        """
        compiling = self.compiling
        if compiling is not None and (not self.fork or compiling.running):
            t = time.perf_counter()
            for part in self._here:          # this core's work while the simulator compiles on the other
                part.result()
            compiling.wait()
            timings["compilation"] = round(time.perf_counter() - t, 2)
        self._here = []
        self.fork = True


def _caused_by_interrupt(exc) -> bool:
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


@contextlib.contextmanager
def _terminate_as_interrupt():
    """SIGTERM (what ``timeout``, batch schedulers and CI send) handled like Ctrl-C: it raises KeyboardInterrupt
    in the main thread, so the temporary outputs are removed and the cluster is shut down on the way out.

    Yields a list that holds the number of each SIGTERM or SIGINT (Ctrl-C) that arrived, so that an interrupt
    which compiled code turned into another exception (numba's compiler raises RuntimeError when Ctrl-C stops
    a compilation) is still reported as one.  SIGINT keeps Python's own action (KeyboardInterrupt) and is
    recorded only where that action is installed (not where it is ignored, as under ``nohup``).  The previous
    handlers are restored after."""
    got: list = []
    previous: dict = {}
    if _on_main_thread():
        def on_term(signum, frame):
            got.append(signum)
            raise KeyboardInterrupt

        def on_int(signum, frame):
            got.append(signum)
            signal.default_int_handler(signum, frame)
        previous[signal.SIGTERM] = signal.signal(signal.SIGTERM, on_term)
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            previous[signal.SIGINT] = signal.signal(signal.SIGINT, on_int)
    try:
        yield got
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _on_main_thread() -> bool:
    """True in the main thread (the only one where a signal handler can be installed)."""
    import threading
    return threading.current_thread() is threading.main_thread()


def _end_if_terminated(status: int, signals) -> int:
    """After SIGTERM (in ``signals``, the signal numbers that arrived), once the temporary outputs are removed
    (the context managers have unwound), end the process at once with ``status`` (143), as SIGTERM's default
    action does: the exit functions run (child processes are stopped, logs flushed) but not the interpreter's
    finalization, during which a worker thread still inside compiled code could abort the process (exit -6
    instead of 143, seen once in CI).  After Ctrl-C, or when no signal arrived, ``status`` is returned to the
    caller."""
    if not _terminated(signals):
        return status
    import atexit
    try:
        atexit._run_exitfuncs()
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(status)


def _terminated(signals) -> bool:
    """True when SIGTERM is among ``signals`` (the signal numbers that arrived)."""
    return signal.SIGTERM in signals


def _interrupted(args, signals=()) -> int:
    terminated = _terminated(signals)
    why = "terminated (SIGTERM)" if terminated else "interrupted"
    print(f"riskrf {args.command}: {why}; nothing was written (outputs appear only when complete)",
          file=sys.stderr)
    return 143 if terminated else 130


def _compile_early(argv) -> None:
    """For ``riskrf demo`` and ``riskrf assess SITE.toml`` with a site that simulates (not their ``--help``), start
    compiling the simulator on the other core before this process imports pandas, scipy and numba (about 2 s),
    when its cache is not there yet (:func:`simulation.precompile.start_early`): on a fresh installation that
    compilation is the longest part of the first run.  A child no run takes over is stopped when the command
    ends (:func:`simulation.precompile.discard_early`)."""
    words = [a for a in argv if not a.startswith("-")]
    asks_help = any(a == "-h" or (len(a) > 2 and "--help".startswith(a)) for a in argv)
    if not words or words[0] not in ("demo", "assess") or asks_help:
        return
    if words[0] == "assess":          # only for a site that simulates (a readable site file naming a scenario)
        import tomllib
        sites = [w for w in words[1:] if w.endswith(".toml")]
        try:
            with open(sites[0], "rb") as f:
                if not tomllib.load(f).get("hazard", {}).get("scenario"):
                    return
        except (IndexError, OSError, ValueError, AttributeError):
            return
    from simulation.precompile import start_early
    start_early()
