"""The value of a release campaign priced from the mitigation study's own material draws
(riskrf.risk.campaign): the draws' costs are the study's samples under each draw, and the EVSI behaves as a
preposterior value must (0 without data, growing with the releases, reaching the EVPI once the stops identify
the draw)."""
import numpy as np
import pytest

from riskrf.risk.campaign import DEFAULT_CAMPAIGN_COST, material_draw_ranking, release_campaign_value
from riskrf.risk.mitigation import MitigationStudy

from .test_error_budget import _study
from .test_mitigation import CONSTANT_V, HAZ


@pytest.fixture(scope="module")
def study():
    # ground friction 2-30 deg: the draws range from blocks running far (doing nothing costs most) to blocks
    # stopping high on the slope (doing nothing is cheapest), so the material decides the choice
    return _study(1, 2, draws=6, samples=300, blocks=300)


def test_the_draws_costs_are_the_studys_samples_under_each_draw(study):
    r = material_draw_ranking(study)
    P = study.sample_parameters()
    one = study._evaluate({**P, "material_draw": np.full_like(P["material_draw"], 3.0)}).total
    np.testing.assert_allclose(r.costs[2], one.mean(axis=0))
    np.testing.assert_allclose(r.sample_costs[2], one)
    assert r.costs.shape == (6, 3) and r.draws.shape[0] == 6
    # the study's own estimate (each sample with one random draw) is the mean over the draws, within its error
    u = study.uncertain
    assert np.all(np.abs(r.costs.mean(axis=0) - u["mean"]) <= 3 * u["se"] + 1e-9)
    # the material decides: not the same option is cheapest under every draw
    assert len(set(np.argmin(r.costs, axis=1))) > 1


def test_evsi_is_zero_without_releases_grows_with_them_and_reaches_the_evpi(study):
    values = {n: release_campaign_value(study, n_releases=n) for n in (0, 1, 40)}
    evpi = values[0].evpi
    assert evpi > 0
    assert values[0].evsi == 0.0
    assert values[1].evsi <= values[40].evsi + 2 * values[40].standard_error
    assert values[40].evsi <= evpi + 1e-6
    # 40 stops tell the draws (2-30 deg of ground friction) apart: the campaign buys all the EVPI
    assert values[40].evsi == pytest.approx(evpi, rel=0.02)
    v = values[40]
    assert v.calibration_cost == DEFAULT_CAMPAIGN_COST and v.cost_is_assumption
    assert "(ASSUMED default)" in v.verdict()
    stated = release_campaign_value(study, n_releases=40, calibration_cost=1.0)
    assert not stated.cost_is_assumption and stated.calibrate_first


def test_no_material_draws_no_campaign_value():
    s = MitigationStudy(hazard=HAZ, options=_study(1, 2).options, consequences=CONSTANT_V)
    assert material_draw_ranking(s) is None and release_campaign_value(s) is None


def test_a_large_re_simulation_is_thinned_to_its_quantiles(study, monkeypatch):
    import riskrf.risk.campaign as campaign
    from riskrf.risk.campaign import draw_stops
    full = draw_stops(study)
    monkeypatch.setattr(campaign, "MAX_STOPS_PER_DRAW", 50)
    thin = draw_stops(study)
    assert all(t.size == 50 for t in thin)
    for f, t in zip(full, thin):
        np.testing.assert_allclose(np.median(t), np.median(f), atol=0.05 * (f.max() - f.min()) + 1e-9)


def test_a_campaign_value_computed_in_a_forked_child_is_the_one_computed_here(study):
    # riskrf assess computes it beside the rest of the ranking's report (runner.beside) and hands it over
    from functools import partial

    from riskrf.cli.runner import InBackground
    from riskrf.report.mitigation_text import study_report
    here = study_report(study)
    beside = InBackground(partial(release_campaign_value, study))
    there = study_report(study, campaign=beside)
    assert there["release_campaign"] == here["release_campaign"]
    assert there["text"] == here["text"]
