"""A recommendation a checking engineer can sign: options that fail their design checks are
never recommended, the barrier the design basis requires is costed and ranked, and where no certified barrier can
be placed the report says so and what would work instead (riskrf.risk.required_barrier, MitigationStudy.
recommendation, riskrf.app.assess.decision.required_barrier_for_site)."""
from dataclasses import replace

import numpy as np
import pytest

from riskrf.app.site import SiteError, load_site
from riskrf.hazard.design_basis import DesignBasis
from riskrf.hazard.design_requirement import design_requirement
from riskrf.risk.mitigation import MitigationError, Option
from riskrf.risk.required_barrier import (DEFAULT_COST_PER_M, BarrierCostModel, basis_design_checks,
                                          cost_model_from_site, required_barrier)

from .test_design_basis import RHO, _block, _hazard
from .test_mitigation import OPTIONS, study

BAD = "NOT ADEQUATE under UNI 11211-4: energy: E_d x gamma_E (1.2) <= MEL (demand 34,000 > capacity 2,000 kJ)"


def _cheap_fence_study(**kw):
    """The test study with the fence made so cheap that it is the recommendation when its checks are ignored."""
    opts = tuple(replace(o, capital_cost=1e3, annual_maintenance=0.0) if o.kind == "fence" else o for o in OPTIONS)
    return study(options=opts, **kw)


def test_an_option_failing_its_design_checks_is_ranked_but_never_recommended():
    free = _cheap_fence_study()
    assert free.recommendation()["option"] == "fence"          # without a verdict the cheap fence wins
    checked = replace(free, design_checks={"fence": BAD})
    t = checked.ranking()
    row = t[t["option"] == "fence"].iloc[0]
    assert row["design_check"] == BAD and not row["design_adequate"]      # still ranked, marked
    rec = checked.recommendation(t)
    assert rec["option"] not in (None, "fence")
    assert rec["not_recommended"] == {"fence": BAD}
    assert "fail their design checks: fence (NOT ADEQUATE" in rec["reason"]
    assert t.loc[t["option"] == rec["option"], "design_adequate"].iloc[0]


def test_no_adequate_option_is_stated_not_hidden():
    s = _cheap_fence_study()
    s = replace(s, design_checks={o.name: BAD for o in s.options})
    rec = s.recommendation()
    assert rec["option"] is None and rec["basis"] == "no option passes its design checks"
    assert rec["reason"].startswith("NO ADEQUATE OPTION") and set(rec["not_recommended"]) == {o.name for o in s.options}


def _requirement(h_m, rate=0.01, v=20.0):
    """UNI 11211-4 at a line 3 m from the road: speed v [m/s], every block passing h_m [m] high."""
    return design_requirement(_hazard(rate=rate, v=v, h=h_m), DesignBasis("UNI 11211-4"), block=_block(1.0),
                              density_kg_m3=RHO, x_m=100.0, clearance_m=3.0,
                              candidates=[("fence 1000 kJ", 1000.0, 5.0)])


def test_the_required_barrier_is_the_smallest_class_meeting_mel_and_height_and_is_costed():
    req = _requirement(h_m=2.0)
    model = BarrierCostModel()
    rb = required_barrier(req, None, model, exposed_length_m=120.0, currency="CHF")
    assert rb.placeable
    o = rb.option
    assert o.kind == "fence" and o.capacity_kj == req.required_class_kj and o.height_m == req.required_net_height_m
    assert o.capacity_kj >= req.required_mel_kj
    # the default price of that class at that height, for 120 m: by hand from the table
    unit = DEFAULT_COST_PER_M[o.capacity_kj] * o.height_m / 5.0
    assert o.capital_cost == pytest.approx(120.0 * unit)
    assert o.capital_cost_range == pytest.approx((0.7 * o.capital_cost, 1.5 * o.capital_cost))
    assert "adequate under UNI 11211-4 by construction" in rb.verdict
    assert "ASSUMED cost" in rb.text("CHF") and "ASSUMED" in rb.to_dict()["cost_basis"]
    # the required barrier enters the ranking with its cost, and its derived effect
    s = study(options=OPTIONS + (o,), design_checks={o.name: rb.verdict}, required_barrier=rb)
    t = s.ranking()
    row = t[t["option"] == o.name].iloc[0]
    assert row["capital"] == pytest.approx(o.capital_cost) and np.isfinite(row["expected_total_cost"])
    assert row["design_adequate"] and row["effectiveness"] > 0
    assert f"ranked {int(row['rank'])} of {len(t)}" in s.recommendation(t)["reason"] or \
        s.recommendation(t)["option"] == o.name


def test_blocks_in_first_flight_over_every_catalogue_net_no_barrier_and_what_instead():
    """The practitioner's cut: blocks cross the barrier line 8-9 m high, 3 m from the toe."""
    req = _requirement(h_m=8.5)
    assert req.required_net_height_m > 8.0
    rb = required_barrier(req, None, BarrierCostModel(), exposed_length_m=100.0, currency="CHF")
    assert not rb.placeable and rb.option is None
    text = rb.text("CHF")
    assert "No certified barrier meets UNI 11211-4" in text and "blocks pass too high" in text
    for alternative in ("another position", "ditch", "bund", "drape"):
        assert alternative in text
    # the site's own 1000 kJ / 5 m fence fails the basis's checks, so it cannot be the recommendation
    verdicts = basis_design_checks(req)
    assert verdicts["fence 1000 kJ"].startswith("NOT ADEQUATE under UNI 11211-4") and "height" in verdicts[
        "fence 1000 kJ"]
    fence = Option("fence 1000 kJ", "fence", 1e3, capacity_kj=1000.0, height_m=5.0)
    s = study(options=(OPTIONS[0], fence), design_checks=verdicts, required_barrier=rb)
    rec = s.recommendation()
    assert rec["option"] != "fence 1000 kJ" and "No certified barrier meets" in rec["reason"]


def test_required_mel_above_the_largest_class_names_the_range_once():
    req = _requirement(h_m=2.0, v=60.0)              # 2.7 t at 60 m/s: far above 8,500 kJ
    rb = required_barrier(req, None, BarrierCostModel(), exposed_length_m=100.0)
    assert not rb.placeable
    assert rb.reason.count("above the largest certified class") == 1 and "x = 100 m" in rb.reason


def test_cost_model_from_the_site_file_and_scaled_default():
    model, include = cost_model_from_site({"cost_classes_kj": [1000, 5000], "cost_per_m": [500, 1500],
                                           "fixed_cost": 1e4}, source="site.toml")
    assert include and model.from_site and "site file" in model.label
    assert model.capital(3000.0, 5.0, 100.0) == pytest.approx(1e4 + 100 * 1000.0)   # linear between classes
    # no unit prices: the default table scaled to the site's own fence (its price / the table's price)
    table_price = BarrierCostModel().capital(2000.0, 5.0, 100.0)
    scaled, _ = cost_model_from_site(None, site_fences=[(2000.0, 5.0, 2 * table_price, 100.0)])
    assert scaled.scale == pytest.approx(2.0) and "scaled by 2" in scaled.label
    assert scaled.capital(2000.0, 5.0, 100.0) == pytest.approx(2 * table_price)
    assert cost_model_from_site({"include": False})[1] is False


@pytest.mark.parametrize("table, match", [
    ({"price": 3}, "unknown field required_barrier.price"),
    ({"cost_classes_kj": [1000, 2000]}, "go together"),
    ({"cost_classes_kj": [2000, 1000], "cost_per_m": [1, 2]}, "must increase"),
    ({"cost_classes_kj": [1000], "cost_per_m": [1, 2]}, "one price per class"),
    ({"cost_per_m": [-1], "cost_classes_kj": [1000]}, r"cost_per_m = -1 must be a number > 0"),
    ({"cost_range": [1.2, 1.5]}, "must bracket 1"),
    ({"include": "yes"}, "must be true or false"),
    ({"max_net_height_m": 0}, "max_net_height_m = 0 must be a number > 0"),
])
def test_bad_required_barrier_tables_are_refused_naming_the_field(table, match):
    with pytest.raises(MitigationError, match=match):
        cost_model_from_site(table, source="site.toml")


def test_site_file_required_barrier_errors_name_the_file(tmp_path):
    from .test_assess import _site_copy
    site = _site_copy(tmp_path, replace={"[report]": "[required_barrier]\ncost_range = [2, 3]\n\n[report]"})
    with pytest.raises(SiteError, match=r"site\.toml: required_barrier\.cost_range = \[2, 3\] must bracket 1"):
        load_site(site)
