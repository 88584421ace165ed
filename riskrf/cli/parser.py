"""The ``riskrf`` argument parser: one ``_add_*_parser`` per sub-command with its options and help texts
(:func:`build_parser`); the shared option groups (inventory reading, fits, energy inputs, outputs).  Nothing here
computes; each sub-command's ``func`` is its ``cmd_*`` in :mod:`riskrf.cli.steps`, :mod:`riskrf.cli.decisions` or
:mod:`riskrf.cli.studies`."""
from __future__ import annotations

import argparse
import textwrap

from .. import __version__
from ..core.units import DEFAULT_DENSITY_KG_M3
from .decisions import cmd_assess, cmd_decide, cmd_demo
from .steps import cmd_energy, cmd_fit, cmd_rates, cmd_simulate
from .studies import cmd_calibrate, cmd_calibrate_pooled, cmd_corridor, cmd_hazard_map, cmd_profile

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
