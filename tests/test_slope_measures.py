"""Catch bench, bund and drape options: profiles checked by hand; bench and bund effects derived by re-simulation,
the drape's from the simulated release points and an ASSUMED containment."""
import numpy as np
import pytest
import simulation

from riskrf.risk.measures import MeasureError
from riskrf.risk.mitigation import MitigationError, Option
from riskrf.risk.mitigation_inputs import parse_mitigation
from riskrf.risk.geometry_measures import SlopeMeasure, bench_profile, bund_profile, drape_scenario, \
    scenario_with_measures

from riskrf.risk.measures import SimulationContext
from riskrf.risk.mitigation import MitigationStudy, Uncertainty

from .test_mitigation import CONSTANT_V, HAZ, TOE, _toe_study


def test_bench_profile_by_hand():
    prof = simulation.scenario_from_dict(TOE).profile
    # slope from (5, 40) to (30, 0): z(15) = 24, z(21) = 14.4; back wall 0.25 x 9.6 = 2.4 m
    b = bench_profile(prof, 15.0, 6.0)
    assert np.allclose(b.x, [0, 5, 15, 17.4, 21, 30, 80]) and np.allclose(b.z, [40, 40, 24, 14.4, 14.4, 0, 0])
    with pytest.raises(MeasureError, match="too narrow"):
        bench_profile(prof, 15.0, 2.0, inner_slope_hv=1.0)
    with pytest.raises(MeasureError, match="falling towards the road"):
        bench_profile(prof, 40.0, 5.0)


def test_bund_profile_by_hand():
    prof = simulation.scenario_from_dict(TOE).profile
    # on the flat at z = 0 from 40 to 48 m: 2 m high, faces 0.5H:1V (1 m) and 1.5H:1V (3 m): crest 41-45 m
    b = bund_profile(prof, 40.0, 8.0, 2.0)
    assert np.allclose(b.x, [0, 5, 30, 40, 41, 45, 48, 80]) and np.allclose(b.z, [40, 40, 0, 0, 2, 2, 0, 0])
    assert b.material_index.size == b.x.size - 1
    with pytest.raises(MeasureError, match="too narrow"):
        bund_profile(prof, 40.0, 3.0, 2.0)


def test_drape_changes_the_surface_material_in_its_zone_only():
    sc = simulation.scenario_from_dict(TOE)
    d = drape_scenario(sc, (10.0, 25.0))
    k = list(d.profile.material_names).index("drape")
    mid = 0.5 * (d.profile.x[:-1] + d.profile.x[1:])
    assert np.all((d.profile.material_index == k) == ((mid >= 10) & (mid <= 25)))
    assert np.allclose(np.interp([12.5, 20.0], d.profile.x, d.profile.z), [28.0, 16.0])    # ground unchanged


def test_overlapping_slope_measures_and_the_road_line_are_refused():
    sc = simulation.scenario_from_dict(TOE)
    with pytest.raises(MeasureError, match="overlap"):
        scenario_with_measures(sc, [SlopeMeasure("bund", "a", 40.0, 8.0, 2.0), SlopeMeasure("bund", "b", 45, 8, 2)])
    with pytest.raises(MeasureError, match="road line"):
        scenario_with_measures(sc, [SlopeMeasure("bund", "a", 55.0, 8.0, 2.0)])
    with pytest.raises(MitigationError, match="a bund needs height_m"):
        parse_mitigation({"options": [{"name": "n", "kind": "none", "capital_cost": 0},
                                      {"name": "b", "kind": "bund", "capital_cost": 1, "x_m": 40, "width_m": 8}]},
                         "site.toml")


def test_bench_and_bund_are_re_simulated_and_the_drape_contains_what_starts_under_it():
    opts = (Option("nothing", "none"), Option("bench", "bench", 1e5, x_m=15.0, width_m=6.0),
            Option("bund", "bund", 1e5, x_m=40.0, width_m=8.0, height_m=3.0),
            Option("drape", "drape", 1e5, zone_x_m=(5.5, 29.5), max_mass_kg=1e9))
    # the road 70 m out: on this slope every block rolls past 60 m (to the end of the profile at 80 m) unless a
    # measure stops it
    toe = {**TOE, "collectors": [{"name": "barrier", "x": 31.0}, {"name": "road", "x": 70.0}]}
    s = MitigationStudy(hazard=HAZ, options=opts, consequences=CONSTANT_V, uncertainty=Uncertainty(samples=50),
                        context=SimulationContext(simulation.scenario_from_dict(toe), n_blocks=2000, seed=3))
    base = s.evaluate("nothing").road_falls_per_year
    t = s.ranking().set_index("option")
    for name in ("bench", "bund", "drape"):
        r = s.evaluate(name)
        assert r.road_falls_per_year < base, name                    # each keeps falls off the road
        assert 0 < r.retention < 1, name
    # every block starts under the mesh (seeder x = 6-9 m): the drape keeps the ASSUMED 85 % of them, no more
    assert s.evaluate("drape").retention == pytest.approx(0.85, abs=1e-9)
    assert "ASSUMED containment 85% (70%-95%)" in t.loc["drape", "effect_basis"]
    assert "released under the mesh" in t.loc["drape", "effect_basis"]
    assert t.loc["bund", "effect_basis"].startswith("derived: the slope re-simulated with the bund")
    assert t.loc["bench", "effect_basis"].startswith("derived: the slope re-simulated with the bench")
    # the effect is a simulation result: a higher bund stops at least as many falls (common random numbers)
    s2 = _toe_study((Option("nothing", "none"), Option("low", "bund", 1e5, x_m=40.0, width_m=12.0, height_m=1.0),
                     Option("high", "bund", 1e5, x_m=40.0, width_m=12.0, height_m=3.0)))
    assert s2.evaluate("high").retention >= s2.evaluate("low").retention


def test_drape_effect_is_the_simulated_share_released_under_it_times_its_containment():
    """Retained share = containment x share of the road falls released under the mesh (their simulated release
    points); heavier blocks than the mesh holds are not credited; a stated containment of 1 is labelled."""
    half = Option("half", "drape", 1e5, zone_x_m=(7.5, 29.5), max_mass_kg=1e9)        # seeder 6-9 m: half
    full = Option("full", "drape", 1e5, zone_x_m=(5.5, 29.5), max_mass_kg=1e9, containment=1.0)
    small = Option("small", "drape", 1e5, zone_x_m=(5.5, 29.5), max_mass_kg=400.0)   # every block is 500 kg
    s = _toe_study((Option("nothing", "none"), half, full, small))
    t = s.ranking().set_index("option")
    share = s._slopes.derived["half: share under the mesh"][0]
    ref = s._slopes.reference_run
    from riskrf.risk.measures import road_crossings
    road = road_crossings(ref, "road")
    x0 = ref.blocks["x"][road]
    assert share == pytest.approx(np.mean((x0 >= 7.5) & (x0 <= 29.5)), abs=1e-12) and 0.3 < share < 0.7
    assert s.evaluate("half").retention == pytest.approx(0.85 * share, rel=1e-9)
    assert s.evaluate("full").retention == pytest.approx(1.0)
    # no simulated block (500 kg each) is small enough: only the hazard's falls below 400 kg are credited
    assert s._slopes.derived["small: share under the mesh"][0] == 0.0
    assert 0 < s.evaluate("small").retention <= 0.85 * HAZ.mass.cdf(400.0) * 1.1
    assert "stated containment (an ASSUMPTION, not derived) 100%" in t.loc["full", "effect_basis"]
    assert "blocks above max_mass_kg = 400 kg not contained" in t.loc["small", "effect_basis"]
    # the ASSUMED containment is an uncertain input of the study (tornado, sampling)
    assert s.parameter_ranges()["containment:half"][:2] == (0.7, 0.95)
    assert "containment:full" not in s.parameter_ranges()


def test_drape_off_the_face_or_over_no_release_is_refused():
    sc = simulation.scenario_from_dict(TOE)
    from riskrf.risk.geometry_measures import check_drape_zone, face_spans
    assert face_spans(sc.profile) == [(5.0, 30.0)]
    assert check_drape_zone(sc, (5.0, 30.0)) == pytest.approx(1.0)
    with pytest.raises(MeasureError, match=r"zone_x_m = \[35, 50\] is not on a rock face.*span x = 5-30 m"):
        check_drape_zone(sc, (35.0, 50.0))
    with pytest.raises(MeasureError, match="outside the profile"):
        check_drape_zone(sc, (5.0, 90.0))
    with pytest.raises(MeasureError, match="no block is released under the mesh"):
        check_drape_zone(sc, (20.0, 30.0))
    flat = simulation.scenario_from_dict({**TOE, "profile": {"x": [0.0, 50.0, 80.0], "z": [20.0, 0.0, 0.0],
                                                             "materials": ["rock", "soil"]}})
    with pytest.raises(MeasureError, match="has no rock face to drape"):
        check_drape_zone(flat, (5.0, 20.0))
    with pytest.raises(MitigationError, match="containment = 0.5 lies outside containment_range"):
        parse_mitigation({"options": [{"name": "n", "kind": "none", "capital_cost": 0},
                                      {"name": "d", "kind": "drape", "capital_cost": 1, "zone_x_m": [5, 20],
                                       "containment": 0.5, "containment_range": [0.7, 0.9]}]}, "site.toml")
    with pytest.raises(MitigationError, match="containment and containment_range are only for kind = 'drape'"):
        parse_mitigation({"options": [{"name": "n", "kind": "none", "capital_cost": 0},
                                      {"name": "b", "kind": "bund", "capital_cost": 1, "x_m": 40, "width_m": 8,
                                       "height_m": 2, "containment": 0.9}]}, "site.toml")
