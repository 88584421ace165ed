"""Benchmark: the uncertainty ranking of the demo's mitigation options.

Run: python tests/benchmarks/bench_mitigation.py [samples]
Builds the demo site's hazard (50,000 simulated blocks, as ``riskrf demo``), then times
(1) deriving the options' effects (re-simulating each ditch profile and the reference with
the site's option_blocks, the barrier damage-state tables on the mass grid) and (2) the
joint-uncertainty ranking: ``samples`` (default 1,000) joint samples of every uncertain
input for every option, with the mean, 5-95 %, probability cheapest and expected regret,
then the tornado and break-even tables.  Simulations are made once and reused by every
sample; the samples run through one vectorised loss engine.
"""
from __future__ import annotations

import sys
import time
import warnings
from dataclasses import replace

from riskrf.app.assess.decision import road_share, study_context
from riskrf.app.assess.hazard import energy_hazard_from_inputs
from riskrf.frequency.inventory.reader import read_inventory
from riskrf.risk.mitigation import MitigationStudy
from riskrf.app.site import load_site


def main(samples: int = 1000):
    from importlib import resources
    with resources.as_file(resources.files("riskrf") / "data" / "demo_site.toml") as path:
        site = load_site(path)
    inv_cfg, hz_cfg = site.inventory, site.hazard
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inv = read_inventory(site.resolve(inv_cfg.path))
    gr, hazard, result = energy_hazard_from_inputs(
        inv, m_max=inv_cfg.m_max_kg, rate_scale=inv_cfg.rate_scale, scenario=site.resolve(hz_cfg.scenario),
        n=hz_cfg.n_blocks, seed=hz_cfg.seed)
    mit = site.mitigation.study_kwargs()
    if site.rates is not None:          # closure rules: share and hours from the site's daily rate model
        from riskrf.risk.site_rates import evaluate_rates, resolve_closures
        rates = evaluate_rates(site.rates, site.path.parent, inv_cfg, mit["options"])
        mit["options"] = resolve_closures(mit["options"], rates)
    mit["uncertainty"] = replace(mit["uncertainty"], samples=samples)
    study = MitigationStudy(hazard=hazard, road_share=road_share(result, "barrier", "road"),
                            **study_context(result, "barrier", "road", hz_cfg.option_blocks, hz_cfg.seed, inv,
                                            hazard, inv_cfg.rate_scale), **mit)
    n_opt = len(study.options)
    t0 = time.perf_counter()
    study.central_parameters()          # derives every option's effect (re-simulations included)
    t1 = time.perf_counter()
    ranking = study.ranking()
    t2 = time.perf_counter()
    study.tornado()
    study.break_even_table()
    t3 = time.perf_counter()
    print(f"options: {n_opt} ({', '.join(study.options[i].name for i in range(n_opt))})")
    print(f"deriving effects (ditch re-simulations with {hz_cfg.option_blocks:,} blocks, damage tables): "
          f"{t1 - t0:.2f} s")
    print(f"uncertainty ranking, {samples:,} joint samples x {n_opt} options: {t2 - t1:.2f} s")
    print(f"tornado and break-even over {len(study.central_parameters())} inputs: {t3 - t2:.2f} s")
    print(f"total: {t3 - t0:.2f} s")
    print(ranking[["option", "expected_total_cost", "cost_p05", "cost_p95", "probability_best"]].to_string(index=False))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1000)
