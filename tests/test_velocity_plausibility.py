"""Velocities above what a free fall from the profile could give are warned about."""
import numpy as np
import pandas as pd
import pytest

import simulation
from riskrf.cli import main
from riskrf.core.validation import RiskrfWarning
from riskrf.io.velocities import (
    FREE_FALL_MARGIN,
    PLAUSIBLE_MAX_MS,
    free_fall_drop_m,
    plausible_velocity_ms,
    read_velocities,
)

from .conftest import INVENTORIES
from .test_simulation_run import BARRIER

G = 9.81


def _file(tmp_path, speeds, name="v.csv"):
    f = tmp_path / name
    pd.DataFrame({"velocity_ms": speeds}).to_csv(f, index=False)
    return f


def test_free_fall_limit_is_sqrt_2gh_plus_the_stated_margin():
    v, how = plausible_velocity_ms(20.0)
    assert v == pytest.approx(1.1 * np.sqrt(2 * G * 20.0)) and FREE_FALL_MARGIN == 0.10     # 21.8 m/s
    assert "free fall of 20 m" in how and "10%" in how
    v0 = 3.0
    assert plausible_velocity_ms(20.0, v0)[0] == pytest.approx(1.1 * np.sqrt(v0 ** 2 + 2 * G * 20.0))
    v, how = plausible_velocity_ms(None)
    assert v == PLAUSIBLE_MAX_MS == 50.0 and "free fall of 127 m" in how and "ASSUMPTION" in how
    with pytest.raises(ValueError, match="drop_height_m = -5"):
        plausible_velocity_ms(-5)


def test_warning_names_row_value_and_plausible_limit(tmp_path):
    f = _file(tmp_path, [12.0, 14.5, 25.0, 16.0, 21.0])
    with pytest.warns(RiskrfWarning) as rec:
        df = read_velocities(f, drop_height_m=20.0)
    msg = str(rec[0].message)
    assert "1 of 5 velocities exceed what a free fall could give" in msg       # 21.0 < 21.8 is plausible
    assert "row 4, column 'velocity_ms': 25 m/s" in msg                        # file line 4 holds 25.0
    assert "plausible at most 21.8 m/s, a free fall of 20 m" in msg
    assert df.attrs["warnings"] == [msg] and len(df) == 5                       # warned, not dropped


def test_without_a_drop_height_the_stated_proxy_applies(tmp_path):
    f = _file(tmp_path, [12.0, 80.0, 14.0, 15.0])
    with pytest.warns(RiskrfWarning, match=r"row 3, column 'velocity_ms': 80 m/s; plausible at most 50 m/s, the "
                                           r"speed of a free fall of 127 m \(ASSUMPTION"):
        read_velocities(f)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert read_velocities(_file(tmp_path, [12.0, 35.0], "ok.csv")).attrs["warnings"] == []


def test_km_h_values_are_checked_after_conversion_and_named_in_both_units(tmp_path):
    f = tmp_path / "kmh.csv"
    pd.DataFrame({"Velocity (km/h)": [36.0, 54.0, 108.0]}).to_csv(f, index=False)
    with pytest.warns(RiskrfWarning, match=r"row 4, column 'Velocity \(km/h\)': 30 m/s \(= 108.0 km/h\)"):
        read_velocities(f, drop_height_m=15.0)        # limit 1.1 sqrt(2 g 15) = 18.9 m/s


def test_scenario_drop_bounds_every_simulated_speed():
    """Energy conservation: no simulated block passes the barrier faster than the free-fall limit."""
    sc = simulation.load_scenario(BARRIER)
    h, v0 = free_fall_drop_m(sc, "barrier")
    prof = sc.profile
    top = np.interp(np.linspace(6.0, 14.0, 801), prof.x, prof.z).max() + 1.5     # seeder x 6-14 m, height <= 1.5
    assert h == pytest.approx(top - np.interp(100.0, prof.x, prof.z)) and v0 == pytest.approx(1.5)
    res = simulation.run(sc, n=3000, seed=4)
    v = res.collector("barrier")["velocity_ms"].to_numpy()
    assert v.size > 100
    assert v.max() <= np.sqrt(v0 ** 2 + 2 * G * h)          # the limit before the margin already holds


def test_cli_energy_reports_the_warning_in_its_summary(tmp_path, capsys):
    rng = np.random.default_rng(1)
    speeds = rng.normal(15, 2, 400).clip(1)
    speeds[7] = 45.0
    f = _file(tmp_path, speeds)
    rc = main(["energy", "--inventory", str(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv"),
               "--velocities", str(f), "--drop-height", "30", "--bootstrap", "10", "--fence", "1000",
               "--out", str(tmp_path / "o")])
    assert rc == 0
    text = capsys.readouterr().out
    assert "row 9, column 'velocity_ms': 45 m/s; plausible at most 26.7 m/s, a free fall of 30 m" in text
    rc = main(["energy", "--inventory", str(INVENTORIES / "lauterbrunnen" / "lauterbrunnen_tls_2018.csv"),
               "--velocities", str(f), "--drop-height", "tall", "--out", str(tmp_path / "p")])
    assert rc == 2 and "--drop-height = 'tall'" in capsys.readouterr().err


def test_release_speed_takes_the_largest_magnitude_a_seeder_can_draw():
    """A block thrown downward (vz < 0) or towards -x: the release speed is the largest |v| of the seeder's
    ranges, not the largest signed value (vz uniform in -6..-1 m/s gives up to 6 m/s, not 1 m/s)."""
    from dataclasses import replace
    from simulation.scenario import Distribution
    sc = simulation.load_scenario(BARRIER)
    sd = replace(sc.seeder, vx_ms=Distribution("uniform", {"low": -2.0, "high": 0.5}),
                 vz_ms=Distribution("uniform", {"low": -6.0, "high": -1.0}))
    _, v0 = free_fall_drop_m(replace(sc, seeder=sd), "barrier")
    assert v0 == pytest.approx(np.hypot(2.0, 6.0))
    sd = replace(sc.seeder, vz_ms=Distribution("normal", {"mean": -3.0, "std": 0.5}))
    assert free_fall_drop_m(replace(sc, seeder=sd), "barrier")[1] == pytest.approx(np.hypot(1.5, 5.0))
