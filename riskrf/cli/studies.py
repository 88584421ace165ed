"""The study commands: ``riskrf calibrate`` and ``riskrf calibrate-pooled`` (material parameters fitted to observed
stops), ``riskrf corridor`` (every section of a road), ``riskrf hazard-map`` (3-D terrain rasters) and
``riskrf profile`` (a 2-D section cut from a DEM)."""
from __future__ import annotations

import math
import os
import shutil
import sys
import warnings
from pathlib import Path


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
    from simulation.pooled.fit import calibrate_pooled
    from simulation.pooled.releases import read_releases

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
