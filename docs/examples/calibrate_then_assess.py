"""From release data to a calibrated assessment: price a release campaign, run it, calibrate, assess again.

The demo site's slope has never been calibrated: its materials are riskrf's presets, sampled over stated ranges
(``[uncertainty.materials]``).  The chain here is the one a user follows on a new slope:

1. **Assess uncalibrated.**  Every output says the trajectory model is UNCALIBRATED, and the ranking states what
   a release campaign of 20 blocks is worth to the decision (its EVSI, priced from the ranking's own material
   draws, against an ASSUMED 100,000 cost).
2. **Release blocks and survey the stops.**  No real campaign exists for this idealised slope, so the 20 stops
   here are SYNTHETIC: simulated under a "true" set of material values inside the stated ranges (talus ground
   friction 40 deg, talus e_T 0.4, soil e_N 0.30).  On a real site they come from the field, in the releases
   file of ``riskrf calibrate-pooled`` (see the user guide, Simulation).
3. **Calibrate** the three uncertain material values on those stops (``simulation.calibrate_pooled``, the engine
   of ``riskrf calibrate-pooled``): a posterior sample, written as ``posterior.csv``.
4. **Assess again** with the posterior: ``[model_uncertainty] posterior = "posterior.csv"`` re-simulates the slope
   for draws of the posterior and carries them to the design energies and the ranking, with the value of
   calibrating further.  Its status is "calibration used for the uncertainty".

The effort is small (6,000 blocks, 400 joint samples, 100 blocks per release and parameter set, 8 posterior
draws) so that the example runs in about 15 s; the figures move with it.  Writes ``posterior_pairs.png``,
``posterior.csv`` and the two assessments' summaries (``uncalibrated_summary.json``, ``calibrated_summary.json``:
what ``riskrf assess`` writes as ``summary.json``) into the output directory (first argument, else a new temporary
directory).

Run from the repository root::

    python docs/examples/calibrate_then_assess.py [OUT_DIR]
"""
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import riskrf  # noqa: E402
import simulation  # noqa: E402
from riskrf.app.assess import run_assessment  # noqa: E402
from riskrf.io.outputs import write_json  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="riskrf-example-"))
out.mkdir(parents=True, exist_ok=True)
demo = Path(riskrf.__file__).parent / "data" / "demo_site.toml"
scenario = (demo.parent / "../../simulation/scenarios/road_cut_barrier.toml").resolve()


def site_file(name: str, extra: str = "") -> Path:
    """The demo site at a small effort, its paths made absolute, with ``extra`` TOML appended."""
    text = demo.read_text()
    for rel in ("lauterbrunnen_tls_2018.csv", "hong_kong_rock_cuts_1984_2020.csv", "hko_daily_rainfall_1983_2020.csv"):
        text = text.replace(f'"{rel}"', f'"{(demo.parent / rel).resolve()}"')
    text = text.replace('"../../simulation/scenarios/road_cut_barrier.toml"', f'"{scenario}"')
    for old, new in (("n_blocks = 50000", "n_blocks = 6000"), ("option_blocks = 10000", "option_blocks = 2000"),
                     ("bootstrap = 200", "bootstrap = 40"), ("\nsamples = 1000", "\nsamples = 400")):
        text = text.replace(old, new)
    path = out / name
    path.write_text(text + extra)
    return path


def assess(site: Path, name: str) -> dict:
    """Run the assessment of ``site`` (no report or figures: ``riskrf assess`` writes those) and keep its summary."""
    summary = run_assessment(riskrf.load_site(site), log=lambda line: None).summary()
    write_json(summary, out / f"{name}_summary.json")
    print(f"wrote {out / f'{name}_summary.json'}")
    return summary


# 1. uncalibrated: the status, the ranking and what a campaign of 20 releases is worth
before = assess(site_file("site.toml"), "uncalibrated")
print(before["trajectory_model"]["status"].upper(), "|", before["recommendation"]["option"], "recommended")
print("  release campaign:", before["release_campaign"]["verdict"])

# 2. a campaign of 20 releases from the scenario's seeder; SYNTHETIC stops from a known truth
truth = {"materials.talus.ground_friction_angle_deg": 40.0, "materials.talus.tangential.mean": 0.4,
         "materials.soil.normal_restitution.mean": 0.30}
stops = simulation.run(simulation.scenario_with_values(scenario, truth), n=20, seed=7).runout["x_stop_m"]
release = simulation.Release("synthetic campaign, 20 blocks", str(scenario), stops.to_numpy())

# 3. the pooled calibration of the three uncertain values (the prior: the site file's stated ranges)
prior = {"materials.talus.ground_friction_angle_deg": (34.0, 42.0), "materials.talus.tangential.mean": (0.3, 0.8),
         "materials.soil.normal_restitution.mean": (0.25, 0.31)}
cal = simulation.calibrate_pooled([release], prior, n_per_release=100, n_initial=64, n_per_iteration=32,
                                  iterations=1, n_posterior=400,
                                  n_predictive=0, seed=1)
cal.write(out / "posterior.csv")
print(cal.summary().to_string(float_format="{:.3g}".format))
print("  truth:", ", ".join(f"{k.split('.', 1)[1]} {v:g}" for k, v in truth.items()))
ax = cal.plot()
fig = ax.flat[0].figure if hasattr(ax, "flat") else ax.figure
fig.savefig(out / "posterior_pairs.png", dpi=90)
plt.close(fig)
print(f"wrote {out / 'posterior_pairs.png'}")

# 4. assess again with the posterior carried to the design energies and the ranking
after = assess(site_file("site_calibrated.toml", '\n[model_uncertainty]\nposterior = "posterior.csv"\ndraws = 8\n'
                         "max_draws = 8\nn_blocks = 600\noption_blocks = 300\nbootstrap = 20\n"),
               "calibrated")
mu = after["model_uncertainty"]
print(after["trajectory_model"]["status"].upper(), "|", after["recommendation"]["option"], "recommended")
print("  further calibration:", mu["verdict"])
