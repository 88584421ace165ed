"""Work done beside the main computation, in a forked child process on the other core."""
from __future__ import annotations

import signal


#: Longest wait for a background child [s]; past it the child is stopped and the work runs in this process.
#: A child forked from a process whose native threads held a lock can wait on that lock for ever; this
#: bounds the cost of that rare case to a repeat of the work instead of a hung run.
CHILD_TIMEOUT_S = 240.0


#: The signals a background child leaves to its parent (riskrf ends a run on them and stops the child).
_PARENTS_SIGNALS = frozenset({signal.SIGINT, signal.SIGTERM})


class InBackground:
    """Run ``work()`` (returning a picklable value) in a forked child on the other core; :meth:`result` returns it.

    ``riskrf assess`` uses it for work a run needs only later: the site's rate model (the hazard's rate, the
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


def _quietly(work):
    """``work()`` with the warnings it raises recorded and dropped (the same in a child and in this process)."""
    import warnings
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        return work()


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
