"""Analytic checks of the trajectory simulator."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import simulation
from simulation.contact import (EN_CONSTANT, EN_VELOCITY, EN_WYLLIE, ET_CONSTANT, ET_FRICTION, impact,
                               stronge_sphere, wyllie_normal_restitution)

G = 9.81


def scenario(x, z, *, material=None, seeder=None, collectors=(), settings=None):
    mat = {"normal_restitution": {"law": "constant", "mean": 0.5}, "tangential": {"law": "constant", "mean": 1.0},
           "roughness_m": 0.0, "ground_motion": "slide", "ground_friction_angle_deg": 30.0}
    mat.update(material or {})
    sd = {"type": "point", "x": x[0] + 1.0, "height_m": 10.0, "mass_kg": 1000.0}
    sd.update(seeder or {})
    data = {"profile": {"x": list(x), "z": list(z), "material": "m"}, "materials": {"m": mat}, "seeder": sd,
            "collectors": list(collectors), "settings": {"envelope_bins": 10, **(settings or {})}}
    return simulation.scenario_from_dict(data, source="test")


def test_free_flight_follows_the_parabola_exactly():
    sc = scenario([0, 200], [0, 0], seeder={"x": 0.0, "height_m": 100.0, "vx_ms": 5.0, "vz_ms": 3.0},
                  collectors=[{"name": "c", "x": 20.0}])
    row = simulation.run(sc, n=1, seed=1).collector("c").iloc[0]
    t = 20.0 / 5.0
    assert row["time_s"] == pytest.approx(t, rel=1e-12)
    assert row["height_m"] == pytest.approx(100 + 3 * t - 0.5 * G * t * t, rel=1e-12)
    assert row["vz_ms"] == pytest.approx(3 - G * t, rel=1e-12)


def test_normal_drop_rebounds_to_e_squared_h():
    sc = scenario([0, 10], [0, 0], seeder={"x": 5.0, "height_m": 10.0})
    res = simulation.run(sc, n=1, seed=1, record_paths=1)
    p = res.paths
    first = np.argmax(p["vz"] > 0)               # state leaving the first impact
    apex = p["vz"][first] ** 2 / (2 * G)
    assert apex == pytest.approx(0.5 ** 2 * 10.0, rel=1e-9)
    assert p["x"][first] == pytest.approx(5.0)


def test_oblique_rebound_with_constant_coefficients():
    vn2, vt2, w2, en = impact(-4.0, 3.0, 0.0, 0.5, EN_CONSTANT, 0.4, ET_CONSTANT, 0.8, 0.0, False)
    assert (vn2, vt2, en) == pytest.approx((1.6, 2.4, 0.4))


def test_sliding_to_a_stop_over_the_friction_distance():
    psi = math.radians(20.0)
    mu = math.tan(math.radians(30.0))
    L = 100.0
    x = [0.0, L * math.cos(psi)]
    z = [L * math.sin(psi), 0.0]
    sc = scenario(x, z, seeder={"x": 1.0, "height_m": 0.0, "vx_ms": 8.0 * math.cos(psi),
                                "vz_ms": -8.0 * math.sin(psi)}, settings={"stop_velocity_ms": 0.0})
    res = simulation.run(sc, n=1, seed=1)
    d = 8.0 ** 2 / (2 * G * (mu * math.cos(psi) - math.sin(psi)))
    assert res.runout["reason"][0] == "stopped"
    assert (res.runout["x_stop_m"][0] - 1.0) / math.cos(psi) == pytest.approx(d, rel=1e-9)


def test_no_motion_when_tan_psi_below_mu():
    psi = math.radians(25.0)
    x = [0.0, 50.0]
    z = [50.0 * math.tan(psi), 0.0]
    sc = scenario(x, z, seeder={"x": 10.0, "height_m": 0.0}, material={"ground_friction_angle_deg": 26.0})
    res = simulation.run(sc, n=1, seed=1)
    assert res.runout["reason"][0] == "stopped" and res.runout["x_stop_m"][0] == pytest.approx(10.0)
    sc = scenario(x, z, seeder={"x": 10.0, "height_m": 0.0}, material={"ground_friction_angle_deg": 24.0})
    assert simulation.run(sc, n=1, seed=1).runout["reason"][0] == "left profile"


def test_rolling_sphere_accelerates_at_five_sevenths_g_sin_psi():
    psi = math.radians(30.0)
    x = [0.0, 100.0]
    z = [100.0 * math.tan(psi), 0.0]
    sc = scenario(x, z, seeder={"x": 0.0 + 1e-9, "height_m": 0.0},
                  material={"ground_motion": "roll", "ground_friction_angle_deg": 0.0},
                  collectors=[{"name": "c", "x": 40.0}], settings={"stop_velocity_ms": 0.0})
    row = simulation.run(sc, n=1, seed=1).collector("c").iloc[0]
    s = 40.0 / math.cos(psi)
    a = 5.0 / 7.0 * G * math.sin(psi)
    assert row["time_s"] == pytest.approx(math.sqrt(2 * s / a), rel=1e-7)
    assert row["velocity_ms"] == pytest.approx(math.sqrt(2 * a * s), rel=1e-7)
    assert row["angular_velocity_rads"] == pytest.approx(row["velocity_ms"] / row["radius_m"], rel=1e-9)


def test_stronge_stick_leaves_the_sphere_rolling():
    # Stick: 2/7 |slip| <= mu (1 + e) |vn|  ->  vt' = 5/7 vt + 2/7 r w  (Wyllie 2014, ch. 5)
    vt2, w2, stuck = stronge_sphere(-10.0, 3.0, 2.0, 0.5, 0.3, 0.8)
    assert stuck and vt2 == pytest.approx(5 / 7 * 3.0 + 2 / 7 * 0.5 * 2.0) and w2 == pytest.approx(vt2 / 0.5)


def test_stronge_slip_applies_coulomb_impulse():
    vn, vt, w, r, e, mu = -2.0, 10.0, 0.0, 0.5, 0.3, 0.2
    vt2, w2, stuck = stronge_sphere(vn, vt, w, r, e, mu)
    p = mu * (1 + e) * 2.0
    assert not stuck
    assert vt2 == pytest.approx(vt - p) and w2 == pytest.approx(w + 2.5 * p / r)


def test_wyllie_normal_restitution_values():
    # e_N = 19.5 theta^-1.03: about 0.19 at 90 deg, 1 near 17.9 deg, 2.5 at 7.35 deg (Wyllie 2014;
    # rockfall-simulation.md 2.1), capped at 2.5 below that.
    assert wyllie_normal_restitution(90.0) == pytest.approx(0.189, abs=5e-4)
    assert wyllie_normal_restitution(17.9) == pytest.approx(1.000, abs=2e-3)
    assert wyllie_normal_restitution(7.35) == pytest.approx(2.499, abs=2e-3)
    assert wyllie_normal_restitution(2.0) == 2.5


@settings(max_examples=300, deadline=None)
@given(vn=st.floats(-50, -0.01), vt=st.floats(-50, 50), w=st.floats(-100, 100), r=st.floats(0.05, 3),
       en=st.floats(0, 1), et=st.floats(0, 1), mu=st.floats(0, 3),
       en_law=st.sampled_from([EN_CONSTANT, EN_WYLLIE, EN_VELOCITY]), et_law=st.sampled_from([ET_FRICTION, ET_CONSTANT]))
def test_energy_never_increases_through_an_impact(vn, vt, w, r, en, et, mu, en_law, et_law):
    vn2, vt2, w2, _ = impact(vn, vt, w, r, en_law, en, et_law, et, mu, False)
    k = 0.4 * r * r
    before = vn * vn + vt * vt + k * w * w
    after = vn2 * vn2 + vt2 * vt2 + k * w2 * w2
    assert after <= before * (1 + 1e-9) + 1e-12


def test_energy_gain_only_when_asked():
    # A shallow impact with Wyllie's e_N = 2.5 and no friction would create energy.  The guard keeps the
    # kinematic rebound 2.5 |v_n|; the normal impact returns only sin^2(theta_i) = 1/101 of its energy,
    # the rest of the rebound is fed from v_t: out = 101 - 1 + 1/101.
    vn2, vt2, _, en = impact(-1.0, 10.0, 0.0, 0.5, EN_WYLLIE, 0.0, ET_CONSTANT, 1.0, 0.0, False)
    assert en == 2.5 and vn2 == pytest.approx(2.5)
    assert vn2 ** 2 + vt2 ** 2 == pytest.approx(100.0 + 1 / 101) and vt2 == pytest.approx((93.75 + 1 / 101) ** 0.5)
    vn2, vt2, _, en = impact(-1.0, 10.0, 0.0, 0.5, EN_WYLLIE, 0.0, ET_CONSTANT, 1.0, 0.0, True)
    assert en == 2.5 and vn2 == pytest.approx(2.5)


def test_barrier_catches_passes_through_or_is_overtopped():
    base = dict(seeder={"x": 0.0, "height_m": 20.0, "vx_ms": 10.0})
    sc = scenario([0, 200], [0, 0], collectors=[{"name": "b", "x": 10.0, "capacity_kj": 1e6, "height_m": 30}],
                  **base)
    res = simulation.run(sc, n=5, seed=1)
    assert (res.collector("b")["outcome"] == "caught").all() and (res.runout["reason"] == "caught by barrier").all()
    sc = scenario([0, 200], [0, 0], collectors=[{"name": "b", "x": 10.0, "capacity_kj": 10.0, "height_m": 30},
                                                 {"name": "after", "x": 11.0}], **base)
    res = simulation.run(sc, n=1, seed=1)
    before, after = res.collector("b").iloc[0], res.collector("after").iloc[0]
    assert before["outcome"] == "through"
    # Energy after the barrier = energy before - capacity (then free flight over 1 m adds potential energy).
    drop = 1000.0 * G * (before["height_m"] - after["height_m"]) / 1000.0
    assert after["energy_kj"] == pytest.approx(before["energy_kj"] - 10.0 + drop, rel=1e-9)
    sc = scenario([0, 200], [0, 0], collectors=[{"name": "b", "x": 10.0, "capacity_kj": 1e6, "height_m": 1.0}],
                  **base)
    assert simulation.run(sc, n=1, seed=1).collector("b")["outcome"].iloc[0] == "over"


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), n_seg=st.integers(1, 300))
def test_impact_search_matches_brute_force(seed, n_seg):
    """The tree search finds the same first impact as scanning the parabola against every segment."""
    from simulation.kernel import chord_slopes, find_impact
    from simulation.slope import Profile
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.uniform(0.1, 3.0, n_seg + 1))
    z = np.cumsum(rng.normal(-0.8, 1.0, n_seg + 1))
    if seed % 3 == 0:       # collinear runs
        z = np.interp(x, x[:: max(n_seg // 4, 1)], z[:: max(n_seg // 4, 1)])
    prof = Profile.build(x, z, np.zeros(n_seg, dtype=int), ["m"])
    x0 = rng.uniform(x[0], x[-1])
    z0 = prof.ground(x0) + rng.uniform(0.01, 20.0)
    vx, vz = rng.normal(0, 10), rng.normal(0, 5)
    seg = int(prof.segment_at(x0))
    t, k = find_impact(prof.x, prof.z, chord_slopes(prof.x, prof.z, prof.n_leaves), prof.tree_offset, prof.n_leaves, prof.run_first, prof.run_last,
                       x0, z0, vx, vz, G, seg, np.empty((3, 128), np.int64))
    ts = np.linspace(0, 60, 600_001)[1:]
    xs = x0 + vx * ts
    inside = (xs >= x[0]) & (xs <= x[-1])
    below = inside & (z0 + vz * ts - 0.5 * G * ts ** 2 < np.interp(xs, x, z))
    if below.any():
        t_ref = ts[np.argmax(below)]
        assert k >= 0 and t == pytest.approx(t_ref, abs=2e-4)
        assert x[k] - 1e-9 <= x0 + vx * t <= x[k + 1] + 1e-9
    else:
        assert k == -1


def test_with_barrier_turns_a_collector_into_a_fence():
    sc = scenario([0, 200], [0, 0], seeder={"x": 0.0, "height_m": 20.0, "vx_ms": 10.0},
                  collectors=[{"name": "line", "x": 10.0}])
    fenced = sc.with_barrier("line", capacity_kj=1e9, height_m=100.0)
    res = simulation.run(fenced, n=3, seed=1)
    assert (res.collector("line")["outcome"] == "caught").all()
    assert simulation.run(sc, n=3, seed=1).collector("line")["outcome"].eq("crossed").all()


def test_rolling_cylinder_accelerates_at_two_thirds_g_sin_psi():
    # A solid cylinder or disc (I = m r^2 / 2) rolling without slip: a = g sin(psi) / (1 + 1/2).
    psi = math.radians(30.0)
    sc = scenario([0.0, 100.0], [100.0 * math.tan(psi), 0.0],
                  seeder={"x": 1e-9, "height_m": 0.0, "shape": "cylinder", "aspect_ratio": 0.5},
                  material={"ground_motion": "roll", "ground_friction_angle_deg": 0.0},
                  collectors=[{"name": "c", "x": 40.0}], settings={"stop_velocity_ms": 0.0})
    row = simulation.run(sc, n=1, seed=1).collector("c").iloc[0]
    s = 40.0 / math.cos(psi)
    assert row["time_s"] == pytest.approx(math.sqrt(2 * s / (2.0 / 3.0 * G * math.sin(psi))), rel=1e-7)
    # radius from m = rho pi r^2 (2 r x aspect ratio); rotational energy 1/2 (1/2 m r^2) w^2
    r = (1000.0 / (2 * math.pi * 2650.0 * 0.5)) ** (1 / 3)
    assert row["radius_m"] == pytest.approx(r) and row["inertia_factor"] == 0.5
    assert row["energy_rotational_kj"] == pytest.approx(0.5 * row["energy_translational_kj"], rel=1e-9)


def test_stronge_stick_for_a_cylinder():
    from simulation.contact import stronge_body
    vt2, w2, stuck = stronge_body(-10.0, 3.0, 2.0, 0.5, 0.3, 0.8, 0.5)
    assert stuck and vt2 == pytest.approx(2 / 3 * 3.0 + 1 / 3 * 0.5 * 2.0)
