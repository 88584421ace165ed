"""The 2-D kernel's specialisations give the same trajectories as its general form.

:func:`simulation.engine.run` passes ``m_drag`` = None (no material with a rolling drag) and ``sin_max_roll`` = None
(no segment steeper than ``max_rolling_slope_deg``) to :func:`simulation.kernel.simulate`, so numba compiles a
version with those features pruned (:func:`simulation.engine.kernel_features`).  Here the same scenario is run
through each specialisation it may use and through the general form (both features on, by patching
``kernel_features``); every output must be bitwise identical.
"""
from dataclasses import replace

import numpy as np
import pytest

import simulation
from simulation import engine

from .conftest import ROOT

SCENARIOS = ROOT / "simulation" / "scenarios"


def _scenario(name, drag=None, max_slope=None):
    sc = simulation.load_scenario(SCENARIOS / f"{name}.toml")
    if drag is not None:
        sc = replace(sc, materials=tuple(replace(m, rolling_drag=drag) for m in sc.materials))
    if max_slope is not None:
        sc = replace(sc, settings=replace(sc.settings, max_rolling_slope_deg=max_slope))
    return sc


def _outputs(result):
    """Every array the run returns: per block, per crossing, the envelopes and the recorded paths."""
    out = {f"block.{k}": v for k, v in result.per_block.items()}
    out.update({f"crossing.{k}": v for k, v in result.crossings.items()})
    out.update({f"path.{k}": v for k, v in result.paths.items()})
    out["envelope"] = result.envelope_acc
    return out


def _run(sc, features, monkeypatch, n=300):
    with monkeypatch.context() as m:
        if features is not None:
            m.setattr(engine, "kernel_features", lambda scenario: features)
        return _outputs(simulation.run(sc, n=n, seed=11, record_paths=20))


def _assert_identical(a, b):
    assert a.keys() == b.keys()
    for k in a:
        assert a[k].dtype == b[k].dtype and a[k].shape == b[k].shape, k
        assert np.array_equal(a[k], b[k], equal_nan=True), k


@pytest.mark.parametrize("name, drag, max_slope, expected", [
    ("peer_benchmark_profile", None, None, (False, False)),
    ("road_cut_barrier", None, None, (False, False)),
    ("peer_benchmark_profile", 0.3, None, (True, False)),
    ("peer_benchmark_profile", None, 55.0, (False, True)),     # its 59 and 63 deg faces
    ("peer_benchmark_profile", None, 70.0, (False, False)),    # a limit no face reaches
    ("cliff_talus_deposition", 0.2, None, (True, True)),
])
def test_kernel_features_name_what_a_scenario_uses(name, drag, max_slope, expected):
    assert engine.kernel_features(_scenario(name, drag, max_slope)) == expected


@pytest.mark.parametrize("name, max_slope", [("peer_benchmark_profile", None), ("road_cut_barrier", None),
                                             ("peer_benchmark_profile", 70.0)])
def test_without_drag_or_steep_faces_the_specialised_kernel_gives_the_general_kernels_trajectories(
        name, max_slope, monkeypatch):
    sc = _scenario(name, max_slope=max_slope)
    assert engine.kernel_features(sc) == (False, False)
    _assert_identical(_run(sc, None, monkeypatch), _run(sc, (True, True), monkeypatch))


@pytest.mark.parametrize("name, drag, max_slope", [
    ("peer_benchmark_profile", 0.3, None),       # drag only: the specialisation without the steep-face rule
    ("peer_benchmark_profile", None, 55.0),      # steep faces only: the one without drag
    ("cliff_talus_deposition", 0.2, None),       # both: the general kernel itself
])
def test_with_drag_or_steep_faces_the_result_matches_the_general_kernel(name, drag, max_slope, monkeypatch):
    sc = _scenario(name, drag, max_slope)
    specialised = _run(sc, None, monkeypatch)
    _assert_identical(specialised, _run(sc, (True, True), monkeypatch))
    # and the feature is really in play: without it the trajectories differ
    drag_on, steep_on = engine.kernel_features(sc)
    plain = _run(sc, (False, steep_on) if drag_on else (drag_on, False), monkeypatch)
    assert not np.array_equal(plain["block.x"], specialised["block.x"])
