"""The ``riskrf`` command line.  Each sub-command is a thin layer over the Python API."""
from __future__ import annotations

import argparse
import contextlib
import logging
import math
import os
import shutil
import signal
import sys
import textwrap
import traceback
import warnings
from pathlib import Path

from .. import __version__
from ..core.units import DEFAULT_DENSITY_KG_M3

EPILOG = "Units: mass kg, volume m3, density kg/m3, energy kJ, velocity m/s, time in years."


def _add_fit_arguments(p):
    p.add_argument("--m-min", type=float, default=None, metavar="KG",
                   help="completeness threshold in kg; default: chosen by the Kolmogorov-Smirnov method "
                        "of Clauset et al. (2009)")
    p.add_argument("--m-max", type=float, default=None, metavar="KG",
                   help="maximum credible mass in kg (upper truncation of the power law); default: none")
    p.add_argument("--method", choices=("mle", "lsq"), default="mle",
                   help="power-law estimator: mle = maximum likelihood (default, recommended); "
                        "lsq = least squares on log cumulative frequency (practitioners' method)")
    p.add_argument("--gumbel-method", choices=("mle", "moments", "lmoments"), default="mle",
                   help="Gumbel estimator for annual maxima (default mle; moments = Wyllie's equations)")
    p.add_argument("--bootstrap", type=int, default=1000, metavar="N",
                   help="replicates of the power-law goodness-of-fit bootstrap (0 to skip; default 1000)")
    p.add_argument("--seed", type=int, default=1, help="random seed of the bootstrap (default 1)")


def _add_inventory_arguments(p):
    p.add_argument("--density", type=float, default=None, metavar="KG_M3",
                   help=f"rock density in kg/m3 (default: the sidecar TOML, else {DEFAULT_DENSITY_KG_M3:g}, reported as "
                        "default)")
    p.add_argument("--start", default=None, help="start of the record period, YYYY-MM-DD")
    p.add_argument("--end", default=None, help="end of the record period, YYYY-MM-DD")
    p.add_argument("--duration-years", type=float, default=None, metavar="YR",
                   help="length of the record in years, for undated inventories")
    g = p.add_argument_group("reading the inventory (docs: File formats, 'Input formats'; each may also be in the "
                             "sidecar)")
    g.add_argument("--sheet", default=None, help="Excel sheet: name, or number counting from 1")
    g.add_argument("--header-row", type=int, default=None, metavar="ROW",
                   help="1-based row holding the column names (default 1), e.g. 4 below three title rows")
    g.add_argument("--date-format", default=None, metavar="FMT",
                   help="strftime pattern of every date, e.g. %%d/%%m/%%Y; needed only for ambiguous dates")
    g.add_argument("--decimal", choices=(".", ","), default=None,
                   help="decimal mark (default: decided per column; a column mixing 1,5 and 1.5 needs it)")
    g.add_argument("--encoding", default=None, help="text encoding (default UTF-8, else cp1252 with a note)")
    g.add_argument("--volume-unit", default=None, choices=("m3", "dm3", "l", "litre", "cm3"),
                   help="unit of the volume column; also confirms volumes that look too large for m3")
    g.add_argument("--mass-unit", default=None, choices=("kg", "t", "tonne", "tonnes", "tons"),
                   help="unit of the mass column")
    g.add_argument("--volume-column", default=None, metavar="NAME", help="volume column when not recognised")
    g.add_argument("--mass-column", default=None, metavar="NAME", help="mass column when not recognised")
    g.add_argument("--date-column", default=None, metavar="NAME", help="date column when not recognised")
    g.add_argument("--duplicates", choices=("warn", "drop", "keep", "error"), default=None,
                   help="dated rows repeating an earlier row exactly: warn and keep (default; refused when every "
                        "dated row has a copy), drop, keep, or error")


def _add_reader_arguments(p, what: str, key: str, *, dates: bool = False, prefix: str = ""):
    """--sheet, --header-row, --decimal, --encoding (and --date-format) for one table a command reads."""
    g = p.add_argument_group(f"reading {what} (docs: File formats, 'Input formats'; also {key}sheet, ... in the file)"
                             if key else f"reading {what} (docs: File formats, 'Input formats')")
    opt = f"--{prefix}-" if prefix else "--"
    dest = f"{prefix.replace('-', '_')}_" if prefix else ""
    g.add_argument(f"{opt}sheet", dest=f"{dest}sheet", default=None, metavar="SHEET",
                   help=f"Excel sheet of {what}: name, or number counting from 1")
    g.add_argument(f"{opt}header-row", dest=f"{dest}header_row", type=int, default=None, metavar="ROW",
                   help=f"1-based row holding the column names of {what} (default 1)")
    g.add_argument(f"{opt}decimal", dest=f"{dest}decimal", choices=(".", ","), default=None,
                   help="decimal mark (default: decided per column)")
    g.add_argument(f"{opt}encoding", dest=f"{dest}encoding", default=None, metavar="ENCODING",
                   help="text encoding (default UTF-8, else cp1252 with a note)")
    if dates:
        g.add_argument(f"{opt}date-format", dest=f"{dest}date_format", default=None, metavar="FMT",
                       help="strftime pattern of every date, e.g. %%d/%%m/%%Y; needed only for ambiguous dates")


def _read(args, path):
    from ..frequency.inventory import read_inventory
    if path is None:
        raise ValueError(f"riskrf {args.command} needs --inventory INVENTORY (the rock fall inventory file)")
    reader = {k: getattr(args, k) for k in ("sheet", "header_row", "date_format", "decimal", "encoding",
                                            "volume_unit", "mass_unit", "volume_column", "mass_column",
                                            "date_column", "duplicates")}
    return read_inventory(path, start=args.start, end=args.end, duration_years=args.duration_years,
                          density_kg_m3=args.density, **reader)


def cmd_fit(args) -> int:
    """``riskrf fit``: read an inventory, fit the power law (and Gumbel/GEV when dated), print and write the results.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..frequency.study import analyse_inventory
    from ..io.outputs import atomic_output_dir

    from ..app.preflight import check_inventory_args, check_out
    check_inventory_args(args)
    out = check_out(args, f"{Path(args.inventory).stem}-fit")
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers = {args.workers}: must be a whole number >= 1")
    if args.bootstrap_grid is not None and args.bootstrap_grid not in (0,) and args.bootstrap_grid < 2:
        raise ValueError(f"--bootstrap-grid = {args.bootstrap_grid}: give 0 (scan every value) or >= 2 thresholds")
    inv = _read(args, args.inventory)
    show = sys.stderr.isatty() if args.progress is None else args.progress
    bar = _BootstrapBar(sys.stderr) if show and args.bootstrap else None
    grid = "auto" if args.bootstrap_grid is None else (None if args.bootstrap_grid == 0 else args.bootstrap_grid)
    try:
        analysis = analyse_inventory(inv, m_min=args.m_min, method=args.method, m_max=args.m_max,
                                     gumbel_method=args.gumbel_method, n_bootstrap=args.bootstrap, seed=args.seed,
                                     bootstrap_workers=args.workers, progress=bar, bootstrap_grid=grid)
    except BaseException:
        if bar is not None and bar.drawn:
            sys.stderr.write("\n")          # end the bar's line: the error or "interrupted" gets its own
        raise
    print(analysis.summary_text())
    from ..report.files import write_frequency_study
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        write_frequency_study(analysis, tmp)
    print(f"\nWrote summary.json, design_masses.csv, completeness.csv and figures to {out}/")
    return 0


class _BootstrapBar:
    """``progress(done, total)`` callback drawing the bootstrap's progress on a terminal stream."""

    def __init__(self, stream):
        import time
        self.stream, self.started, self._clock = stream, time.perf_counter(), time.perf_counter

    drawn = False

    def __call__(self, done: int, total: int) -> None:
        if done == 0:
            self.started = self._clock()
        self.drawn = done < total
        bar = "#" * int(30 * done / total)
        per = (self._clock() - self.started) / max(done, 1)
        left = per * (total - done)
        self.stream.write(f"\rbootstrap [{bar:<30}] {done:>6,}/{total:,} replicates  {per:.2f} s each, "
                          f"{left:,.0f} s left ")
        if done == total:
            self.stream.write("\n")
        self.stream.flush()


def cmd_simulate(args) -> int:
    """``riskrf simulate``: run a scenario, print its summary, write the crossings table and figures.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    import pandas as pd

    import simulation

    from ..io.outputs import atomic_outputs, check_output, check_output_spares_inputs, require_pyarrow, write_table
    from ..app.preflight import command_inputs
    out = Path(f"{Path(args.scenario).stem}-crossings.{'parquet' if args.format == 'parquet' else 'csv'}") \
        if args.out is None else check_output_spares_inputs(args.out, command_inputs(args))
    if out.suffix.lower() not in (".parquet", ".csv"):
        raise ValueError(f"--out {out}: use a .parquet or .csv file name")
    fmt = args.format or out.suffix.lower()[1:]
    if fmt not in ("both", out.suffix.lower()[1:]):
        raise ValueError(f"--out {out} is a {out.suffix} file but --format {fmt}: name a .{fmt} file, or pass "
                         "--format both for a .csv and a .parquet side by side")
    suffixes = (".csv", ".parquet") if fmt == "both" else (out.suffix.lower(),)
    if ".parquet" in suffixes:
        require_pyarrow(f"--format {fmt}" if args.format else f"--out {out}",
                        instead="or use --format csv" if args.format else "or name a .csv file")
    outs = [out] + [out.with_suffix(s) for s in suffixes if s != out.suffix.lower()]
    for path in outs:
        check_output_spares_inputs(path, command_inputs(args))
        check_output(path, overwrite=args.overwrite, kind="file")
    figures = out.with_name(f"{out.stem}-figures") if args.figures is None else Path(args.figures)
    check_output_spares_inputs(figures, command_inputs(args), option="--figures")
    check_output(figures, overwrite=args.overwrite, kind="dir", option="--figures")
    scenario = simulation.load_scenario(args.scenario)
    from ..core.file_schemas import check_scenario_file
    check_scenario_file(args.scenario)          # every declared field's type and range
    progress = None if args.progress is None else args.progress
    result = simulation.run(scenario, n=args.n, seed=args.seed, progress=progress)
    print(f"Scenario {scenario.name} ({scenario.source}): {args.n:,} blocks, seed {args.seed}")
    print(result.summary().to_string(header=False))
    tables = [result.collector(c.name).assign(collector=c.name) for c in scenario.collectors]
    crossings = pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()
    if "outcome" in crossings:
        crossings["outcome"] = crossings["outcome"].astype(str)
    from functools import partial

    from ..app.background import InBackground
    from ..report import files as report_files
    report_files.prepare_drawing()
    targets = [(path, "file") for path in outs] + [(figures, "dir")]
    with atomic_outputs(targets, overwrite=args.overwrite) as tmps:    # tables and figures appear together or not
        *tmp_outs, tmp = tmps
        drawn = InBackground(partial(report_files.write_simulation_figures, result, tmp,   # on the other core
                                     [c.name for c in scenario.collectors]))                 # while tables are written
        for path, tmp_out in zip(outs, tmp_outs):
            write_table(crossings, tmp_out, suffix=path.suffix)
        for suffix in suffixes:
            write_table(result.runout, tmp / f"runout{suffix}", option="--format")
            write_table(result.envelopes, tmp / f"envelopes{suffix}", option="--format")
        drawn.result()
    names = " and ".join(f"runout{s}, envelopes{s}" for s in suffixes)
    print(f"\nWrote {len(crossings):,} collector crossings to {' and '.join(map(str, outs))} and figures, "
          f"{names} to {figures}/")
    return 0


def _drop_height(args):
    """--drop-height: a height in m, or a scenario TOML whose profile gives it at --collector."""
    value = getattr(args, "drop_height", None)
    if value is None:
        return None
    if str(value).lower().endswith(".toml"):
        from ..core.units import STANDARD_GRAVITY_MS2
        from ..io.velocities import free_fall_drop_m
        h, v0 = free_fall_drop_m(value, args.collector or "barrier")
        return h + v0 ** 2 / (2 * STANDARD_GRAVITY_MS2)        # the release speed as an equivalent extra drop
    try:
        h = float(value)
    except ValueError:
        raise ValueError(f"--drop-height = {value!r}: give a height in m or a scenario .toml file") from None
    if not h > 0 or h == float("inf"):
        raise ValueError(f"--drop-height = {value!r}: must be a finite height > 0 m")
    return h


def build_energy_hazard(args, inventory):
    """Power-law fit of the inventory combined with a simulation or a velocity file (energy and decide).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``energy`` or ``decide``.
    inventory : Inventory
        The fall inventory.

    Returns
    -------
    fit : GutenbergRichterFit
        The power-law fit of the inventory.
    hazard : EnergyHazard
        The impact-energy hazard at the barrier line.
    result : SimulationResult or None
        The simulation behind it (None with a velocity file).
    """
    from ..app.assess import energy_hazard_from_inputs
    return energy_hazard_from_inputs(
        inventory, m_min=args.m_min, m_max=args.m_max, rate_scale=args.rate_scale, scenario=args.scenario,
        velocities=args.velocities, collector=args.collector, n=args.n, seed=args.seed,
        reach_probability=args.reach_probability,
        condition_on_mass=args.condition_on_mass, velocity_unit=args.velocity_unit,
        drop_height_m=_drop_height(args),
        velocity_reader={k: getattr(args, f"velocities_{k}", None) for k in ("sheet", "header_row", "decimal",
                                                                            "encoding")},
        mass_coupling="independent" if args.mass_independent else "simulated",
        design_masses_kg=_energy_design_masses(args, inventory))


def _survey_reader(args) -> dict:
    return {k: getattr(args, f"survey_{k}", None) for k in ("sheet", "header_row", "decimal", "encoding")}


def _energy_design_masses(args, inventory):
    """Masses [kg] the energy command reads design values at: the design-block band, the sensitivity's m_max and
    the fragmentation alternative (a function of the site's law, evaluated once the law is fitted)."""
    from ..hazard.design_block import design_block_candidates_kg, fragment_block_kg, read_block_survey
    out = [2.0 * args.m_max] if args.m_max else []
    survey_path, pct = getattr(args, "block_survey", None), getattr(args, "design_percentile", None)
    survey = read_block_survey(survey_path, inventory.density_kg_m3, **_survey_reader(args)) if survey_path else None
    if pct is not None or survey is not None:
        out += design_block_candidates_kg(rule="percentile", percentile=97.0 if pct is None else pct,
                                          survey_volumes_m3=survey, inventory=inventory,
                                          density_kg_m3=inventory.density_kg_m3)
    D, gens = getattr(args, "fractal_dimension", None), getattr(args, "fragmentation_iterations", None)
    if D is None or gens is None:
        return out

    def with_fragments(law, rate):
        frag = fragment_block_kg(law, rate, design_T=args.design_period, fractal_dimension=D, iterations=gens,
                                 percentile=97.0 if pct is None else pct, density_kg_m3=inventory.density_kg_m3)
        return out + ([frag] if frag is not None else [])
    return with_fragments


def cmd_energy(args) -> int:
    """``riskrf energy``: impact-energy hazard at a barrier line, design energies and fence checks.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..hazard.energy_study import analyse_energy
    from ..io.outputs import atomic_output_dir

    from ..app.preflight import check_energy_args, check_out
    check_energy_args(args)
    out = check_out(args, f"{Path(args.inventory).stem}-energy")
    inv = _read(args, args.inventory)
    for note in inv.notes:
        print(f"note: {note}")
    gr, hazard, _ = build_energy_hazard(args, inv)
    block = sensitivity = None
    fragmenting = args.fractal_dimension is not None or args.fragmentation_iterations is not None
    if args.design_percentile is not None or args.block_survey or fragmenting:
        from ..hazard.design_block import design_block, read_block_survey, resolve_sizes
        survey = read_block_survey(args.block_survey, inv.density_kg_m3, **_survey_reader(args)) \
            if args.block_survey else None
        rule = "percentile" if (args.design_percentile is not None or survey is not None) else "fragmentation"
        block = design_block(hazard, rule=rule,
                             percentile=97.0 if args.design_percentile is None else args.design_percentile,
                             survey_volumes_m3=survey, survey_source=args.block_survey, inventory=inv,
                             sizes=resolve_sizes(args.inventory_sizes, inv), design_T=args.design_period,
                             density_kg_m3=inv.density_kg_m3,
                             fractal_dimension=args.fractal_dimension, iterations=args.fragmentation_iterations)
    if args.design_period * hazard.arrival_rate > 1:
        from ..hazard.energy_study import design_energy_sensitivity
        m_values = [0.5 * gr.m_max, gr.m_max, 2.0 * gr.m_max] if gr.m_max else [None]
        sensitivity = design_energy_sensitivity(hazard, inv.masses, inv.duration_years, m_min=gr.m_min,
                                                m_max_values=m_values,
                                                rate_shares=[0.5 * args.rate_scale, args.rate_scale,
                                                             2.0 * args.rate_scale], T=args.design_period)
    from ..hazard.energy_study import design_energy_tornado
    tornado = design_energy_tornado(hazard, design_T=args.design_period, block=block, masses_kg=inv.masses,
                                    duration_years=inv.duration_years, rate_share=args.rate_scale,
                                    sensitivity=sensitivity) \
        if args.design_period * hazard.arrival_rate > 1 else None
    analysis = analyse_energy(hazard, fences=args.fence or (2000.0, 5000.0), fence_height_m=args.fence_height,
                              free_board_m=args.free_board, design_T=args.design_period,
                              density_kg_m3=inv.density_kg_m3, n_bootstrap=args.bootstrap, seed=args.seed,
                              design_block=block, sensitivity=sensitivity, tornado=tornado)
    from ..report.format import sig
    print(f"Inventory {inv.source}: power law b = {gr.b:.4f} ± {gr.b_stderr:.4f} above m_min = {sig(gr.m_min, 5)} kg "
          f"({gr.n_tail} falls, {sig(gr.rate_min, 4)} per year)" + (f", m_max = {sig(gr.m_max, 5)} kg" if gr.m_max else ""))
    print(analysis.summary_text())
    from ..report.files import write_energy_study
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        written = write_energy_study(analysis, tmp)
    tables = [p.name for p in written if p.suffix != ".png"]
    figures = [p.name for p in written if p.suffix == ".png"]
    print(f"\nWrote {', '.join(tables)} and {len(figures)} figures ({', '.join(figures)}) to {out}/")
    return 0


def cmd_decide(args) -> int:
    """``riskrf decide``: rank mitigation options (site file) or roll back a decision tree file.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..risk.decision_tree import DecisionTree
    from ..risk.mitigation import load_mitigation
    from ..io.outputs import atomic_output_dir, write_json
    from ..report.decision_figures import plot_risk_profiles, plot_tornado, plot_tree
    from ..report.files import save_figure
    from ..report.mitigation_text import study_report, write_mitigation_outputs

    if (args.tree is None) == (args.options is None):
        raise ValueError("give a decision tree file (riskrf decide TREE.json) or --options OPTIONS.toml with "
                         "--inventory and --scenario, not both")
    from ..app.preflight import check_energy_args, check_number, check_out
    check_number(args.risk_tolerance, "--risk-tolerance", low=0, low_open=True,
                 what=" (in money; leave it out for expected values)")
    out = check_out(args, "decision")
    if args.tree is None:
        if args.inventory is None:
            raise ValueError("riskrf decide --options needs --inventory INVENTORY and --scenario SCENARIO "
                             "(or --velocities FILE)")
        check_energy_args(args, road_collector=args.road_collector)
    if args.tree is not None:
        tree = DecisionTree.from_file(args.tree)
        rb = tree.rollback(risk_tolerance=args.risk_tolerance)
        ranking = tree.ranking(risk_tolerance=args.risk_tolerance)
        print(f"Decision tree {args.tree} (objective {tree.objective}"
              + (f", exponential utility with risk tolerance {args.risk_tolerance:g}" if args.risk_tolerance
                 else ", expected values") + ")")
        print(ranking.to_string(index=False))
        print("\nOptimal policy:")
        for path, choice in rb.policy.items():
            print(f"  at {path}: {choice}")
        evpi = {var: tree.evpi(var) for var in tree.variables()}
        for var, value in evpi.items():
            print(f"  EVPI of {var!r}: {value:.6g}")
        tornado = tree.tornado() if tree.parameters else None
        with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
            ranking.to_csv(tmp / "ranking.csv", index=False)
            profiles = tree.risk_profile()
            profiles.to_csv(tmp / "risk_profiles.csv", index=False)
            write_json({"objective": tree.objective, "value": rb.value, "options": rb.option_values,
                        "policy": rb.policy, "evpi": evpi},
                       tmp / "decision.json")
            n_leaves = _count_leaves(tree.root)
            if n_leaves <= MAX_DRAWN_LEAVES:
                save_figure(plot_tree(tree).figure, tmp / "tree.png")
            else:           # a diagram of thousands of branches is unreadable and takes minutes to draw
                print(f"note: tree.png not drawn: {n_leaves:,} end branches (more than {MAX_DRAWN_LEAVES}); "
                      "ranking.csv and risk_profiles.csv hold every option")
            if profiles["option"].nunique() <= MAX_DRAWN_PROFILES:
                save_figure(plot_risk_profiles(profiles).figure, tmp / "risk_profiles.png")
            else:
                print(f"note: risk_profiles.png not drawn: {profiles['option'].nunique():,} options (more than "
                      f"{MAX_DRAWN_PROFILES}); risk_profiles.csv holds them")
            if tornado is not None and len(tornado):
                tornado.to_csv(tmp / "tornado.csv", index=False)
                ax = plot_tornado(tornado)
                save_figure(ax.figure, tmp / "tornado.png")
        print(f"\nWrote ranking.csv, decision.json and figures to {out}/")
        return 0

    from ..risk.mitigation import check_mitigation_file
    check_mitigation_file(args.options)          # every option and table checked before the inventory is read
    inv = _read(args, args.inventory)
    gr, hazard, result = build_energy_hazard(args, inv)
    from ..app.assess import road_share, study_context
    road = args.road_collector or "road"
    study = load_mitigation(args.options, hazard, road_share=road_share(result, hazard.collector, road),
                            **study_context(result, hazard.collector, road, args.option_blocks,
                                            args.seed, inv, hazard, args.rate_scale))
    report = study_report(study)
    print(report["text"])
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        write_mitigation_outputs(study, report, tmp)
    print(f"\nWrote ranking.csv, tornado.csv, break_even.csv, decision.json and figures to {out}/")
    return 0


#: Decision-tree figures are drawn up to these sizes (end branches; options with a risk profile).
MAX_DRAWN_LEAVES = 400
MAX_DRAWN_PROFILES = 40


def _count_leaves(node) -> int:
    """End branches below ``node`` (iteratively: a tree may be deeper than Python's recursion limit)."""
    count, stack = 0, [node]
    while stack:
        n = stack.pop()
        if n.branches:
            stack.extend(b.child for b in n.branches)
        else:
            count += 1
    return count


def _add_energy_arguments(p):
    p.add_argument("--scenario", default=None, help="scenario TOML: simulate the velocities at --collector")
    p.add_argument("--velocities", default=None, metavar="FILE",
                   help="velocity samples at the barrier line (.csv/.parquet: a velocity_ms column, optionally "
                        "height_m, angular_velocity_rads, radius_m, collector; RocFall/RAMMS exports with columns "
                        "such as 'Translational Velocity (m/s)' and 'Bounce Height (m)' are recognised)")
    p.add_argument("--collector", default=None,
                   help="collector (barrier line) name (default 'barrier' in a scenario; a velocity file is "
                        "filtered to it only when given)")
    _add_reader_arguments(p, "the --velocities table", "", prefix="velocities")
    p.add_argument("--drop-height", default=None, metavar="M|SCENARIO",
                   help="with --velocities: height drop [m] from release to the barrier line, or a scenario .toml "
                        "whose profile gives it at --collector; velocities above 1.1 sqrt(2 g H) are warned about "
                        "(default limit without it: 50 m/s, a 127 m free fall)")
    p.add_argument("-n", type=int, default=100_000, help="blocks to simulate with --scenario (default 100,000)")
    p.add_argument("--reach-probability", type=float, default=1.0, metavar="P",
                   help="with --velocities: probability that a fall reaches the line (default 1)")
    p.add_argument("--rate-scale", type=float, default=1.0, metavar="F",
                   help="multiply the inventory's rate of falls by F, e.g. the share of the inventoried cliff "
                        "above this line (default 1)")
    p.add_argument("--condition-on-mass", action="store_true",
                   help="older form: class the seeder's own simulated masses (implies --mass-independent reach)")
    p.add_argument("--mass-independent", action="store_true",
                   help="one reach probability and velocity law for all masses, from the seeder's masses (default: "
                        "blocks simulated across the power law's mass range, reach and speed by mass)")
    p.add_argument("--m-min", type=float, default=None, metavar="KG", help="power-law threshold (default: KS)")
    p.add_argument("--m-max", type=float, default=None, metavar="KG",
                   help="maximum credible block mass, kg (upper truncation; default none)")
    p.add_argument("--seed", type=int, default=1, help="random seed (simulation and bootstrap; default 1)")
    p.add_argument("--bootstrap", type=int, default=300, metavar="N",
                   help="bootstrap replicates for the intervals (default 300)")
    p.add_argument("--velocity-unit", choices=("m/s", "km/h"), default=None,
                   help="unit of the velocity file's velocity column (default m/s; a median above 50 m/s is refused "
                        "as probable km/h unless the unit is given)")


def cmd_assess(args) -> int:
    """``riskrf assess``: the whole chain for a site file, written atomically to ``--out``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..app.assess import run_assessment, write_assessment
    from ..io.outputs import atomic_output_dir
    from ..app.site import load_site

    from ..app.preflight import check_number, check_out
    check_number(args.n, "-n", low=1)
    out = check_out(args, f"{Path(args.site).stem}-assessment")
    site = load_site(args.site)          # every input is checked before anything is computed
    if site.three_d:
        return _assess_terrain(site, args, out)
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        # figures of each stage are drawn into the temporary output beside the later stages
        assessment = run_assessment(site, seed=args.seed, n_blocks=args.n, figures_dir=tmp / "figures")
        s = write_assessment(assessment, tmp)
    stages = ", ".join(f"{k} {v:.1f} s" for k, v in assessment.timings.items())
    print(f"\nStage times: {stages}.")
    if assessment.warnings:
        print(f"{len(assessment.warnings)} warning(s), also listed in the report:")
        from ..io.outputs import relative_paths
        for w in assessment.warnings:
            print(f"  - {relative_paths(w, site.path.parent)}")        # paths relative to the site file
    print(f"Rate of falls from the {s['hazard']['rate_source']}.")
    print(f"Lowest expected total cost: {s['best_option']} (then {s['second_option']}).")
    print(f"Recommendation: {s['recommendation']['option'] or 'none'} ({s['recommendation']['basis']}).")
    if "resolution" in s["recommendation"]:
        print(f"Resolution: {s['recommendation']['resolution']['text']}")
    if assessment.model_uncertainty is not None:
        print("\n".join(assessment.model_uncertainty.text()))
    print(f"Report: {(out / 'report.html').resolve()}")
    return 0


def _assess_terrain(site, args, out) -> int:
    """``riskrf assess`` for a site on 3-D terrain (:mod:`riskrf.app.assess3d`)."""
    from ..app.assess3d import run_terrain_assessment
    from ..io.outputs import atomic_output_dir
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        a = run_terrain_assessment(site, seed=args.seed, n_blocks=args.n)
        s = a.write(tmp)
    print(f"\nStage times: {', '.join(f'{k} {v:.1f} s' for k, v in a.timings.items())}.")
    hz = s["hazard"]
    print(f"3-D terrain: {hz['line']}; reach {hz['reach_probability']:.3g}, "
          f"{hz['arrival_rate_per_year']:.3g} falls/yr at the line.")
    if s["road"] is not None:
        r = s["road"]
        print(f"Road {r['road']!r}: {r['falls_per_year']:.3g} falls/yr over {r['length_m']:.0f} m, "
              f"{r['deaths_per_year']:.3g} deaths/yr; worst metre at {r['worst_metre_start_m']:.0f} m.")
    for w in a.warnings:
        print(f"  - {w}")
    print("Not done on 3-D terrain: " + "; ".join(s["not_done_on_3d_terrain"]) + ".")
    print(f"Outputs: {out.resolve()}")
    return 0


def cmd_demo(args) -> int:
    """``riskrf demo``: ``assess`` on the bundled demo site.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from importlib import resources

    with resources.as_file(resources.files("riskrf") / "data" / "demo_site.toml") as site:
        args.site = str(site)
        if args.out is None:
            args.out = "riskrf-demo"
        print(f"riskrf demo: the bundled site {site.name} (real Lauterbrunnen inventory, shipped road-cut "
              "scenario, illustrative costs)")
        return cmd_assess(args)


def _with_warnings_printed(func, *args, **kwargs):
    """``func(*args, **kwargs)`` (a calibration), printing each warning it raised that its ``notes`` do not
    already hold as ``warning: ...`` lines.

    Returns
    -------
    object
        What ``func`` returned.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = func(*args, **kwargs)
    for w in caught:
        if str(w.message) not in result.notes:
            print(f"warning: {w.message}")
    return result


def cmd_calibrate(args) -> int:
    """``riskrf calibrate``: fit scenario material parameters to observed stop points.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    import simulation
    from simulation.calibration import read_observed

    from ..io.outputs import atomic_output_dir, write_json
    from ..report.files import save_figure

    parameters = _parse_parameters(args.parameter)
    select = {}
    for item in args.select or []:
        key, sep, value = item.partition("=")
        if not sep:
            raise ValueError(f"--select {item!r}: use COLUMN=VALUE, e.g. profile=P1")
        select[key] = value
    from ..app.preflight import check_out
    out = check_out(args, f"{Path(args.scenario).stem}-calibration")
    from ..core.file_schemas import check_scenario_file
    check_scenario_file(args.scenario)
    table = None
    if Path(args.observed).is_file():
        from ..io.tables import read_numeric_table       # separators, decimal commas, encodings, sheets as for inventories
        table = read_numeric_table(args.observed, what="observed stops", decimal=args.decimal, sheet=args.sheet,
                                   header_row=args.header_row, encoding=args.encoding, numeric=(args.column,))
    observed = read_observed(args.observed, column=args.column, select=select, table=table)
    cal = _with_warnings_printed(simulation.calibrate, args.scenario, observed, parameters, n=args.n,
                                 seed=args.seed, distance=args.distance, collector=args.collector,
                                 maxiter=args.maxiter, n_bootstrap=args.bootstrap)
    print(f"Calibrated {args.scenario} to {observed.attrs['source']}"
          + (f" rows {select}" if select else "") + f": {cal.observed.size} observed stops, {args.n:,} simulated "
          f"blocks per evaluation (seed {args.seed}), {len(cal.evaluations)} evaluations, distance {cal.distance_name}")
    print(cal.summary().to_string(float_format=lambda v: f"{v:.4g}"))
    print()
    print(cal.comparison().to_string(float_format=lambda v: f"{v:.4g}"))
    for note in cal.notes:
        print(f"note: {note}")
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        (tmp / f"{Path(args.scenario).stem}_calibrated.toml").write_text(cal.to_toml())
        cal.summary().to_csv(tmp / "parameters.csv")
        cal.comparison().to_csv(tmp / "comparison.csv")
        cal.bootstrap.to_csv(tmp / "bootstrap.csv", index=False)
        cal.evaluations.to_csv(tmp / "evaluations.csv", index=False)
        write_json({"parameters": cal.parameters, "bounds": cal.bounds,
                                              "n": cal.n, "seed": cal.seed, "distance": cal.distance_name,
                                              "objective": cal.distance, "objective_initial": cal.distance_initial,
                                              "observed": cal.observed_source, "select": select,
                    "notes": list(cal.notes)}, tmp / "calibration.json")
        save_figure(cal.plot().figure, tmp / "runout_observed_vs_simulated.png")
    print(f"\nWrote the calibrated scenario, parameters.csv, comparison.csv, bootstrap.csv, evaluations.csv, "
          f"calibration.json and runout_observed_vs_simulated.png to {out}/")
    return 0


def _parse_parameters(items) -> dict:
    """The ``--parameter NAME=LOW:HIGH`` options as {dotted path: (low, high)}.

    Parameters
    ----------
    items : list of str or None
        The options as given.

    Returns
    -------
    dict
        Dotted scenario path -> (low, high).

    Raises
    ------
    ValueError
        An option not of the form NAME=LOW:HIGH with numbers, or none given.
    """
    parameters = {}
    for item in items or []:
        name, sep, rng = item.partition("=")
        low, sep2, high = rng.partition(":")
        if not (sep and sep2 and name):
            raise ValueError(f"--parameter {item!r}: use NAME=LOW:HIGH, e.g. "
                             "materials.talus.ground_friction_angle_deg=15:40")
        if name in parameters:
            raise ValueError(f"--parameter {item!r}: {name} is already given as {parameters[name]}")
        try:
            parameters[name] = (float(low), float(high))
        except ValueError:
            raise ValueError(f"--parameter {item!r}: LOW and HIGH must be numbers; got {low!r} and {high!r}") from None
    if not parameters:
        raise ValueError("give at least one --parameter NAME=LOW:HIGH")
    return parameters


def cmd_calibrate_pooled(args) -> int:
    """``riskrf calibrate-pooled RELEASES``: fit material parameters shared by many releases to all their observed
    stops (:func:`simulation.calibrate_pooled`) and write the posterior sample with its diagnostics.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from simulation.pooled import calibrate_pooled, read_releases

    from ..app.preflight import check_out
    from ..core.file_schemas import check_scenario_file
    from ..io.outputs import atomic_output_dir, files_named_in_toml, write_json
    from ..report.files import save_figure

    parameters = _parse_parameters(args.parameter)
    for option, value, least in (("--n-per-release", args.n_per_release, 10), ("--iterations", args.iterations, 0),
                                 ("--posterior", args.posterior, 10), ("--predictive", args.predictive, 0)):
        if value < least:
            raise ValueError(f"{option} {value}: must be a whole number >= {least}")
    scenarios, inputs = {}, {}
    for item in args.scenario or []:
        name, sep, path = item.partition("=")
        if not (sep and name and path):
            raise ValueError(f"--scenario {item!r}: use NAME=FILE, e.g. P1=authume_p1.toml (NAME as in the "
                             f"{args.scenario_column!r} column)")
        if name in scenarios:
            raise ValueError(f"--scenario {item!r}: {name!r} is already given as {scenarios[name]!r}")
        if not Path(path).is_file():
            raise FileNotFoundError(f"--scenario {item!r}: scenario file not found: {path}")
        check_scenario_file(path)
        scenarios[name] = path
        inputs |= files_named_in_toml(path, label=f"scenario {name}")      # the TOML and the DEM etc. it names
    if not scenarios:
        raise ValueError(f"give at least one --scenario NAME=FILE (NAME as in the {args.scenario_column!r} column)")
    out = check_out(args, f"{Path(args.releases).stem}-pooled-calibration", inputs=inputs)
    columns = [c.strip() for c in args.release_column.split(",")]
    releases = read_releases(args.releases, scenarios, release_column=columns if len(columns) > 1 else columns[0],
                             scenario_column=args.scenario_column)
    print(f"riskrf calibrate-pooled: {len(releases)} releases from {args.releases}, "
          f"{sum(len(r.x_stop_m) for r in releases)} observed stops, {len(parameters)} parameters, "
          f"{args.n_per_release} blocks per release and parameter set (seed {args.seed})")
    cal = _with_warnings_printed(calibrate_pooled, releases, parameters, n_per_release=args.n_per_release,
                                 seed=args.seed, iterations=args.iterations, n_posterior=args.posterior,
                                 n_predictive=args.predictive)
    summary = cal.summary()
    print(summary.to_string(float_format=lambda v: f"{v:.4g}"))
    if args.predictive:
        cov = cal.coverage()
        print(f"\nPredictive check: {cov['inside_90']:.0%} of the observed stops inside their release's central 90 % "
              f"interval, {cov['inside_99']:.0%} inside its 99 % (nominal 90 % and 99 %)")
    for note in cal.notes:
        print(f"note: {note}")
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        cal.write(tmp / "posterior.csv")
        summary.to_csv(tmp / "parameters.csv")
        cal.correlations().to_csv(tmp / "correlations.csv")
        cal.evaluations.to_csv(tmp / "evaluations.csv", index=False)
        files = ["posterior.csv", "parameters.csv", "correlations.csv", "evaluations.csv", "calibration.json",
                 "posterior_pairs.png"]
        if args.predictive:
            cal.coverage_table.to_csv(tmp / "coverage.csv", index=False)
            save_figure(cal.plot("coverage").figure, tmp / "coverage.png")
            files[4:4] = ["coverage.csv"]
            files.append("coverage.png")
        write_json({"parameters": cal.parameters, "bounds": cal.bounds, "n_per_release": cal.n_per_release,
                    "seed": cal.seed, "effective_sample": cal.ess, "releases": args.releases,
                    "scenarios": scenarios, "notes": list(cal.notes)}, tmp / "calibration.json")
        save_figure(cal.plot("pairs").figure, tmp / "posterior_pairs.png")
    print(f"\nWrote {', '.join(files)} to {out}/")
    return 0


def cmd_corridor(args) -> int:
    """``riskrf corridor FILE``: read and check the corridor (sections table, mass law, study inputs), run every
    section and write the tables, figures and report to ``--out``.  Returns the exit code (0 on success).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..app.corridor import load_corridor, run_corridor, write_corridor
    from ..app.preflight import check_number, check_out
    check_number(args.workers, "--workers", low=1, what=" (whole workers of the local cluster)")
    if args.n is not None and args.n < 100:
        raise ValueError(f"-n = {args.n} (n_blocks = {args.n} blocks per section) must be a whole number >= 100 (the "
                         "mass-coupled hazard needs at least 20 blocks in each of at least 4 mass classes)")
    out = check_out(args, f"{Path(args.corridor).stem}-corridor")

    if args.budget is not None and not (args.budget >= 0 and math.isfinite(args.budget)):
        print(f"riskrf corridor: error: --budget = {args.budget:g} must be a finite amount >= 0 (in the corridor's "
              "currency)", file=sys.stderr)
        return 2
    if args.gdf is not None and not (math.isfinite(args.gdf) and args.gdf >= 1):
        print(f"riskrf corridor: error: --gdf = {args.gdf:g} must be a number >= 1 (the ALARP gross-disproportion "
              "factor: a section is funded while its cost is at most GDF times what it is worth at the VSL; it "
              "overrides [criteria] disproportion_factor of the corridor file)", file=sys.stderr)
        return 2
    corridor = load_corridor(args.corridor, keep_going=args.keep_going, sheet=args.sheet,   # every row checked
                             header_row=args.header_row, decimal=args.decimal, encoding=args.encoding)
    for e in corridor.errors:
        print(f"skipped (--keep-going): {e}")
    parts = out.parent / f".{out.name}.sections"
    n = args.n or corridor.n_blocks
    where = args.scheduler or os.environ.get("DASK_SCHEDULER_ADDRESS") or \
        f"a local cluster of {args.workers or os.cpu_count()} workers"
    print(f"riskrf corridor: {len(corridor.sections)} sections x {n:,} blocks on {where}; "
          f"finished sections go to {parts}")

    from ..report.format import probability

    def progress(done, total, sid):
        bar = "#" * int(30 * done / total)
        print(f"\r[{bar:<30}] {done}/{total} sections (last: {sid})", end="" if done < total else "\n", flush=True)

    try:
        res = run_corridor(corridor, scheduler=args.scheduler, n_workers=args.workers, n_blocks=n, partitions=parts,
                           resume=args.resume, keep_going=args.keep_going, progress=progress, log=print)
    except (ConnectionError, RuntimeError) as exc:
        print(f"\nriskrf corridor: error: {exc}", file=sys.stderr)
        if parts.exists():
            print(f"finished sections are kept in {parts}; rerun with --resume to skip them", file=sys.stderr)
        return 2
    write_corridor(res, out, overwrite=args.overwrite, budget=args.budget, budget_basis=args.budget_basis,
                   objective=args.objective, gdf=args.gdf)
    shutil.rmtree(parts, ignore_errors=True)        # the run is complete: its partitions are in sections.csv
    for f in res.failures:
        print(f"failed: {f}")
    top = res.summary().head(5)
    print(f"{len(res.table)} sections in {res.seconds:.1f} s on {res.workers} workers "
          f"({len(res.table) / max(res.seconds, 1e-9) * 60:.1f} sections per minute).  Highest risk first:")
    for _, r in top.iterrows():
        print(f"  {r['id']}: RHRS {r.get('rhrs_total', r.get('rhrs_score')):.0f} (rank {r['rank_rhrs']:.0f}), {probability(r['deaths_per_year'])} deaths/yr, "
              f"best: {r['best_option']} ({r['best_option_capital']:,.0f} {corridor.currency})")
    if args.budget is not None:
        import json
        summ = json.loads((out / "summary.json").read_text(encoding="utf-8"))
        caps = "capital" if args.budget_basis == "total" else "equivalent annual cost"
        for label, p in (("Programme", summ["programme"]), ("Beside it", summ["other_programme"])):
            gdf = f", GDF {p['gross_disproportion_factor']:g}" if p["gross_disproportion_factor"] else ""
            bc = p["median_benefit_cost_ratio"]
            req = (f"; {len(p['required_by_tolerability'])} required by tolerability"
                   if p["required_by_tolerability"] else "")
            print(f"{label} ({p['objective']}{gdf}) within {args.budget:,.0f} {corridor.currency} of {caps}: "
                  f"{p['sections_funded']} sections funded for {p['cost']:,.0f} {corridor.currency}"
                  + (f", median benefit/cost {bc:.2g}" if bc is not None else "") + req
                  + f", {p['maximised'].replace('_', ' ')} {p['benefit']:.4g}")
        print(summ["programme"]["disagreement"] + " (programme.csv, frontier.png)")
    extra = ", sections.gpkg, map.png" if corridor.centreline is not None else ""
    print(f"Report: {(out / 'report.html').resolve()} (also corridor.csv, sections.csv{extra}, budget_curve.csv, "
          "chainage.png, rating_sheets.html, summary.json)")
    return 0


def cmd_hazard_map(args) -> int:
    """``riskrf hazard-map``: run a 3-D ``[terrain]`` scenario and write hazard GeoTIFFs on the DEM's grid, stop
    points and trajectories (GeoPackage) and a hillshade figure.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..app.hazard_map import hazard_map
    from ..io.outputs import check_output
    out = Path(args.out) if args.out else Path(f"{Path(args.scenario).stem}-hazard-map")
    check_output(out, overwrite=args.overwrite, kind="dir")
    if args.tile_m <= 0:
        raise ValueError(f"--tile-m {args.tile_m!r} must be a tile size > 0 m")
    hm = hazard_map(args.scenario, n=args.n, seed=args.seed, crs=args.crs, workers=args.workers,
                    dask=args.dask or args.scheduler is not None, scheduler=args.scheduler, tile_m=args.tile_m,
                    rate_per_year=args.rate_per_year)
    print(f"Scenario {hm.scenario.name} ({hm.scenario.source}): {hm.result.n:,} blocks, seed {args.seed}")
    print(hm.result.summary().to_string(index=False, header=False))
    hm.write(out, overwrite=args.overwrite)
    print(f"Wrote hazard rasters (GeoTIFF, {hm.scenario.terrain.crs}), hazard_map.gpkg and hillshade.png to {out}/")
    return 0


def cmd_profile(args) -> int:
    """``riskrf profile``: cut a 2-D slope profile from a DEM raster along a plan polyline and write it as the
    ``[profile]`` table of a scenario (TOML).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    import simulation

    from ..io.outputs import atomic_outputs, check_output
    out = Path(args.out) if args.out else Path(f"{Path(args.dem).stem}-profile.toml")
    check_output(out, overwrite=args.overwrite, kind="file")
    try:
        path = [tuple(float(v) for v in p.split(",")) for p in args.path]
    except ValueError:
        raise ValueError(f"--path {' '.join(args.path)}: give plan vertices as X,Y X,Y ... (numbers)") from None
    if any(len(p) != 2 for p in path) or len(path) < 2:
        raise ValueError(f"--path {' '.join(args.path)}: give at least two plan vertices as X,Y")
    dem = simulation.read_dem(args.dem, crs=args.crs)
    prof = simulation.profile_from_grid(dem, path, spacing=args.spacing)
    d = prof.to_dict()
    fmt = lambda xs: "[" + ", ".join(repr(float(v)) for v in xs) + "]"  # noqa: E731  (to_dict: 1 mm)
    text = (f"# 2-D section of {args.dem} ({dem.crs.to_string() if dem.crs else 'no CRS'}) along "
            f"{' -> '.join(f'({x:g}, {y:g})' for x, y in path)}, every {prof.spacing_m:g} m (riskrf profile)\n"
            f"[profile]\nx = {fmt(d['x'])}\nz = {fmt(d['z'])}\nmaterial = \"{args.material}\"\n")
    with atomic_outputs([(out, "file")], overwrite=args.overwrite) as tmp:
        tmp.write_text(text)
    print(f"{len(d['x'])} vertices over {d['x'][-1]:g} m, elevation {min(d['z']):g}-{max(d['z']):g} m; wrote the "
          f"[profile] table to {out} (add [materials.{args.material}] and a [seeder] to make a scenario)")
    return 0


def _add_out_dir(p, default: str) -> None:
    """Add ``--out DIR``, the output directory of a command.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser.
    default : str
        The default directory as the help text names it, e.g. ``<scenario>-calibration``.
    """
    p.add_argument("--out", default=None, metavar="DIR", help=f"output directory (default {default})")


def _add_release_arguments(p, n_default: int) -> None:
    """Add ``-n`` (blocks to release) and ``--seed`` of a simulating command.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser.
    n_default : int
        Default number of blocks to release.
    """
    p.add_argument("-n", type=int, default=n_default, help=f"number of blocks to release (default {n_default:,})")
    p.add_argument("--seed", type=int, default=1, help="random seed; the same seed gives identical results")


def _add_fit_parser(sub) -> None:
    """Add the sub-command fit: magnitude-frequency fits of an inventory, bootstrap options included.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("fit", help="fit power-law, Gumbel and GEV models to a rock fall inventory",
                       description="Fit the magnitude-frequency models of Wyllie (2014) section 8.4 to an "
                       "inventory (CSV, XLSX or Parquet with a volume_m3 or mass_kg column and optionally a "
                       "date): a power law to all masses and, for dated inventories, Gumbel and GEV "
                       "distributions to the annual maxima.  Prints the parameters with standard errors "
                       "and a table of design masses for 10-1000 years, and writes summary.json, "
                       "design_masses.csv, completeness.csv and PNG figures.", epilog=EPILOG)
    p.add_argument("inventory", help="inventory file (.csv, .xlsx, .parquet); a sidecar <name>.toml beside it "
                   "may give [record] start/end or duration_years and density_kg_m3")
    _add_inventory_arguments(p)
    _add_fit_arguments(p)
    p.add_argument("--out", default=None, metavar="DIR",
                   help="output directory (default: <inventory name>-fit); written only when complete")
    g = p.add_argument_group("bootstrap of large inventories (docs: Inventories, 'Scale of the fits')")
    g.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="show the bootstrap's progress bar (default: on when standard error is a terminal)")
    g.add_argument("--workers", type=int, default=None, metavar="N",
                   help="threads running bootstrap replicates (default: one per core for 20,000-100,000 falls, "
                        "where the compiled threshold scan dominates; else 1); results are identical for any number "
                        "(replicate i always uses seed child i)")
    g.add_argument("--bootstrap-grid", type=int, default=None, metavar="K",
                   help="threshold candidates scanned in the data and in each bootstrap replicate.  Default: "
                        "every distinct value (exact, Clauset et al. 2009) up to 100,000 falls; above that "
                        "2,000 candidates at log-spaced tail sizes, which makes a replicate of 10^6 falls about "
                        "0.05-0.1 s instead of 3-7 s (neighbouring candidates are < 0.6 %% apart in tail size).  "
                        "0 = every value")
    p.set_defaults(func=cmd_fit)


def _add_simulate_parser(sub) -> None:
    """Add the sub-command simulate: Monte Carlo trajectories of a 2-D scenario.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("simulate", help="Monte Carlo rock fall trajectories on a slope scenario",
                       description="Simulate blocks released by a scenario's seeder (TOML; see the docs: File "
                       "formats, 'Scenario files') and write one row per collector crossing (velocity_ms, "
                       "angular_velocity_rads, height_m, energy_kj, ...) to a CSV or Parquet file (--format), "
                       "with figures: the profile and trajectories, distributions at each collector, envelopes.",
                       epilog=EPILOG)
    p.add_argument("scenario", help="scenario TOML file, e.g. simulation/scenarios/road_cut_barrier.toml")
    _add_release_arguments(p, 100_000)
    p.add_argument("--out", default=None, metavar="FILE",
                   help="crossings table, .csv or .parquet (default <scenario>-crossings.csv, .parquet with "
                   "--format parquet)")
    p.add_argument("--format", choices=("csv", "parquet", "both"), default=None,
                   help="format of the crossings table and of runout and envelopes: csv (cells a spreadsheet "
                   "would run as a formula are prefixed with '), parquet (columnar, smaller and faster to read; "
                   "needs pyarrow: pip install 'riskrf[parquet]') or both side by side (default: the --out "
                   "suffix, else csv)")
    p.add_argument("--figures", default=None, metavar="DIR",
                   help="directory of the figures, runout and envelopes (default <out>-figures)")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="show a progress bar (default: on for 200,000 blocks or more on a terminal)")
    p.set_defaults(func=cmd_simulate)


def _add_energy_parser(sub) -> None:
    """Add the sub-command energy: impact-energy hazard at a barrier line, fence checks and the design block.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("energy", help="impact-energy hazard at a barrier line and fence checks",
                       description="Combine the power law fitted to an inventory with velocities at a barrier line "
                       "(simulated from a scenario, or read from a file) into the annual frequency of impacts above "
                       "each energy, design energies for 10-1000 years with bootstrap intervals, percentiles, "
                       "ETAG 027 MEL/SEL checks of candidate fences and the UNI 11211-4 design energy.",
                       epilog=EPILOG)
    p.add_argument("--inventory", required=True, help="inventory file (as for riskrf fit)")
    _add_inventory_arguments(p)
    _add_energy_arguments(p)
    p.add_argument("--fence", type=float, action="append", metavar="KJ",
                   help="candidate fence capacity (MEL) in kJ; repeat for several (default 2000 and 5000)")
    p.add_argument("--fence-height", type=float, default=5.0, metavar="M", help="fence height in m (default 5)")
    p.add_argument("--free-board", type=float, default=0.5, metavar="M",
                   help="free board above the p95 bounce height, m (UNI 11211-4: at least 0.5; default 0.5)")
    p.add_argument("--design-period", type=float, default=100.0, metavar="YR",
                   help="return period of the fence checks and UNI design block, years (default 100)")
    p.add_argument("--design-percentile", type=float, default=None, metavar="P",
                   help="design block: the P-th percentile of the block sizes (ONR 24810: 95-98), of --block-survey or "
                        "else of the inventory's sizes (stated as an assumption when they are event volumes)")
    p.add_argument("--block-survey", default=None, metavar="FILE",
                   help="block survey (.csv/.xlsx/.parquet with a volume_m3 or mass_kg column) for the design block")
    p.add_argument("--fractal-dimension", type=float, default=None, metavar="D",
                   help="fragmentation step (Perfect 1997): fractal dimension D in (0, 3) of the fragments of the "
                        "design-period event; the design block is then a percentile of its fragments")
    p.add_argument("--fragmentation-iterations", type=int, default=None, metavar="N",
                   help="fragmentation generations (1-12) with --fractal-dimension")
    p.add_argument("--inventory-sizes", choices=("event_volumes", "blocks"), default=None,
                   help="what the inventory's sizes are (default: the inventory sidecar's sizes, else event_volumes)")
    _add_out_dir(p, "<inventory>-energy")
    _add_reader_arguments(p, "the --block-survey table", "", prefix="survey")
    p.set_defaults(func=cmd_energy)


def _add_decide_parser(sub) -> None:
    """Add the sub-command decide: roll back a decision tree, or rank mitigation options.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("decide", help="rank mitigation options, or roll back any decision tree",
                       description="Two uses.  (1) riskrf decide TREE.json|TREE.toml: roll back a decision tree "
                       "(format in the docs: Risk and mitigation decisions), print the ranking, optimal policy and "
                       "EVPI, and draw the tree, risk profiles and tornado.  (2) riskrf decide --options OPTIONS.toml "
                       "--inventory INV --scenario SCENARIO: build the energy hazard, evaluate each mitigation "
                       "option's residual hazard and rank them by expected total cost, with break-even values, tornado "
                       "chart and F-N curves.",
                       epilog=EPILOG)
    p.add_argument("tree", nargs="?", default=None, help="decision tree file (.json or .toml)")
    p.add_argument("--options", default=None, metavar="TOML", help="mitigation options file")
    p.add_argument("--inventory", default=None, help="inventory file (with --options)")
    p.add_argument("--option-blocks", type=int, default=20_000, metavar="N",
                   help="blocks per re-simulation deriving an option's effect (ditch profiles; default 20,000)")
    p.add_argument("--road-collector", default=None,
                   help="collector at the road: P(road | barrier) from the simulation (default 'road')")
    p.add_argument("--risk-tolerance", type=float, default=None,
                   help="exponential-utility risk tolerance for tree rollback (default: expected values)")
    _add_inventory_arguments(p)
    _add_energy_arguments(p)
    _add_out_dir(p, "./decision")
    p.set_defaults(func=cmd_decide)


def _add_assess_parser(sub) -> None:
    """Add the sub-command assess: the whole chain for one site file.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("assess", help="the whole chain for one site file: fits, simulation, energy, decision",
                       description="Run the whole assessment of one site described by a TOML file (see the docs: File "
                       "formats, 'Site files'): magnitude-frequency fits, trajectory simulation, impact-energy "
                       "hazard and fence checks, risk to road users and the ranking of mitigation options.  Writes "
                       "report.html (self-contained), summary.json, CSV tables, PNG figures and a copy of the inputs "
                       "with the version and seed; the directory appears only when everything succeeded.",
                       epilog=EPILOG)
    p.add_argument("site", help="site file (.toml); paths in it are relative to it")
    _add_out_dir(p, "<site>-assessment")
    p.add_argument("--seed", type=int, default=None, help="random seed (default: the site file's, else 1)")
    p.add_argument("-n", type=int, default=None, help="simulated blocks (default: the site file's, else 50,000)")
    p.set_defaults(func=cmd_assess)


def _add_demo_parser(sub) -> None:
    """Add the sub-command demo: the whole chain on the bundled example site.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("demo", help="run the whole chain on the bundled example site",
                       description="Run riskrf assess on the bundled example site: the real Lauterbrunnen "
                       "laser-scanning inventory (power law), the real Hong Kong rock-cut incident register 1984-2020 "
                       "(annual maxima), the shipped road-cut barrier scenario and illustrative traffic, costs and options. "
                       "Works from any directory; takes well under a minute.", epilog=EPILOG)
    _add_out_dir(p, "./riskrf-demo")
    p.add_argument("--seed", type=int, default=None, help="random seed (default 1)")
    p.add_argument("-n", type=int, default=None, help="simulated blocks (default 50,000)")
    p.set_defaults(func=cmd_demo)


def _add_calibrate_parser(sub) -> None:
    """Add the sub-command calibrate: fit scenario material parameters to observed stop points.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("calibrate", help="fit scenario material parameters to observed stop points",
                       description="Fit scenario values named by dotted paths (e.g. "
                       "materials.talus.ground_friction_angle_deg) within bounds so that simulated stop positions "
                       "match observed ones (1-Wasserstein distance, common random numbers, differential evolution, "
                       "bootstrap intervals; see the docs: Trajectories and simulation, 'Calibration').  Writes the "
                       "calibrated scenario TOML, parameter and comparison tables and a figure.", epilog=EPILOG)
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("observed", help="observed stops: CSV/Parquet/XLSX with an x_stop_m column [m along the profile]")
    p.add_argument("--parameter", action="append", metavar="NAME=LOW:HIGH",
                   help="dotted scenario path and bounds; repeat for several")
    p.add_argument("--select", action="append", metavar="COLUMN=VALUE",
                   help="use only rows of the observed file with this value (e.g. profile=P1); repeatable")
    p.add_argument("--column", default="x_stop_m", help="column of stop positions in m (default x_stop_m)")
    p.add_argument("--collector", default=None, help="collector where observed velocity_ms/height_m columns apply")
    p.add_argument("--distance", choices=("wasserstein", "cvm"), default="wasserstein",
                   help="distance between distributions (default wasserstein)")
    p.add_argument("-n", type=int, default=1000, help="simulated blocks per evaluation (default 1,000)")
    p.add_argument("--seed", type=int, default=1, help="random seed of every evaluation (default 1)")
    p.add_argument("--maxiter", type=int, default=20, help="differential-evolution generations (default 20)")
    p.add_argument("--bootstrap", type=int, default=200, help="bootstrap replicates (default 200; 0 to skip)")
    _add_out_dir(p, "<scenario>-calibration")
    _add_reader_arguments(p, "the observed stops", "")
    p.set_defaults(func=cmd_calibrate)


def _add_calibrate_pooled_parser(sub) -> None:
    """Add the sub-command calibrate-pooled: fit material parameters shared by many releases, with a posterior.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser(
        "calibrate-pooled", help="fit material parameters shared by many releases to all their stops (posterior)",
        description=textwrap.fill("Fit material parameters (dotted paths, uniform priors within bounds) shared by many "
        "releases, each on its own scenario with its own block, to all their observed stops: kernel likelihood "
        "of each stop under its release's simulated stops, common random numbers, a Sobol design and adaptive "
        "importance rounds, the posterior from a quadratic or Gaussian-process surrogate of the log-likelihood "
        "(ABC rejection as the last resort; the notes say which), and a predictive check per release.  Writes "
        "the posterior sample (read back by simulation.read_posterior and the model-uncertainty inputs), "
        "its summary, correlations, the evaluations, the predictive coverage and figures.  See the docs: "
        "Trajectories and simulation, 'Pooled calibration'.", 100),
        epilog="Example (the 89 Authume quarry blocks, each its own release on its profile's section):\n"
        "  riskrf calibrate-pooled tests/data/authume/observed_runout.csv --release-column profile,block \\\n"
        "    --scenario-column profile --scenario P1=simulation/scenarios/authume/authume_p1.toml \\\n"
        "    --scenario P2=simulation/scenarios/authume/authume_p2.toml \\\n"
        "    --parameter materials.vegetated_slope.ground_friction_angle_deg=3:45 --n-per-release 50\n" + EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("releases", help="CSV, one row per observed block: release name, scenario name, x_stop_m [m], "
                   "optionally mass_kg, radius_m, shape, aspect_ratio, x_m, height_m, vx_ms, vz_ms, "
                   "downslope_speed_ms (one value per release)")
    p.add_argument("--scenario", action="append", metavar="NAME=FILE",
                   help="scenario TOML of the releases whose scenario column says NAME; repeat for each")
    p.add_argument("--parameter", action="append", metavar="NAME=LOW:HIGH",
                   help="dotted material path and its uniform prior's bounds; repeat for several")
    p.add_argument("--release-column", default="release", metavar="COL[,COL]",
                   help="column naming the release, or several (comma-separated) that together name it "
                        "(default release)")
    p.add_argument("--scenario-column", default="scenario", metavar="COL",
                   help="column holding the scenario name (default scenario)")
    p.add_argument("--n-per-release", type=int, default=200,
                   help="simulated blocks per release and parameter set (default 200)")
    p.add_argument("--iterations", type=int, default=3, help="adaptive importance rounds (default 3)")
    p.add_argument("--posterior", type=int, default=2000, help="size of the posterior sample (default 2,000)")
    p.add_argument("--predictive", type=int, default=40,
                   help="posterior draws simulated for the predictive check (default 40; 0 to skip)")
    p.add_argument("--seed", type=int, default=1, help="seed of the simulations, design and sampling (default 1)")
    _add_out_dir(p, "<releases>-pooled-calibration")
    p.set_defaults(func=cmd_calibrate_pooled)


def _add_rates_parser(sub) -> None:
    """Add the sub-command rates: rate regressions on rainfall, season and trend, and closure rules.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("rates", help="rock fall rates against rainfall, season and trend (Poisson / negative binomial)",
                       description="Count the events of a dated inventory per day, month or year and fit Poisson and "
                       "negative-binomial regressions on antecedent rainfall, season and a year trend (see the docs: "
                       "Rates and rainfall).  Prints the model comparison (AIC, deviance, overdispersion tests), "
                       "rate ratios with intervals, the trend test and expected rates by month; writes CSV tables and "
                       "the figures seasonality.png and rainfall_response.png.", epilog=EPILOG)
    p.add_argument("inventory", help="dated inventory file with its record period (sidecar .toml or --start/--end)")
    p.add_argument("--rainfall", required=True, metavar="FILE",
                   help="daily rainfall: the Hong Kong Observatory file, or a CSV with date,rainfall_mm")
    _add_inventory_arguments(p)
    p.add_argument("--period", choices=("day", "month", "year"), default="day", help="counting period (default day)")
    p.add_argument("--windows", default="1,3,15", metavar="D1,D2,...",
                   help="antecedent rainfall bands for daily counts as window lengths in days (default 1,3,15: "
                        "the day, the 2 days before, days 3-14 before)")
    p.add_argument("--rain-transform", choices=("linear", "sqrt", "log1p"), default="linear",
                   help="rainfall in the model: linear (rate ratio per 100 mm; default), sqrt or log1p "
                        "(rate ratio of 100 mm against none)")
    p.add_argument("--season", choices=("harmonic", "wet", "month", "none"), default="harmonic",
                   help="season terms (default harmonic: annual sine and cosine)")
    p.add_argument("--no-trend", action="store_true", help="leave out the year trend")
    p.add_argument("--closure-mm", type=float, action="append", metavar="MM",
                   help="evaluate a closure rule: close the road on days whose rainfall over --closure-window days "
                        "reaches MM (daily models; repeat for several thresholds)")
    p.add_argument("--closure-window", type=int, default=1, metavar="DAYS", help="closure rule window (default 1)")
    p.add_argument("--warnings", default=None, metavar="FILE",
                   help="Hong Kong Observatory rainstorm warning list: evaluate closing under Red or Black warnings")
    p.add_argument("--cost-per-hour", type=float, default=0.0, metavar="MONEY",
                   help="cost of one hour of closure, for the closure rules (default 0)")
    p.add_argument("--heavy-day-mm", type=float, default=None, metavar="MM",
                   help="with --heavy-day-change: daily rainfall of a heavy-rain day")
    p.add_argument("--heavy-day-change", type=float, default=None, metavar="SHARE",
                   help="expected rate if heavy-rain days became this much more frequent (0.1 = +10%%; an assumption)")
    _add_out_dir(p, "<inventory>-rates")
    _add_reader_arguments(p, "the --rainfall table (generic layout)", "", dates=True, prefix="rainfall")
    p.set_defaults(func=cmd_rates)


def _add_corridor_parser(sub) -> None:
    """Add the sub-command corridor: screen and assess the sections of a road corridor on dask.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("corridor", help="screen and assess many sections along a road (RHRS + risk, on dask)",
                       description="Read a corridor file (TOML with defaults, mass law, traffic, costs and options, "
                       "naming a sections table) and check every row first; then run each section's chain "
                       "(simulation, energy hazard, road-user risk, option ranking) as a task on dask.distributed: "
                       "a local cluster sized to the machine by default, or an existing scheduler unchanged.  "
                       "Writes report.html, corridor.csv (ranked by risk beside the RHRS rank), sections.csv, "
                       "budget_curve.csv, chainage.png, rating_sheets.html and summary.json; with a centreline "
                       "sections.gpkg and map.png; with --budget programme.csv, frontier.csv and frontier.png (see "
                       "the docs: Corridor, and Corridor programmes).", epilog=EPILOG)
    p.add_argument("corridor", help="corridor file (.toml); paths in it are relative to it")
    _add_out_dir(p, "<corridor>-corridor")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="address of an existing dask scheduler (default: DASK_SCHEDULER_ADDRESS, else a local cluster)")
    p.add_argument("--workers", type=int, default=None, help="workers of the local cluster (default: one per core)")
    p.add_argument("-n", type=int, default=None, help="simulated blocks per section (default: the corridor file's)")
    p.add_argument("--keep-going", action="store_true", help="skip bad rows and failed sections, listing them")
    p.add_argument("--resume", action="store_true", help="skip sections already finished by an earlier run")
    p.add_argument("--budget", type=float, default=None, metavar="AMOUNT",
                   help="choose one option (or none) per section to get the most within AMOUNT (corridor currency), "
                        "exactly (mixed-integer programme); writes programme.csv, frontier.csv and frontier.png")
    p.add_argument("--budget-basis", choices=("total", "year"), default="total",
                   help="what --budget caps: 'total' the capital paid now (default), 'year' the equivalent annual "
                        "cost (present value of capital, renewals and maintenance as a level cost per year)")
    p.add_argument("--objective", choices=("alarp", "risk", "cost"), default="alarp",
                   help="'alarp' (default): fund the sections above the intolerable individual-risk line whatever "
                        "they cost, then maximise the net benefit at the corridor's VSL with the gross-disproportion "
                        "factor (--gdf); 'risk': maximise deaths avoided per year; 'cost': minimise the expected "
                        "total cost.  The other objective's programme is reported beside it")
    p.add_argument("--gdf", type=float, default=None, metavar="FACTOR",
                   help="ALARP gross-disproportion factor (>= 1) of --objective alarp: fund a section while its cost "
                        "is at most FACTOR times what it is worth at the VSL (default: [criteria] "
                        "disproportion_factor of the corridor file, else 1)")
    _add_reader_arguments(p, "the sections table", "corridor.sections_")
    p.set_defaults(func=cmd_corridor)


def _add_hazard_map_parser(sub) -> None:
    """Add the sub-command hazard-map: 3-D hazard rasters of a scenario on a DEM.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("hazard-map", help="3-D rock fall hazard rasters on a DEM (GeoTIFF, GeoPackage)",
                       description="Run a 3-D scenario (TOML with a [terrain] table: DEM raster, materials, "
                       "[sources] points or polygon, plan collectors) and write GeoTIFFs on the DEM's grid and CRS "
                       "(passage count, reach probability, kinetic energy p50/p95/p99/max, jump height p95, "
                       "deposition density; with --rate-per-year the energies at annual frequencies 1/30, 1/100, "
                       "1/300), stop points and trajectories as GeoPackage layers and a hillshade figure.",
                       epilog=EPILOG)
    p.add_argument("scenario", help="3-D scenario TOML, e.g. simulation/scenarios/authume/authume_3d.toml")
    _add_release_arguments(p, 10_000)
    p.add_argument("--crs", default=None, help="the DEM's CRS when its file has none, e.g. EPSG:2154")
    p.add_argument("--workers", type=int, default=1, help="threads running the kernel, or with --dask the local "
                   "cluster's worker processes (results do not depend on it)")
    p.add_argument("--dask", action="store_true", help="tile the sources and run the tiles on dask.distributed "
                   "(a LocalCluster of --workers, or --scheduler / DASK_SCHEDULER_ADDRESS); same rasters")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", help="a dask scheduler to run the tiles on "
                   "(implies --dask)")
    p.add_argument("--tile-m", type=float, default=250.0, help="tile size: squares of release points [m] "
                   "(default 250; results do not depend on it)")
    p.add_argument("--rate-per-year", type=float, default=None, metavar="R", help="annual rate of releases from "
                   "the scenario's sources [1/year] the blocks stand for: adds the intensity-frequency layers "
                   "energy_1in30_kj, energy_1in100_kj, energy_1in300_kj (energy reached or exceeded with annual "
                   "frequency 1/30, 1/100, 1/300 per cell; nodata where too few blocks pass)")
    _add_out_dir(p, "<scenario>-hazard-map")
    p.set_defaults(func=cmd_hazard_map)


def _add_profile_parser(sub) -> None:
    """Add the sub-command profile: cut a 2-D slope profile from a DEM along a plan polyline.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command registry of :func:`build_parser`.
    """
    p = sub.add_parser("profile", help="cut a 2-D slope profile from a DEM raster along a plan polyline",
                       description="Sample a DEM (GeoTIFF, ESRI ASCII grid) every --spacing metres along a plan "
                       "polyline (bilinear, the surface the 3-D simulator uses) and write the [profile] table of a "
                       "2-D scenario.  A path leaving the DEM or crossing a nodata hole is refused, naming the "
                       "distance.", epilog=EPILOG)
    p.add_argument("dem", help="DEM raster file")
    p.add_argument("--path", nargs="+", required=True, metavar="X,Y",
                   help="plan vertices of the section, top of the slope first, in the DEM's CRS")
    p.add_argument("--spacing", type=float, default=None, help="vertex spacing [m] (default: the DEM's cell size)")
    p.add_argument("--material", default="talus", help="material name given to every segment (default talus)")
    p.add_argument("--crs", default=None, help="the DEM's CRS when its file has none, e.g. EPSG:2154")
    p.add_argument("--out", default=None, metavar="FILE", help="output TOML (default <dem>-profile.toml)")
    p.set_defaults(func=cmd_profile)


def build_parser() -> argparse.ArgumentParser:
    """The ``riskrf`` argument parser with one sub-command per task.

    Returns
    -------
    argparse.ArgumentParser
        The parser.
    """
    parser = argparse.ArgumentParser(
        prog="riskrf", description="Rock fall hazard, risk and mitigation decisions (after Wyllie 2014, "
        "Rock Fall Engineering, chapters 3-8).  Start with 'riskrf demo' (the whole chain on a bundled site, "
        "report in ./riskrf-demo/report.html), then copy riskrf/data/demo_site.toml, point it at your inventory "
        "and slope, and run 'riskrf assess your_site.toml'.  Each step also runs alone: fit -> simulate -> "
        "energy -> decide.", epilog=EPILOG)
    parser.add_argument("--version", action="version", version=f"riskrf {__version__}")
    parser.add_argument("--debug", action="store_true", help="show the full traceback of an error")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    _add_fit_parser(sub)
    _add_simulate_parser(sub)
    _add_energy_parser(sub)
    _add_decide_parser(sub)
    _add_assess_parser(sub)
    _add_demo_parser(sub)
    _add_calibrate_parser(sub)
    _add_calibrate_pooled_parser(sub)
    _add_rates_parser(sub)
    _add_corridor_parser(sub)
    _add_hazard_map_parser(sub)
    _add_profile_parser(sub)

    for p in sub.choices.values():       # every command with outputs: never clobber without --overwrite
        if any("--out" in a.option_strings for a in p._actions):
            p.add_argument("--overwrite", action="store_true",
                           help="replace an existing --out (whole, atomically); without it an existing output is "
                                "refused before any work")
    return parser


def cmd_rates(args) -> int:
    """``riskrf rates``: fit the rate model of falls (Poisson and negative binomial regressions on rainfall
    over ``--windows`` days, season and trend) and write its tables and figures.  Returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..io.outputs import atomic_output_dir
    from ..frequency.rates import rate_model

    try:
        windows = tuple(int(w) for w in args.windows.split(","))
    except ValueError:
        raise ValueError(f"--windows {args.windows!r}: give whole numbers of days separated by commas") from None
    if args.period != "day" and (args.closure_mm or args.warnings or args.heavy_day_change is not None):
        raise ValueError(f"--period {args.period}: closure rules (--closure-mm, --warnings) and --heavy-day-change "
                         "need a daily model (--period day)")
    if (args.heavy_day_change is None) != (args.heavy_day_mm is None):
        raise ValueError("give --heavy-day-mm and --heavy-day-change together")
    from ..app.preflight import check_inventory_args, check_out, check_rates_args
    check_rates_args(args, windows)
    check_inventory_args(args)
    out = check_out(args, f"{Path(args.inventory).stem}-rates")
    from ..io.rainfall import read_rainfall
    rainfall = read_rainfall(args.rainfall, **{k: getattr(args, f"rainfall_{k}") for k in
                                               ("sheet", "header_row", "decimal", "encoding", "date_format")})
    inv = _read(args, args.inventory)
    model = rate_model(inv, rainfall, period=args.period, windows_days=windows,
                       season=None if args.season == "none" else args.season, trend=not args.no_trend,
                       rain_transform=args.rain_transform)
    print(model.summary_text())
    if args.heavy_day_change is not None:
        base = model.expected_annual_rate()
        changed = model.expected_annual_rate(heavy_day_mm=args.heavy_day_mm, heavy_day_change=args.heavy_day_change)
        print(f"\nStated change of climate (ASSUMPTION): days with >= {args.heavy_day_mm:g} mm "
              f"{args.heavy_day_change:+.0%} as frequent: {changed:.4g} events per year against {base:.4g} "
              f"({changed / base - 1:+.1%})")
    rules = []
    if args.closure_mm or args.warnings:
        from ..risk.closure import closure_rule, warning_closure
        rules = [closure_rule(model, mm, window_days=args.closure_window, cost_per_hour=args.cost_per_hour)
                 for mm in (args.closure_mm or [])]
        if args.warnings:
            rules.append(warning_closure(model, args.warnings, levels=("Red", "Black"),
                                         cost_per_hour=args.cost_per_hour))
        import pandas as pd
        table = pd.concat([r.summary()["value"].rename(f"rule {i + 1}") for i, r in enumerate(rules)], axis=1)
        print("\nClosure rules (effectiveness = share of falls while closed, from the rate model):")
        print(table.to_string())
    from ..report.rate_figures import write_rate_study
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        write_rate_study(model, tmp)
        if rules:
            pd.concat([r.summary()["value"].rename(f"rule {i + 1}") for i, r in enumerate(rules)], axis=1).to_csv(
                tmp / "closure_rules.csv")
    print(f"\nWrote rate_ratios.csv, model_comparison.csv, design.csv, season.csv and figures to {out}/")
    return 0


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
    """The innermost riskrf or simulation function on the traceback of ``exc`` (module.function)."""
    tb, stage = exc.__traceback__, "?"
    while tb is not None:
        module = tb.tb_frame.f_globals.get("__name__", "")
        if module.split(".")[0] in ("riskrf", "simulation") and module != "riskrf.cli":
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


def _caused_by_interrupt(exc) -> bool:
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


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


if __name__ == "__main__":
    sys.exit(command())
