"""Command-line arguments checked before any work starts: each error names the option and its value."""
from __future__ import annotations

import math
import os
from pathlib import Path

from ..io.outputs import check_output


def _num(args, attr):
    return getattr(args, attr, None)


def _fail(option, value, need):
    shown = f"{value:g}" if isinstance(value, float) else repr(value) if isinstance(value, str) else f"{value}"
    raise ValueError(f"{option} = {shown}: {need}")


def check_number(value, option, *, low=None, high=None, low_open=False, high_open=False, what="") -> None:
    """Raise unless ``value`` is finite and within the bounds; None passes (not given).

    Parameters
    ----------
    value : float or None
        The value given.
    option : str
        Name of the option, for the error message.
    low, high : float, optional
        Bounds (None: unbounded).
    low_open, high_open : bool, optional
        Exclude the bound itself.
    what : str, optional
        Unit or note appended to the error message (e.g. " kg/m3").
    """
    if value is None:
        return
    ok = isinstance(value, (int, float)) and math.isfinite(value)
    if ok and low is not None:
        ok = value > low if low_open else value >= low
    if ok and high is not None:
        ok = value < high if high_open else value <= high
    if not ok:
        lo = "" if low is None else (f"> {low:g}" if low_open else f">= {low:g}")
        hi = "" if high is None else (f"< {high:g}" if high_open else f"<= {high:g}")
        _fail(option, value, f"must be a finite number {' and '.join(x for x in (lo, hi) if x)}" + what)


def check_inventory_args(args) -> None:
    """Options shared by fit, energy and decide.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.
    """
    check_number(_num(args, "density"), "--density", low=0, low_open=True, what=" kg/m3")
    if _num(args, "density") is not None:
        from ..core.validation import check_density
        check_density(args.density, "--density")
    check_number(_num(args, "duration_years"), "--duration-years", low=0, low_open=True, what=" years")
    check_number(_num(args, "m_min"), "--m-min", low=0, low_open=True, what=" kg")
    check_number(_num(args, "m_max"), "--m-max", low=0, low_open=True, what=" kg")
    if _num(args, "m_min") is not None and _num(args, "m_max") is not None and args.m_min >= args.m_max:
        raise ValueError(f"--m-min = {args.m_min:g} kg must be below --m-max = {args.m_max:g} kg")
    check_number(_num(args, "bootstrap"), "--bootstrap", low=0)
    for attr, opt in (("header_row", "--header-row"),):
        check_number(_num(args, attr), opt, low=1)


def check_energy_args(args, *, road_collector=None) -> None:
    """Every option `riskrf energy` and `riskrf decide --options` will use, with the scenario's collectors.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.
    road_collector : str, optional
        Name of the road collector of the scenario.
    """
    check_inventory_args(args)
    check_number(args.n, "-n", low=1)
    check_number(args.reach_probability, "--reach-probability", low=0, high=1, low_open=True)
    check_number(args.rate_scale, "--rate-scale", low=0, high=1, low_open=True,
                 what=" (a share of the inventory's rate: the part of the inventoried face above this line)")
    if hasattr(args, "design_period"):
        check_number(args.design_period, "--design-period", low=1, low_open=True,
                     what=" years (a T-year event has annual probability 1/T)")
        check_number(args.fence_height, "--fence-height", low=0, low_open=True, what=" m")
        check_number(args.free_board, "--free-board", low=0, what=" m")
        for cap in args.fence or ():
            check_number(cap, "--fence", low=0, low_open=True, what=" kJ")
        check_number(args.design_percentile, "--design-percentile", low=0, high=100, low_open=True, high_open=True,
                     what=" % (the design block's percentile of the block sizes; ONR 24810: 95-98)")
        check_number(args.fractal_dimension, "--fractal-dimension", low=0, high=3, low_open=True, high_open=True,
                     what=" (fractal dimension of the fragments; rock fragmentation typically 2-3)")
        check_number(args.fragmentation_iterations, "--fragmentation-iterations", low=1, high=12,
                     what=" (whole fragmentation generations)")
        if (args.fractal_dimension is None) != (args.fragmentation_iterations is None):
            given, missing = (("--fractal-dimension", "--fragmentation-iterations") if args.fragmentation_iterations
                              is None else ("--fragmentation-iterations", "--fractal-dimension"))
            raise ValueError(f"{given} = {getattr(args, given[2:].replace('-', '_'))}: the fragmentation step needs "
                             f"{missing} as well")
    if (args.scenario is None) == (args.velocities is None):
        raise ValueError("give exactly one of --scenario (simulate the velocities) or --velocities (a file)")
    if args.velocities is not None and not Path(args.velocities).is_file():
        raise FileNotFoundError(f"--velocities {args.velocities}: file not found")
    if args.scenario is not None:
        import simulation
        sc = simulation.load_scenario(args.scenario)
        from ..core.file_schemas import check_scenario_file
        check_scenario_file(args.scenario)
        names = [c.name for c in sc.collectors]
        collector = args.collector or "barrier"
        if collector not in names:
            raise ValueError(f"--collector = {collector!r}: scenario {Path(args.scenario).name} has no such collector; "
                             f"its collectors are {names}")
        if road_collector is not None and road_collector not in names:
            raise ValueError(f"--road-collector = {road_collector!r}: scenario {Path(args.scenario).name} has no such "
                             f"collector; its collectors are {names}")


def check_out(args, default, *, kind="dir", inputs=None) -> Path:
    """The output path of a command, refused up front when it would clobber something: an existing output
    without ``--overwrite``, or (:func:`riskrf.io.outputs.check_output_spares_inputs`) an ``--out`` that is, holds
    or lies inside one of ``inputs`` (``{"what it is": path}``), and ``--out ''`` or ``.``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (``--out``, ``--overwrite``).
    default : str or pathlib.Path
        Output path when ``--out`` is not given.
    kind : str, optional
        ``"dir"`` or ``"file"``.
    inputs : dict, optional
        ``{"what it is": path}`` of the command's inputs.

    Returns
    -------
    pathlib.Path
        The checked output path.
    """
    from ..io.outputs import check_output_spares_inputs
    given = getattr(args, "out", None)
    out = Path(default) if given is None else check_output_spares_inputs(given, {}, option="--out")
    check_output_spares_inputs(out, command_inputs(args) | dict(inputs or {}), option="--out")
    return check_output(out, overwrite=getattr(args, "overwrite", False), kind=kind)


#: Arguments that name input files, with what they are (for messages).
INPUT_ARGUMENTS = {"inventory": "inventory", "scenario": "scenario", "velocities": "velocity file",
                   "options": "options file", "tree": "decision tree", "site": "site file",
                   "corridor": "corridor file", "rainfall": "rainfall file", "warnings": "warning list",
                   "block_survey": "block survey", "observed": "observed stops", "drop_height": "scenario",
                   "releases": "releases file"}


def command_inputs(args) -> dict:
    """Every input file a command's arguments name, TOML inputs with the files they name, tables with their
    sidecar ``<stem>.toml``: ``{"what it is": path}``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    dict
        ``{"what it is": path}``.
    """
    from ..io.outputs import files_named_in_toml
    found = {}
    for attr, label in INPUT_ARGUMENTS.items():
        value = getattr(args, attr, None)
        if not isinstance(value, (str, Path)) or not str(value) or not Path(value).exists():
            continue
        path = Path(value)
        if path.suffix.lower() == ".toml" and path.is_file():
            found |= files_named_in_toml(path, label=label)
        else:
            found[label] = path
            side = path.with_suffix(".toml")
            if side.is_file() and side != path:
                found[f"sidecar of the {label}"] = side
    return found


def check_rates_args(args, windows) -> None:
    """Every numeric option of `riskrf rates`, checked before any file is read.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.
    windows : sequence of int
        Rainfall windows [days].
    """
    for w in windows:
        check_number(w, "--windows", low=1, what=" days (whole days)")
    for mm in args.closure_mm or ():
        check_number(mm, "--closure-mm", low=0, low_open=True, what=" mm")
    check_number(args.closure_window, "--closure-window", low=1, what=" days")
    check_number(args.cost_per_hour, "--cost-per-hour", low=0, what=" (money per hour of closure)")
    check_number(args.heavy_day_mm, "--heavy-day-mm", low=0, low_open=True, what=" mm")
    check_number(args.heavy_day_change, "--heavy-day-change", low=-1, low_open=True,
                 what=" (a share: 0.1 = +10 %, -1 would remove every heavy-rain day)")
    check_number(_num(args, "rainfall_header_row"), "--rainfall-header-row", low=1)


#: Memory the simulator holds per released block [bytes]: peak resident memory grew by about 170 bytes per block
#: between 20,000 and 400,000 blocks of the shipped road-cut scenario (Linux, numpy 2.4; measured with
#: ``resource.getrusage`` on ``simulation.run``), rounded up.
BYTES_PER_BLOCK = 200


def physical_memory_bytes() -> int | None:
    """The machine's physical memory [bytes], or None where the system does not say.

    Returns
    -------
    int or None
        Physical memory [bytes].
    """
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return None


def check_common(args) -> None:
    """Options most commands share, checked before anything is read: ``--seed`` a whole number >= 0 (NumPy's
    seeds), ``-n`` at least one block and small enough that the simulation fits in memory
    (:data:`BYTES_PER_BLOCK` x n against the physical memory).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.
    """
    seed = getattr(args, "seed", None)
    if seed is not None:
        check_number(seed, "--seed", low=0, what=" (a whole number; NumPy seeds are >= 0)")
    n = getattr(args, "n", None)
    if n is not None:
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"-n = {n}: n must be a positive whole number of blocks")
        memory = physical_memory_bytes()
        if memory is not None and n * BYTES_PER_BLOCK > memory:
            raise ValueError(f"-n = {n:,}: simulating that many blocks needs about {n * BYTES_PER_BLOCK / 1e9:,.0f} GB "
                             f"of memory ({BYTES_PER_BLOCK} bytes a block), more than this machine's "
                             f"{memory / 1e9:,.0f} GB; at most about {memory // BYTES_PER_BLOCK:,} blocks fit")
