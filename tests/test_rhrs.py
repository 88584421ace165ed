"""RHRS category scores against the published rating criteria.

Reference: Pierson & Van Vickle (1993), FHWA-SA-93-057, RHRS summary sheet (category criteria and
points 3 / 9 / 27 / 81), as listed in shared/research/domain-methods.md section 4.3 [R]; also Pierson
(1991) FHWA-OR-GI-92-05.  Each benchmark of the summary sheet is converted to SI exactly
(1 ft = 0.3048 m, 1 yd3 = 0.764554857984 m3) and must score its published points.
"""
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from riskrf.risk import rhrs

FT = 0.3048
YD3 = 0.764554857984
POINTS = (3.0, 9.0, 27.0, 81.0)


@pytest.mark.parametrize("feet,points", list(zip((25, 50, 75, 100), POINTS)))
def test_slope_height_points(feet, points):
    # summary sheet: slope height 25 ft = 3, 50 ft = 9, 75 ft = 27, 100 ft = 81 points; x = H/25
    assert rhrs.score(rhrs.slope_height_x(feet * FT)) == pytest.approx(points, rel=1e-12)


@pytest.mark.parametrize("avr,points", list(zip((25, 50, 75, 100), POINTS)))
def test_average_vehicle_risk_points(avr, points):
    # summary sheet: AVR 25 % = 3 ... 100 % = 81 points; x = AVR/25
    assert rhrs.score(rhrs.avr_x(avr)) == pytest.approx(points, rel=1e-12)


@pytest.mark.parametrize("dsd,points", list(zip((100, 80, 60, 40), POINTS)))
def test_decision_sight_distance_points(dsd, points):
    # summary sheet: %DSD adequate 100 % = 3, moderate 80 % = 9, limited 60 % = 27, very limited 40 % = 81
    assert rhrs.score(rhrs.dsd_x(dsd)) == pytest.approx(points, rel=1e-12)


@pytest.mark.parametrize("feet,points", list(zip((44, 36, 28, 20), POINTS)))
def test_roadway_width_points(feet, points):
    # summary sheet: roadway width incl. paved shoulders 44 ft = 3, 36 = 9, 28 = 27, 20 ft = 81 points
    assert rhrs.score(rhrs.roadway_width_x(feet * FT)) == pytest.approx(points, rel=1e-12)


@pytest.mark.parametrize("feet,yd3,points", list(zip((1, 2, 3, 4), (3, 6, 9, 12), POINTS)))
def test_block_size_and_volume_points(feet, yd3, points):
    # summary sheet: block size 1/2/3/4 ft, or volume 3/6/9/12 cu yd per event = 3/9/27/81 points
    assert rhrs.score(rhrs.block_size_x(feet * FT)) == pytest.approx(points, rel=1e-12)
    assert rhrs.score(rhrs.volume_x(yd3 * YD3)) == pytest.approx(points, rel=1e-12)


def test_avr_formula_units_cancel():
    # AVR = ADT x L[mi] / 24 / V[mph] x 100 (summary sheet): the SI form gives the same number.
    adt, length_mi, mph = 5000.0, 0.1, 55.0
    imperial = adt * length_mi / 24.0 / mph * 100.0
    si = rhrs.average_vehicle_risk(adt, length_mi * 1609.344, mph * 1.609344)
    assert si == pytest.approx(imperial, rel=1e-12)
    # a vehicle below a 1 km slope at 24 km/h with 24 vehicles a day: 1 vehicle-hour a day /24 h/day = 4.1667 %
    assert rhrs.average_vehicle_risk(24, 1000, 24) == pytest.approx(100 / 24)


def test_percent_dsd():
    assert rhrs.percent_decision_sight_distance(150, 300) == pytest.approx(50.0)


@pytest.mark.parametrize("category", sorted(rhrs.CLASSES))
def test_descriptive_classes_score_3_9_27_81(category):
    for name, points in zip(rhrs.CLASSES[category], POINTS):
        assert rhrs.score(rhrs.class_x(category, name)) == pytest.approx(points)


def test_short_class_names_and_errors():
    assert rhrs.class_x("ditch_effectiveness", "limited") == 3
    assert rhrs.class_x("rockfall_history", "Occasional") == 2
    assert rhrs.class_x("rockfall_history", 2.5) == 2.5
    with pytest.raises(ValueError, match="rockfall_history = 'sometimes'"):
        rhrs.class_x("rockfall_history", "sometimes")
    with pytest.raises(ValueError, match=r"\[1, 4\]"):
        rhrs.class_x("climate_and_water", 5)
    with pytest.raises(ValueError, match="unknown RHRS category"):
        rhrs.class_x("colour", 1)


def _worst_case():
    """A slope at the 81-point benchmark of every category (summary sheet), case 1 geology."""
    return dict(slope_height_m=100 * FT, ditch_effectiveness="no catchment", avr_percent=100, percent_dsd=40,
                roadway_width_m=20 * FT, structural_condition_case1="continuous joints, adverse orientation",
                rock_friction="clay infilling or slickensided", block_size_m=4 * FT, climate_and_water=4,
                rockfall_history="constant falls")


def test_total_of_ten_scored_items():
    # 10 scored items (geologic character has two) at 81 points each: 810.
    r = rhrs.rate(**_worst_case())
    assert r.total == pytest.approx(810.0)
    s = r.summary()
    assert list(s["category"])[-1] == "total" and len(s) == 11
    assert np.allclose(s["score"].iloc[:-1], 81.0)


def test_rate_from_raw_inputs_and_block_or_volume_takes_the_larger():
    a = _worst_case()
    del a["avr_percent"], a["percent_dsd"]
    a.update(adt_vehicles_per_day=2400, slope_length_m=500, speed_kmh=50, sight_distance_m=100,
             decision_sight_distance_m=250, volume_m3=9 * YD3, block_size_m=1 * FT)
    r = rhrs.rate(**a)
    assert r.inputs["avr_percent"] == pytest.approx(2400 * 0.5 / 24 / 50 * 100)      # 100 %
    assert r.inputs["percent_dsd"] == pytest.approx(40.0)
    assert r.scores["block_size_or_volume"] == pytest.approx(27.0)                  # 9 yd3 beats 1 ft


def test_rate_errors_name_the_attribute():
    a = _worst_case()
    del a["roadway_width_m"]
    with pytest.raises(ValueError, match="roadway_width_m"):
        rhrs.rate(**a)
    with pytest.raises(ValueError, match="case 1"):
        rhrs.rate(**_worst_case(), difference_in_erosion_rates="small")
    with pytest.raises(ValueError, match="unknown RHRS attribute"):
        rhrs.rate(**_worst_case(), colour="red")
    with pytest.raises(ValueError, match="slope_height_m"):
        rhrs.rate(**{**_worst_case(), "slope_height_m": -1.0})
    with pytest.raises(TypeError, match="speed_kmh"):
        rhrs.average_vehicle_risk(100, 100, "fast")


@given(st.floats(0, 200), st.floats(0, 200))
def test_scores_monotone_in_height(h1, h2):
    lo, hi = sorted((h1, h2))
    assert rhrs.score(rhrs.slope_height_x(lo)) <= rhrs.score(rhrs.slope_height_x(hi))
    assert math.isclose(rhrs.score(rhrs.slope_height_x(hi)), 3 ** (hi / FT / 25), rel_tol=1e-12)


def test_cap_points_limits_each_category():
    a = {**_worst_case(), "slope_height_m": 200 * FT}          # x = 8: 6561 points uncapped
    assert rhrs.rate(**a).scores["slope_height"] == pytest.approx(6561.0)
    capped = rhrs.rate(cap_points=100, **a)
    assert capped.scores["slope_height"] == 100 and capped.total == pytest.approx(9 * 81 + 100)
    with pytest.raises(ValueError, match="cap_points"):
        rhrs.rate(cap_points=10, **a)


def test_only_the_fhwa_variant_is_rated_and_the_others_say_what_is_missing():
    """ODOT and Colorado-modified RHRS: their published tables were not found, so they are refused (not guessed),
    and the refusal names the documents that are missing."""
    from riskrf import RiskrfError
    r = rhrs.rate(variant="fhwa", **_worst_case())
    assert r.variant == "fhwa" and r.total == pytest.approx(810.0)
    assert sorted(rhrs.VARIANTS) == ["fhwa"] and sorted(rhrs.UNAVAILABLE_VARIANTS) == ["colorado", "odot"]
    with pytest.raises(RiskrfError, match=r"variant = 'colorado' must be one of \['fhwa'\] \(not implemented: .*"
                                          r"Santi, Russell, Higgins & Spriet 2009, Eng. Geol. 104: 55-65.*CDOT-2008-7"):
        rhrs.rate(variant="colorado", **_worst_case())
    with pytest.raises(ValueError, match=r"variant = 'odot' .*FHWA-OR-GI-92-05.*not found"):
        rhrs.rate(variant="odot", **_worst_case())
    with pytest.raises(ValueError, match=r"variant = 'nz' must be one of \['fhwa'\] \(known but not implemented: "
                                         r"\['colorado', 'odot'\]\)"):
        rhrs.rate(variant="nz", **_worst_case())
    assert rhrs.variant_problem("fhwa") is None and rhrs.variant_problem(3) is not None


def test_missing_attributes_are_listed():
    a = _worst_case()
    del a["climate_and_water"], a["rockfall_history"]
    with pytest.raises(rhrs.RHRSError, match="FHWA RHRS rating needs climate_and_water, rockfall_history") as e:
        rhrs.rate(**a)
    assert e.value.missing == ("climate_and_water", "rockfall_history")


def test_schema_declares_the_implemented_variants():
    """riskrf.core.file_schemas cannot import riskrf.risk; the declared choices must be rhrs.VARIANTS."""
    from riskrf.core.file_schemas import CORRIDOR_SCHEMA
    field = CORRIDOR_SCHEMA.table("corridor").field("rhrs_variant")
    assert set(field.choices) == set(rhrs.VARIANTS) and field.default == "fhwa"
