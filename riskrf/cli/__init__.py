"""The ``riskrf`` command line.  Each sub-command is a thin layer over the Python API.

The package's modules (each a seam of the command line, none imports numpy at import time):

- this module: :func:`main` (parse, run the sub-command, exit codes and one-line errors) and :func:`command`
  (the console script ``riskrf = "riskrf.cli:command"``);
- :mod:`riskrf.cli.parser`: :func:`build_parser`, every sub-command's options and help texts;
- :mod:`riskrf.cli.steps`: ``fit``, ``simulate``, ``energy``, ``rates``;
- :mod:`riskrf.cli.decisions`: ``decide``, ``assess``, ``demo``;
- :mod:`riskrf.cli.studies`: ``calibrate``, ``calibrate-pooled``, ``corridor``, ``hazard-map``, ``profile``;
- :mod:`riskrf.cli.runner`: the process machinery: the simulator compiled early on the other core, work forked
  to it (figures, the rate model), and SIGTERM/SIGINT handled as an interrupt.  The science and ``riskrf.app``
  never start a process or know how many cores there are: ``run_assessment`` takes the runner as an argument.
"""
from __future__ import annotations

import contextlib
import logging
import os
import sys
import traceback
import warnings

from .decisions import MAX_DRAWN_LEAVES, MAX_DRAWN_PROFILES, _count_leaves, cmd_assess, cmd_decide, cmd_demo
from .parser import EPILOG, build_parser
from .runner import (
    _caused_by_interrupt,
    _compile_early,
    _end_if_terminated,
    _interrupted,
    _on_main_thread,
    _terminate_as_interrupt,
    _terminated,
)
from .steps import _BootstrapBar, _read, build_energy_hazard, cmd_energy, cmd_fit, cmd_rates, cmd_simulate
from .studies import _parse_parameters, cmd_calibrate, cmd_calibrate_pooled, cmd_corridor, cmd_hazard_map, cmd_profile

__all__ = ["main", "command", "build_parser", "EPILOG", "cmd_fit", "cmd_simulate", "cmd_energy", "cmd_rates",
           "cmd_decide", "cmd_assess", "cmd_demo", "cmd_calibrate", "cmd_calibrate_pooled", "cmd_corridor",
           "cmd_hazard_map", "cmd_profile", "build_energy_hazard", "MAX_DRAWN_LEAVES", "MAX_DRAWN_PROFILES"]

#: Kept importable from ``riskrf.cli`` (tests and scripts use them); they live in the modules above.
_REEXPORTED = (_count_leaves, _on_main_thread, _terminated, _BootstrapBar, _read, _parse_parameters)


@contextlib.contextmanager
def _readable_numbers():
    """Printed tables show 4 significant figures with thousands separators, never ``2.308e+04``."""
    import pandas as pd

    from ..report.format import sig

    def shown(v):          # whole numbers exactly (19,999 stays 19,999), others to 4 significant figures
        return f"{v:,.0f}".replace("-", "−") if float(v).is_integer() and abs(v) < 1e15 else sig(v, 4)
    with pd.option_context("display.float_format", shown, "display.width", 200):
        yield


def main(argv=None) -> int:
    """Entry point of the ``riskrf`` command; returns the exit status (0 ok, 2 bad input).

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0 ok, 2 bad input, 3 internal error.
    """
    # Figures are written to files: a non-interactive backend, unless the user chose one.
    os.environ.setdefault("MPLBACKEND", "Agg")
    # Library code logs its stages (logger "riskrf"); the command line shows them as plain lines.
    logger = logging.getLogger("riskrf")
    if not logger.handlers:
        handler = _StdoutHandler()
        handler.setFormatter(logging.Formatter("%(message)s"))
        logger.addHandler(handler)
    logger.setLevel(logging.INFO)
    parser = build_parser()
    args = parser.parse_args(argv)
    signals: list = []
    try:
        with warnings.catch_warnings(), _readable_numbers(), _terminate_as_interrupt() as signals:
            warnings.simplefilter("ignore")  # every warning is reported in the printed summary instead
            from ..app.preflight import check_common
            check_common(args)               # --seed and -n, before anything is read
            return args.func(args)
    except KeyboardInterrupt:
        return _end_if_terminated(_interrupted(args, signals), signals)
    except (ValueError, TypeError, FileNotFoundError, KeyError) as exc:   # includes SiteError, ScenarioError
        if signals:                          # a signal arrived: whatever failed after it, the run was interrupted
            return _end_if_terminated(_interrupted(args, signals), signals)
        if args.debug:
            traceback.print_exc()
        print(f"riskrf {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except Exception as exc:     # OSError, RecursionError, ...: one line, the traceback only with --debug
        # Ctrl-C or SIGTERM inside compiled code surfaces as SystemError (numpy, numba's kernels) or RuntimeError
        # (numba's compiler): after a signal, any failure is the interrupt's
        if signals or _caused_by_interrupt(exc):
            return _end_if_terminated(_interrupted(args, signals), signals)
        if args.debug:
            traceback.print_exc()
        if isinstance(exc, OSError):           # a file system refusal names its file itself
            print(f"riskrf {args.command}: error: {type(exc).__name__}: {exc} (run with --debug for the "
                  "traceback)", file=sys.stderr)
            return 2
        print(f"riskrf {args.command}: internal error (a fault of riskrf, not of the inputs) in stage "
              f"{_failing_stage(exc)} with {_inputs_text(args)}: {type(exc).__name__}: {exc}.  Please report it "
              "with the output of --debug", file=sys.stderr)
        return 3


def _failing_stage(exc) -> str:
    """The innermost riskrf or simulation function outside the command line on the traceback of ``exc``
    (module.function)."""
    tb, stage = exc.__traceback__, "?"
    while tb is not None:
        module = tb.tb_frame.f_globals.get("__name__", "")
        if module.split(".")[0] in ("riskrf", "simulation") and not (module == "riskrf.cli"
                                                                     or module.startswith("riskrf.cli.")):
            stage = f"{module}.{tb.tb_frame.f_code.co_name}"
        tb = tb.tb_next
    return stage


def _inputs_text(args) -> str:
    from ..app.preflight import command_inputs
    try:
        found = command_inputs(args)
    except Exception:                      # noqa: BLE001 (the message must not fail in turn)
        found = {}
    return ("inputs " + ", ".join(f"{k} {v}" for k, v in found.items())) if found else "no input files"


class _StdoutHandler(logging.StreamHandler):
    """A logging handler that writes to ``sys.stdout`` as it is when a record is emitted, not as it was when the
    handler was made: a caller that replaces ``sys.stdout`` between calls of :func:`main` (a notebook, a test's
    capture) gets the log lines, and a stream closed since is never written to."""

    @property
    def stream(self):
        return sys.stdout if sys.stdout is not None else sys.stderr     # no stdout (pythonw, a daemon): stderr

    @stream.setter
    def stream(self, value):
        pass

    def setStream(self, stream):
        """Not supported: the stream is always the current ``sys.stdout``; returns None (nothing replaced)."""
        return None


def command() -> int:
    """The ``riskrf`` console script: the simulator's compilation started early where it is needed
    (:func:`_compile_early`), :func:`main`, then the objects left from the run are frozen out of the
    garbage collector, so that the interpreter's collection at exit does not walk them one by one (about
    0.7 s after a demo); the process ends right after, nothing is lost.

    Returns
    -------
    int
        Exit status of :func:`main`.
    """
    _compile_early(sys.argv[1:])
    try:
        status = main()
    finally:
        if "simulation.precompile" in sys.modules:
            sys.modules["simulation.precompile"].discard_early()
    import gc
    import os
    if os.environ.get("RISKRF_NO_GC_FREEZE", "0") in ("", "0"):
        gc.freeze()
    return status
