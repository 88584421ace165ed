"""How an assessment schedules the work it needs only later: the ``runner=`` hook of
:func:`~riskrf.app.assess.run.run_assessment` and :func:`~riskrf.app.assess.outputs.write_assessment`, and its default,
:class:`InLine` (everything in this process, in order).

The chain says *what* can run beside it (the site's rate model, each stage's figures) and *when* it is about to
simulate; the runner decides *where* that work runs.  ``riskrf.app`` never starts a process and never asks how many
cores there are: the command line passes :class:`riskrf.cli.runner.TwoCores`, which compiles the simulator on
the other core and forks the figure writers there.  The values and the files are the same with either runner.

A runner has three methods:

- ``start(simulates, log)``: the run begins; ``simulates`` is True when it will run the trajectory simulator;
- ``beside(work)``: ``work()`` (no arguments, returning a picklable value) is needed later; returns an object
  whose ``result()`` returns its value (computed once, then kept; an exception ``work`` raised is raised again);
- ``before_simulation(timings)``: the simulation is next; a runner that waited for something records the wait
  in the stage timings ``timings`` [s];
- ``gate()`` (optional): an object with ``open()`` and ``wait()``: work handed to ``beside`` may call ``wait()``
  where it needs what this process finishes later (the report's PDF, before the figures drawn beside it); the
  chain calls ``open()`` once they are finished.  A runner without it runs such work after ``open()`` anyway.
"""
from __future__ import annotations


def quietly(work):
    """``work()`` with the warnings it raises recorded and dropped: work run beside the chain passes on no
    warnings wherever it runs (a forked child cannot pass them on), so work whose warnings matter returns them
    (the rate model keeps them in its notes).

    Parameters
    ----------
    work : callable
        Called with no arguments.

    Returns
    -------
    object
        What ``work`` returned.
    """
    import warnings
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        return work()


class Deferred:
    """``work()`` run in this process when :meth:`result` is first called (quietly, see :func:`quietly`)."""

    def __init__(self, work):
        self.work, self._done = work, None

    def result(self):
        """The work's return value, computed at the first call and then kept.

        Returns
        -------
        object
            What the work returned.
        """
        if self._done is None:
            self._done = (quietly(self.work),)
        return self._done[0]


class OpenGate:
    """The gate of a runner that runs work handed to ``beside`` in this process, when its result is asked for (so
    after :meth:`open`): :meth:`wait` never waits."""

    def open(self) -> None:
        """Nothing to signal."""

    def wait(self, path=None) -> bool:
        """Return at once: the gate is open.

        Parameters
        ----------
        path : str or path, optional
            Ignored (see :meth:`riskrf.cli.runner.Gate.wait`).

        Returns
        -------
        bool
            True.
        """
        return True


class InLine:
    """The default runner: no compilation started ahead, no process forked; work handed to :meth:`beside` runs
    in this process when its result is asked for."""

    def gate(self) -> OpenGate:
        """A gate that never waits (work handed to :meth:`beside` runs at its result, after the gate opened).

        Returns
        -------
        OpenGate
        """
        return OpenGate()

    def start(self, simulates: bool, log) -> None:
        """Nothing to start (the simulator compiles on its first use, in this process).

        Parameters
        ----------
        simulates : bool
            Whether the run will simulate trajectories.
        log : callable
            ``log(str)`` for progress lines.
        """

    def beside(self, work) -> Deferred:
        """``work`` deferred to its :meth:`Deferred.result`.

        Parameters
        ----------
        work : callable
            Called with no arguments.

        Returns
        -------
        Deferred
            Its value on demand.
        """
        return Deferred(work)

    def before_simulation(self, timings: dict) -> None:
        """Nothing to wait for.

        Parameters
        ----------
        timings : dict
            Stage timings [s] of the run (left as they are).
        """
