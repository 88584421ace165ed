"""The declarations of riskrf's four input files (site, mitigation options, corridor, slope scenario).

One :class:`~riskrf.core.schema.Field` per field: type, unit, range, default, meaning.  The defaults here are
the ones the readers apply (:data:`riskrf.app.site.SITE_FIELDS` is built from :data:`SITE_SCHEMA`; a test holds
the mitigation dataclasses' defaults to :data:`TRAFFIC` and the others), and the typed records a site's checked tables
are read into are generated from them (:data:`SITE_RECORDS`, :meth:`riskrf.core.schema.Table.record`).  Shares and probabilities lie in
[0, 1]; rates, speeds, lengths and traffic are > 0.
"""
from __future__ import annotations

from .schema import REQUIRED, Field, FileSchema, Table
from .validation import DEFAULT_DENSITY_KG_M3, DENSITY_RANGE_KG_M3


def _num(name, unit="", doc="", default=None, **bounds):
    return Field(name, "number", unit, doc, default, **bounds)


def _pos(name, unit="", doc="", default=None):
    return Field(name, "number", unit, doc, default, low=0, low_open=True)


def _nonneg(name, unit="", doc="", default=None):
    return Field(name, "number", unit, doc, default, low=0)


def _share(name, doc="", default=None):
    return Field(name, "number", "", doc, default, low=0, high=1)


def _count(name, doc="", default=None, low=1):
    return Field(name, "integer", "", doc, default, low=low)


def _text(name, doc="", default=None, choices=()):
    return Field(name, "text", "", doc, default, choices=choices)


def _path(name, doc="", default=None):
    return Field(name, "path", "", doc, default)


READER_FIELDS = (
    Field("sheet", "any", "", "Excel sheet: name, or number counting from 1"),
    _count("header_row", "1-based row holding the column names"),
    _text("encoding", "text encoding (default UTF-8, else cp1252 with a note)"),
    _text("decimal", "decimal mark (default: decided per column)", choices=(".", ",")),
    _text("date_format", "strftime pattern of every date, e.g. %d/%m/%Y"),
    _text("volume_unit", "unit of the volume column", choices=("m3", "dm3", "l", "litre", "cm3")),
    _text("mass_unit", "unit of the mass column", choices=("kg", "t", "tonne", "tonnes", "tons")),
    _text("duplicates", "repeated dated rows", choices=("warn", "drop", "keep", "error")),
    _text("volume_column", "volume column when not recognised"),
    _text("mass_column", "mass column when not recognised"),
    _text("date_column", "date column when not recognised"),
    _text("location_column", "location column when not recognised"),
)

SITE = Table("site", (_text("name", "shown in the report (default: the file name)"),
                      _text("description", "shown in the report", default="")),
             "What the site is.")

INVENTORY = Table("inventory", (
    _path("path", "the rock fall inventory (CSV, Excel or Parquet)", default=REQUIRED),
    Field("start", "date", "", "start of the record period (else the sidecar, else the first date)"),
    Field("end", "date", "", "end of the record period"),
    _pos("duration_years", "yr", "length of the record, for undated inventories"),
    _num("density_kg_m3", "kg/m3", "rock density (default: the sidecar, else 2,650, reported)",
         low=DENSITY_RANGE_KG_M3[0], high=DENSITY_RANGE_KG_M3[1]),
    _pos("m_min_kg", "kg", "completeness threshold of the power law (default: Clauset et al. 2009)"),
    _pos("m_max_kg", "kg", "maximum credible block (upper truncation)"),
    _num("rate_scale", "", "share of the inventoried rock face above this road (0.05 = 5 %)", default=1.0,
         low=0, high=1, low_open=True),
    _path("annual_maxima", "a dated inventory for the Gumbel/GEV section"),
    _text("rate_basis", "what the inventory's rate counts: falls released, or falls recorded on the road",
          default="release", choices=("release", "road")),
    _text("sizes", "what the sizes are (default: the sidecar's, else event_volumes)",
          choices=("event_volumes", "blocks")),
    *READER_FIELDS,
    _text("rate_from", "where the hazard's rate of falls comes from", default="inventory",
          choices=("inventory", "rate_model")),
    _pos("rain_factor", "", "stated change of the rate model's rain response (an assumption)"),
    _pos("heavy_day_mm", "mm", "daily rainfall of a heavy-rain day"),
    _num("heavy_day_change", "", "change of the heavy-rain days' frequency (0.1 = +10 %)", low=-1, low_open=True),
), "The rock fall inventory and how to read it (each reader option may also be in the inventory's sidecar).")

HAZARD = Table("hazard", (
    _path("scenario", "slope scenario to simulate (give this or velocities)"),
    _path("velocities", "velocity samples at the barrier line (give this or scenario)"),
    _text("collector", "the barrier line's collector (default 'barrier' with a scenario)"),
    _text("road_collector", "the road's collector", default="road"),
    _count("n_blocks", "simulated blocks", default=50_000),
    Field("reach_probability", "number", "", "with velocities: probability that a fall reaches the line", 1.0,
          low=0, high=1, low_open=True),
    Field("fences_kj", "numbers", "kJ", "candidate fence capacities (MEL)", [2000.0, 5000.0], low=0,
          low_open=True),
    Field("fence_height_m", "number|numbers", "m", "fence height, or one per fence", 5.0, low=0, low_open=True),
    _nonneg("free_board_m", "m", "free board above the p95 bounce height (UNI 11211-4)", default=0.5),
    _num("design_period_years", "yr", "return period of the fence checks", default=100.0, low=1, low_open=True),
    _count("bootstrap", "bootstrap replicates of the intervals", default=300),
    _count("seed", "random seed", default=1, low=0),
    _count("option_blocks", "blocks per re-simulation of an option", default=20_000),
    _text("mass_coupling", "reach and speed by block mass, or one law for all", default="simulated",
          choices=("simulated", "independent")),
    _text("velocity_unit", "unit of the velocity file", choices=("m/s", "km/h")),
    _pos("drop_height_m", "m", "release to the barrier line, for the velocity plausibility check"),
), "Where the velocities come from and what is checked at the barrier line.")

DESIGN_BLOCK = Table("design_block", (
    _text("rule", "how the design block is chosen", default="return_period",
          choices=("return_period", "percentile", "fragmentation")),
    _num("percentile", "%", "percentile of the block sizes (ONR 24810: 95-98)", default=97.0, low=0, high=100,
         low_open=True, high_open=True),
    _path("survey", "block survey (volume_m3 or mass_kg)"),
    _num("fractal_dimension", "", "fractal dimension of the fragments (Perfect 1997)", low=0, high=3,
         low_open=True, high_open=True),
    _count("iterations", "fragmentation generations (1-12)"),
), "The design block (ONR 24810, UNI 11211-4).")

DESIGN = Table("design", (
    _text("basis", "the standard that governs the barrier design (riskrf.hazard.design_basis)",
          default="UNI 11211-4"),
    _pos("frequent_T_years", "years", "return period of the frequent event: ONR 24810's frequent design block, and "
         "the energy of the owner option frequent_events_sel", default=30.0),
    Field("frequent_events_sel", "bool", "", "OWNER OPTION, not in UNI 11211-4 or ONR 24810: the frequent_T_years "
          "impact energy must not exceed SEL = MEL/3", False),
    _text("residual_category", "OWNER OPTION: residual-height category required of the kit (EAD 340059 categories)",
          default="A", choices=("A", "B", "C")),
    _text("consequence_class", "ONR 24810 consequence class (EN 1990); flagged in every output when not stated",
          choices=("CC1", "CC2", "CC3")),
    _pos("clearance_m", "m", "clearance from the barrier to the road, for the elongation check"),
    Field("mel_classes_kj", "numbers", "kJ", "the product classes searched for the required MEL", low=0,
          low_open=True),
    Field("elongation_m", "any", "m", "the kits' maximum elongation at MEL: one number for every fence, or a table "
          "{fence name = metres}"),
    Field("positions_x_m", "numbers", "m", "barrier positions searched along the profile"),
    _count("position_blocks", "blocks simulated for the position search", low=100),
    *(_pos(g, "", f"partial factor {g} (default: the basis's value, flagged in every output)")
      for g in ("gamma_Tr", "gamma_Dp", "gamma_VolF", "gamma_gamma", "gamma_E", "gamma_d", "gamma_m", "gamma_v")),
    _num("velocity_percentile", "%", "velocity percentile of the design", low=0, high=100, low_open=True,
         high_open=True),
    _num("height_percentile", "%", "bounce-height percentile of the design", low=0, high=100, low_open=True,
         high_open=True),
), "The design basis that governs the barrier design, its partial factors and the required-barrier search.")

REQUIRED_BARRIER = Table("required_barrier", (
    Field("include", "bool", "", "rank the barrier the design basis requires as an option", True),
    Field("cost_classes_kj", "numbers", "kJ", "MEL classes of the unit prices (default: riskrf's ASSUMED price "
          "table, riskrf.risk.required_barrier.DEFAULT_COST_PER_M, scaled to the site's own fence prices)", low=0,
          low_open=True),
    Field("cost_per_m", "numbers", "currency/m", "unit price per metre of barrier at reference_height_m, one per "
          "class", low=0, low_open=True),
    _pos("reference_height_m", "m", "net height the unit prices refer to", default=5.0),
    _nonneg("height_exponent", "", "a price scales as (net height / reference_height_m)^height_exponent",
            default=1.0),
    _pos("length_m", "m", "barrier length (default: traffic.exposed_length_m)"),
    _nonneg("fixed_cost", "currency", "access and mobilisation", default=0.0),
    _nonneg("annual_maintenance_share", "1/yr", "yearly maintenance as a share of the capital cost", default=0.01),
    _pos("life_years", "years", "renewal period", default=25.0),
    _nonneg("repair_share", "", "repair of an impact held above SEL, as a share of the capital cost", default=0.05),
    _nonneg("replacement_share", "", "rebuild after an impact above MEL, as a share of the capital cost",
            default=0.3),
    Field("cost_range", "range", "", "capital cost range as factors of the central cost", (0.7, 1.5), low=0,
          low_open=True),
    _pos("max_net_height_m", "m", "tallest catalogue net: a position needing more is not placeable", default=8.0),
), "The barrier the design basis requires, costed and ranked (riskrf.risk.required_barrier); the defaults are "
   "ASSUMED and labelled in every output.")

REPORT = Table("report", (
    _text("project", "project name in the title block"),
    _text("location", "site location in the title block"),
    _text("revision", "revision in the title block", default="A"),
    Field("date", "any", "", "date in the title block (default: the run's date)"),
    _text("author", "author in the title block", default="not stated"),
    _text("checker", "checker in the title block", default="not stated"),
    _text("client", "client in the title block"),
), "The report's title block (report.pdf, report.html).")

RATES = Table("rates", (
    _path("record", "dated inventory the rate model counts (default: inventory.path)"),
    Field("start", "date", "", "start of that record"),
    Field("end", "date", "", "end of that record"),
    _path("rainfall", "daily rainfall (Hong Kong Observatory file, or date,rainfall_mm)"),
    _path("warnings", "rainstorm warning list"),
    _text("period", "counting period", default="day", choices=("day", "month", "year")),
    Field("windows_days", "numbers", "days", "antecedent rainfall windows", [1, 3, 15], low=1),
    _text("rain_transform", "rainfall in the model", default="linear", choices=("linear", "sqrt", "log1p")),
    _text("season", "season terms", default="harmonic", choices=("harmonic", "wet", "month", "none")),
    Field("trend", "bool", "", "a year trend", True),
), "The rate model of falls against rainfall, season and trend (riskrf rates).")

TRAFFIC = Table("traffic", (
    _pos("vehicles_per_day", "vehicles/day", "average daily traffic", default=4000.0),
    _pos("vehicle_length_m", "m", "vehicle length L_v (Bunce et al. 1997)", default=5.0),
    _pos("speed_kmh", "km/h", "posted speed", default=80.0),
    _num("occupants_per_vehicle", "persons", "mean occupants (the driver counts)", default=1.5, low=1),
    _nonneg("commuter_trips_per_day", "trips/day", "trips of the individual most at risk", default=2.0),
    _nonneg("hours_rock_on_road", "h", "until a rock on the road is removed or signalled", default=0.5),
    _share("p_cannot_stop", "probability that a driver cannot stop within sight distance", default=0.002),
    _share("share_stopping_on_road", "share of falls reaching the road that stay on it", default=0.3),
    _pos("exposed_length_m", "m", "length of road below the slope", default=100.0),
    Field("occupants_distribution", "any", "", "probabilities of 1, 2, ... occupants"),
    _count("lanes", "lanes carrying the traffic (half each way)", default=2),
    _share("directional_split", "share of the traffic in the first direction", default=0.5),
    Field("lane_fall_shares", "numbers", "", "share of falls landing in each lane", low=0, high=1),
), "Traffic on the exposed road (Bunce et al. 1997; Wyllie 2014 chapter 8).")

CONSEQUENCES = Table("consequences", (
    _nonneg("value_of_statistical_life", "currency", "value of a statistical life", default=5.0e6),
    Field("vulnerability_moving_vehicle", "any", "", "probability of death, or [[mass_kg, probability], ...]"),
    Field("vulnerability_striking_rock", "any", "", "probability of death, or [[mass_kg, probability], ...]"),
    _nonneg("vehicle_damage", "currency", "damage to a vehicle hit", default=25000.0),
    _nonneg("closure_days_per_fall", "days", "road closed per fall reaching it", default=0.5),
    _nonneg("closure_cost_per_day", "currency/day", "the agency's cost of a closed day", default=20000.0),
    _nonneg("detour_hours", "h", "each road user's detour while closed", default=0.0),
    _nonneg("value_of_time_per_hour", "currency/h", "value of a vehicle-hour", default=0.0),
    _nonneg("cleanup_cost_per_fall", "currency", "clean-up per fall reaching the road", default=3000.0),
    _text("currency", "currency label of every amount", default="CHF"),
), "Costs of consequences and vulnerabilities.")

ECONOMICS = Table("economics", (
    _num("discount_rate", "1/yr", "discount rate (0.03 = 3 % a year)", default=0.03, low=0, high=1, high_open=True),
    _pos("horizon_years", "yr", "period over which costs and losses are counted", default=50.0),
), "Discounting (Wyllie 2014, 8.5.5).")

CRITERIA = Table("criteria", (
    _text("set", "criteria set (riskrf.risk.tolerability.CRITERIA_SETS, or 'user')", default="hong-kong-geo-1998"),
    _text("slope", "existing or new slope (the set's limit)", default="existing"),
    _num("individual_risk_per_year", "1/yr", "tolerable individual risk (default: the set's limit)", low=0,
         high=1, low_open=True),
    _text("fn_diagram", "the societal (F-N) criterion (default: the set's name)"),
    _pos("fn_c", "1/yr", "F-N line: frequency of one or more deaths ('user' set)"),
    _pos("fn_k", "", "F-N line: slope", default=1.0),
    _pos("fn_acceptable_c", "1/yr", "F-N acceptable line ('user' set)"),
    _pos("marginal_cost_per_life", "currency", "cost per statistical life saved of the ALARP test"),
    _num("disproportion_factor", "", "ALARP: a measure is reasonably practicable up to this factor", default=1.0,
         low=0, low_open=True),
), "Tolerability criteria.")

OPTIONS = Table("options", (
    _text("name", "the option's name", default=REQUIRED),
    _text("kind", "what the option is", default=REQUIRED,
          choices=("none", "scaling", "ditch", "fence", "attenuator", "shed", "realignment", "closure", "combined",
                   "bench", "bund", "drape")),
    _nonneg("capital_cost", "currency", "cost to build (required except for combined)"),
    _nonneg("annual_maintenance", "currency/yr", "maintenance per year", default=0.0),
    _pos("life_years", "yr", "service life (renewed at its end)"),
    _nonneg("repair_cost_per_impact", "currency", "repair per held impact between SEL and MEL", default=0.0),
    _nonneg("replacement_cost", "currency", "rebuilding after an impact above capacity"),
    _nonneg("repair_days", "days", "out of service after a destroying impact"),
    _share("rate_reduction", "typed share of falls removed (an ASSUMPTION)"),
    _share("retention", "typed share of falls stopped (an ASSUMPTION)"),
    _share("effectiveness", "scaling: share of the loose blocks actually removed (an ASSUMPTION)"),
    _pos("effectiveness_half_life_years", "yr", "scaling: half-life of its effect"),
    Field("effectiveness_range", "range", "", "[low, high] shares", low=0, high=1),
    _nonneg("x_m", "m", "position along the profile (a fence's line; the upslope edge of a ditch, bench or bund)"),
    _pos("width_m", "m", "ditch, bench or bund width along the profile"),
    _pos("depth_m", "m", "ditch depth"),
    _text("kit", "fence or attenuator: a kit of riskrf/data/barrier_kits.csv (its MEL, SEL, nominal height, "
          "maximum elongation and residual category enter the design checks)"),
    _pos("capacity_kj", "kJ", "barrier capacity (MEL)"),
    _pos("height_m", "m", "barrier height; bund crest height above the ground"),
    _pos("min_mass_kg", "kg", "smallest block scaling removes"),
    _pos("max_mass_kg", "kg", "largest block scaling removes; drape: largest block the mesh contains (default: a "
         "1.0 m sphere, ASSUMED)"),
    _pos("covered_length_m", "m", "length of road a shed covers"),
    _nonneg("road_x_m", "m", "position of the road for a realignment"),
    _pos("inner_slope_hv", "", "ditch inner slope, bench back wall or bund upslope face, horizontal to vertical"),
    _pos("outer_slope_hv", "", "ditch outer slope or bund road-side face, horizontal to vertical"),
    _text("material", "ditch or bench floor, bund fill (a material of the scenario; default: the ground's)"),
    _text("description", "shown in the report"),
    _share("share_while_closed", "typed share of falls while the road is closed (an ASSUMPTION)"),
    _nonneg("closure_hours_per_year", "h/yr", "typed hours closed per year (an ASSUMPTION)"),
    _nonneg("cost_per_closure_hour", "currency/h", "cost of one hour of closure", default=0.0),
    _pos("threshold_mm", "mm", "closure rule: rainfall over window_days that closes the road"),
    _count("window_days", "closure rule: rainfall window in days"),
    Field("capital_cost_range", "range", "currency", "[low, high] for the uncertainty study", low=0),
    Field("annual_maintenance_range", "range", "currency/yr", "[low, high]", low=0),
    Field("retention_range", "range", "", "[low, high] shares", low=0, high=1),
    Field("rate_reduction_range", "range", "", "[low, high] shares", low=0, high=1),
    Field("zone_x_m", "range", "m", "scaling zone, or the draped zone of the rock face, along the profile", low=0),
    _share("containment", "drape: share of the blocks released under the mesh it keeps on the face (an ASSUMPTION; "
           "default 0.85, ASSUMED)"),
    Field("containment_range", "range", "", "drape: [low, high] of the containment (default [0.7, 0.95], ASSUMED)",
          low=0, high=1),
), "Mitigation options (each compared with the others by expected total cost).", array=True)

UNCERTAINTY = Table("uncertainty", (
    _count("samples", "joint samples of the uncertain inputs", default=1000),
    _count("seed", "random seed", default=1, low=0),
    Field("rate_factor", "range", "", "rate of falls relative to the estimate", [1.0, 1.0], low=0, low_open=True),
    Field("m_max_kg", "range", "kg", "maximum credible block (log-uniform)", low=0, low_open=True),
    Field("value_of_statistical_life", "range", "currency", "[low, high]", low=0, low_open=True),
    Field("vulnerability_factor", "range", "", "multiplies both vulnerability curves", [1.0, 1.0], low=0),
    Field("vehicles_per_day", "range", "vehicles/day", "[low, high]", low=0, low_open=True),
    Field("discount_rate", "range", "1/yr", "[low, high]", low=0, high=1, high_open=True),
    _count("material_draws", "re-simulations with drawn material parameters", default=8),
    _count("draw_blocks", "blocks of each of those re-simulations (default: [hazard] option_blocks)"),
    Field("sample_power_law", "bool", "", "sample b and the rate from their posteriors", True),
    Field("sample_retention", "bool", "", "sample derived retentions", True),
    _count("ensemble_replicates", "repeated trajectory ensembles of the error budget (0: off; else >= 2)",
           default=4, low=0),
    Field("ensemble_effort", "number", "", "share of the blocks each repeated ensemble simulates", 0.25, low=0,
          high=1, low_open=True),
    Field("precision_target", "number", "", "adaptive effort: stop once every option's expected cost is known "
          "within +- this share (2 SE)", 0.05, low=0, high=1, low_open=True),
    _count("max_samples", "adaptive effort: budget of joint samples (default max(4000, samples))", low=2),
    _count("max_material_draws", "adaptive effort: budget of material re-simulations (default max(32, "
           "material_draws))", low=2),
), "Epistemic uncertainty, sampled jointly.")

MITIGATION_TABLES = (TRAFFIC, CONSEQUENCES, ECONOMICS, CRITERIA, OPTIONS, UNCERTAINTY)

MODEL_UNCERTAINTY = Table("model_uncertainty", (
    _path("posterior", "posterior sample of the scenario's material parameters (simulation.PooledCalibration.write); "
          "without it, the presets' spread (ASSUMED ranges, simulation.material_uncertainty)"),
    _count("draws", "draws of the material parameters, each re-simulated", default=8, low=2),
    _count("max_draws", "budget of draws: more are added (doubling) until the choice between calibrating first "
           "and deciding now is resolved (default 32, at least draws)", default=32, low=2),
    _count("n_blocks", "simulated blocks per draw (energy hazard and the seeder's run)", default=2000, low=100),
    _count("option_blocks", "blocks per re-simulation of an option, per draw", default=1000, low=100),
    _count("bootstrap", "bootstrap replicates of the design energies, per draw", default=100, low=10),
    _count("seed", "random seed of the draws, their simulations and the synthetic calibrations (default: "
           "hazard.seed)", low=0),
    _count("calibration_releases", "blocks released and observed in the field calibration whose value is "
           "computed", default=20, low=1),
    _nonneg("calibration_cost", "currency", "cost of that calibration (default: an ASSUMED 100,000 in the "
            "site's currency)"),
    _count("synthetic_calibrations", "synthetic calibrations per draw in the preposterior analysis", default=200),
    _pos("obs_error_m", "m", "observation error of a stop position (smallest kernel width)", default=0.5),
), "The trajectory model's uncertainty carried to the design energies and the ranking, and the value of a "
   "field calibration (off when the table is absent).")

SITE_SCHEMA = FileSchema("Site file (riskrf assess SITE.toml)",
                         (SITE, INVENTORY, HAZARD, DESIGN_BLOCK, DESIGN, REQUIRED_BARRIER, REPORT, RATES)
                         + MITIGATION_TABLES
                         + (MODEL_UNCERTAINTY,),
                         "One assessment: inventory, slope, exposure, options and economics.")
OPTIONS_SCHEMA = FileSchema("Mitigation options file (riskrf decide --options OPTIONS.toml)", MITIGATION_TABLES,
                            "The mitigation tables of a site file on their own.")

CORRIDOR_SCHEMA = FileSchema("Corridor file (riskrf corridor CORRIDOR.toml)", (
    CORRIDOR := Table("corridor", (
        _text("name", "shown in the report"),
        _text("description", "shown in the report"),
        _path("sections", "the sections table (CSV, Excel or Parquet)", default=REQUIRED),
        _count("seed", "random seed", low=0),
        _count("n_blocks", "simulated blocks per section", low=100),
        _count("option_blocks", "blocks per re-simulation of an option", low=100),
        _text("chainage_unit", "unit of the chainage columns", default="m", choices=("m", "km")),
        _text("rate_basis", "what the rate columns count", default="road", choices=("road", "release")),
        _num("rhrs_cap_points", "points", "cap of an RHRS category score", low=81),
        # choices = riskrf.risk.rhrs.VARIANTS (core imports nothing of riskrf; a test holds them equal)
        _text("rhrs_variant", "RHRS rating system: 'fhwa' (Pierson & Van Vickle 1993). 'odot' and 'colorado' are "
              "refused with what is missing: their published tables were not found", default="fhwa",
              choices=("fhwa",)),
        Field("sections_sheet", "any", "", "Excel sheet of the sections table"),
        _count("sections_header_row", "1-based header row of the sections table"),
        _text("sections_decimal", "decimal mark of the sections table", choices=(".", ",")),
        _text("sections_encoding", "text encoding of the sections table"),
        _path("centreline", "the road centreline (GeoPackage, GeoJSON or shapefile; projected CRS in metres)"),
        _text("centreline_layer", "layer of the centreline file holding the line"),
        _text("centreline_calibration_layer", "point layer of known chainage (same file)"),
        _text("centreline_calibration_field", "chainage field [m] of the calibration points", default="chainage_m"),
        _num("centreline_chainage_start_m", "m", "chainage of the line's first vertex (without calibration points)",
             default=0.0),
    ), "The corridor and its sections table."),
    CORRIDOR_DEFAULTS := Table("defaults", (
        _pos("cut_height_m", "m", "height of a generated cut"),
        _num("face_angle_deg", "deg", "face angle of a generated cut", low=0, high=90, low_open=True),
        _nonneg("ditch_width_m", "m", "ditch width at the toe"),
        _nonneg("ditch_depth_m", "m", "ditch depth"),
        _nonneg("runout_to_road_m", "m", "from the ditch to the road"),
        _pos("road_width_m", "m", "road width"),
        _pos("falls_per_year", "1/yr", "falls reaching the road per year"),
        _pos("falls_per_km_year", "1/(km yr)", "falls per km of road and year"),
        _pos("falls_per_m2_year", "1/(m2 yr)", "falls per m2 of face and year"),
        _pos("vehicles_per_day", "vehicles/day", "average daily traffic"),
        _pos("speed_kmh", "km/h", "posted speed"),
        _share("release_zone_share", "share of the face releasing blocks"),
    ), "Values of the sections table's columns used where a row leaves them empty."),
    CORRIDOR_MASS := Table("mass", (
        _pos("b", "", "power-law exponent of the typed mass law (an ASSUMPTION)"),
        _pos("m_min_kg", "kg", "smallest mass of the law"),
        _pos("m_max_kg", "kg", "largest mass of the law"),
        _path("inventory", "an inventory to fit the law to instead"),
    ), "The mass law shared by the sections."),
    CORRIDOR_MATERIALS := Table("materials", (_path("scenario", "scenario whose materials the generated cuts use"),),
                                "Materials of the generated cuts."),
    # kinds "any": riskrf.app.corridor.rates checks these fields with its own messages
    CORRIDOR_RATES := Table("rates", (
        Field("inventory", "any", "", "the corridor-wide inventory (a file), shared among the sections that give no "
              "rate of their own"),
        Field("share", "any", "", "how it is shared: 'km' (by section length) or 'm2' (by rock-face area)"),
        Field("covered_length_km", "any", "km", "with share = 'km': road length the inventory covers (default: the "
              "sharing sections together), a number > 0"),
        Field("covered_face_area_m2", "any", "m2", "with share = 'm2': rock-face area the inventory covers (default: "
              "the sharing sections together), a number > 0"),
    ), "A corridor-wide rate of falls (riskrf.app.corridor.rates).", record_name="CorridorRatesTable"),
) + MITIGATION_TABLES, "Many sections along a road, each assessed like a site.")

SCENARIO_SCHEMA = FileSchema("Slope scenario (simulation TOML)", (
    Table("profile", (
        Field("x", "numbers", "m", "horizontal positions of the profile's vertices (or points = [[x, z], ...])"),
        Field("z", "numbers", "m", "elevations of the vertices"),
    ), "The 2-D slope profile (or raster = ... for 3-D)."),
    Table("seeder", (
        _text("type", "where blocks start", default="line"),
        Field("x", "any", "m", "release point or zone [from, to] along the profile"),
        _num("density_kg_m3", "kg/m3", "block density", default=DEFAULT_DENSITY_KG_M3, low=DENSITY_RANGE_KG_M3[0],
             high=DENSITY_RANGE_KG_M3[1]),
    ), "Where and how blocks are released; mass_kg, height_m and velocities are numbers or distributions."),
    Table("collectors", (
        _text("name", "collector name", default=REQUIRED),
        _num("x", "m", "position of the vertical line along the profile", default=REQUIRED),
    ), "Vertical lines recording every crossing.", array=True),
    Table("settings", (
        _pos("contact_velocity_ms", "m/s", "below it a flight becomes a contact"),
        _pos("stop_velocity_ms", "m/s", "below it a block stops"),
        _count("max_events", "events per block"),
        _count("envelope_bins", "bins of the envelopes (0 = off)", low=0),
    ), "Numerical settings of the simulator."),
), "A slope for the trajectory simulator; materials are presets or their parameters.")

ALL_SCHEMAS = (SITE_SCHEMA, OPTIONS_SCHEMA, CORRIDOR_SCHEMA, SCENARIO_SCHEMA)


def check_scenario_file(path, *, error=ValueError) -> None:
    """Hold a 2-D scenario TOML against :data:`SCENARIO_SCHEMA` (the simulator's own reader runs after); a 3-D
    scenario (a ``[terrain]`` table) is left to its own reader, :mod:`simulation.scenario3d`.

    Parameters
    ----------
    path : str or path
        The scenario file; one that cannot be read or parsed is left to the simulator's reader to report.
    error : type
        Exception class raised for an invalid field.

    Raises
    ------
    error
        Naming the file, table, field and value.
    """
    import tomllib

    from .schema import check
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except (OSError, tomllib.TOMLDecodeError):
        return                               # the simulator's reader names the problem
    if "terrain" in data:
        return
    check(data, SCENARIO_SCHEMA, path, error=error)


def write_reference(path=None) -> str:
    """Write the file-format reference (:func:`riskrf.core.schema.render_markdown` of :data:`ALL_SCHEMAS`) to
    ``path`` (default ``docs/reference/file-formats-generated.md`` of the source tree) and return its text.

    Parameters
    ----------
    path : str or path, optional
        Where to write; None for the source tree's ``docs/reference/file-formats-generated.md``.

    Returns
    -------
    str
        The Markdown written.
    """
    from pathlib import Path

    from .schema import render_markdown
    text = render_markdown(ALL_SCHEMAS)
    if path is None:
        path = Path(__file__).resolve().parents[2] / "docs" / "reference" / "file-formats-generated.md"
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(text, encoding="utf-8")
    return text



def _export_records(tables) -> dict:
    """The typed record of each table (:meth:`riskrf.core.schema.Table.record`), made a name of this module so that
    records pickle (a site goes to the forked and spawned writers of ``riskrf assess``)."""
    out = {}
    for t in tables:
        cls = t.record_type
        cls.__module__ = __name__
        globals()[cls.__name__] = cls
        out[t.name] = cls
    return out


#: Table name -> the record class of that [table] of a site file (``riskrf.app.site.Site`` holds them).
SITE_RECORDS = _export_records(SITE_SCHEMA.tables)
#: Table name -> the record class of that [table] of a corridor file (:func:`riskrf.app.corridor.load_corridor`
#: reads its tables into them; the mitigation tables' are the site file's).
CORRIDOR_RECORDS = _export_records(CORRIDOR_SCHEMA.tables)


__all__ = ["ALL_SCHEMAS", "CORRIDOR_RECORDS", "CORRIDOR_SCHEMA", "OPTIONS_SCHEMA", "SCENARIO_SCHEMA", "SITE_RECORDS",
           "SITE_SCHEMA", "check_scenario_file", "write_reference"]
