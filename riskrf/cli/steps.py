"""The single steps of the chain, each run alone: ``riskrf fit`` (magnitude-frequency fits), ``riskrf simulate``
(trajectories), ``riskrf energy`` (impact-energy hazard at a barrier line) and ``riskrf rates`` (rate model of
falls), with the inventory reader and the energy-hazard inputs that ``riskrf decide`` shares."""
from __future__ import annotations

import sys
from pathlib import Path


def _read(args, path):
    from ..frequency.inventory.reader import read_inventory
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
    from simulation.parameters import scenario_dict

    from ..hazard.trajectory_status import trajectory_model_status
    status = trajectory_model_status(scenario_dict(args.scenario)[0])
    if status.uncalibrated:
        print(status.text)
    tables = [result.collector(c.name).assign(collector=c.name) for c in scenario.collectors]
    crossings = pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()
    if "outcome" in crossings:
        crossings["outcome"] = crossings["outcome"].astype(str)
    from functools import partial

    from .runner import InBackground
    from ..report import files as report_files
    report_files.prepare_drawing()
    targets = [(path, "file") for path in outs] + [(figures, "dir")]
    # tables and figures appear together or not; an uncalibrated trajectory model is stamped on the figures
    with atomic_outputs(targets, overwrite=args.overwrite) as tmps, report_files.figure_note(status.figure_note):
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
    from ..app.assess.hazard import energy_hazard_from_inputs
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
    from ..hazard.energy_tornado import design_energy_tornado
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
    from ..frequency.rates.fit import rate_model

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
