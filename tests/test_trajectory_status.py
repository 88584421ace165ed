"""Every output says whether the trajectory model is calibrated, and how wrong the presets were on held-out real
releases (riskrf.hazard.trajectory_status)."""
import pandas as pd
import pytest

from riskrf.hazard.trajectory_status import UNCALIBRATED_HELD_OUT, held_out_range, trajectory_model_status

from .conftest import ROOT


def test_the_held_out_errors_are_those_of_the_validation_table():
    t = pd.read_csv(ROOT / "docs" / "validation" / "presets_loo.csv")
    rows = t[t["model"] == "published presets"].set_index("held_out")
    assert set(rows.index) == set(UNCALIBRATED_HELD_OUT)
    for name, (n, err, b95, b99) in UNCALIBRATED_HELD_OUT.items():
        r = rows.loc[name]
        assert (int(r["observations"]), r["median_error_pct"], r["beyond_p95"], r["beyond_p99"]) == \
            pytest.approx((n, err, b95, b99)), name
    assert held_out_range() == "median runout 14 to 82 % short, and up to 98% of the real stops beyond the simulated p99"


def test_presets_typed_materials_and_calibrations():
    presets = {"materials": {"rock": {"preset": "bedrock"}, "scree": {"preset": "talus", "roughness_m": 0.2}}}
    s = trajectory_model_status(presets)
    assert s.uncalibrated and s.presets == {"rock": "bedrock", "scree": "talus"}
    assert s.text.startswith("UNCALIBRATED trajectory model") and "rock = bedrock" in s.text and "82 %" in s.text
    assert s.to_dict()["held_out_errors_of_the_presets"]["authume_p2"]["share_beyond_p99"] == pytest.approx(0.9792)
    typed = trajectory_model_status({"materials": {"rock": {"normal_restitution": 0.3}}})
    assert typed.status == "typed" and not typed.uncalibrated
    used = trajectory_model_status(presets, calibration_bootstrap="bootstrap.csv")
    assert not used.uncalibrated and "bootstrap.csv" in used.text and "not for the central run" in used.text
    assert trajectory_model_status(None).status == "no simulation"
