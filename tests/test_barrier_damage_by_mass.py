"""Damage states of a barrier per mass bin with the speeds and heights of the bin's own simulated mass class
(riskrf.risk.slope_models.SlopeModels._damage_by_mass): every class at once must give the very floats of
riskrf.hazard.barriers.damage_state_shares applied class by class (the per-class loop it replaced)."""
from types import MethodType, SimpleNamespace

import numpy as np
import pytest

from riskrf.core.units import kinetic_energy_kj
from riskrf.hazard.barriers import damage_state_shares
from riskrf.risk.slope_models import SlopeModels


def _per_class(cls, mid, radius, samples, height_m, cap):
    """The former per-class loop: damage_state_shares on each class's (blocks x bins) matrix."""
    shares = [np.zeros(mid.size) for _ in range(3)]
    for c, (vc, hc) in samples.items():
        j = cls == c
        over = np.asarray(hc)[:, None] - radius[j][None, :] > height_m
        got = damage_state_shares(kinetic_energy_kj(mid[j][None, :], vc[:, None]), over, cap)
        for out, part in zip(shares, got):
            out[j] = part
    return tuple(shares)


def _study(seed):
    rng = np.random.default_rng(seed)
    n_bins, n_classes = 40, 7
    mid = np.geomspace(50.0, 2.0e5, n_bins)
    radius = (3.0 * mid / (4.0 * np.pi * 2650.0)) ** (1.0 / 3.0)
    cls = np.minimum(np.arange(n_bins) * n_classes // n_bins, n_classes - 1)
    samples = {}
    for c in range(n_classes - 1):               # the last class holds bins but no samples
        n = 0 if c == 2 else int(rng.integers(5, 60))       # and class 2 none reached
        samples[c] = (rng.gamma(4.0, 4.0, n), np.round(rng.gamma(2.0, 0.6, n), 1))
    cap = 500.0
    v3 = samples[3][0]
    v3[:4] = np.sqrt(2000.0 * np.array([cap, cap / 3.0, cap, cap / 3.0]) / mid[cls == 3][0])   # at MEL and SEL
    study = SimpleNamespace(by_mass=(cls, samples), grid=SimpleNamespace(mid=mid), radius_m=radius,
                            _variant_pairs={}, _class_samples=lambda model, v, h: samples)
    study._class_pairs = MethodType(SlopeModels._class_pairs, study)
    return study, cls, mid, radius, samples, cap


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_all_classes_at_once_give_the_per_class_floats(seed):
    study, cls, mid, radius, samples, cap = _study(seed)
    model = object()
    for height_m in (0.5, 1.0, 2.0, 4.0):
        for c in (cap, 3.0 * cap, cap / 7.0):
            got = SlopeModels._damage_by_mass(study, model, None, None, height_m, c)
            want = _per_class(cls, mid, radius, samples, height_m, c)
            for g, w in zip(got, want):
                assert np.array_equal(g, w)
    assert len(study._variant_pairs) == 1                      # the pairs built once for the model
    got = SlopeModels._damage_by_mass(study, model, None, None, 1.0, cap)
    for part in got:                                           # no samples, or none reached: no share
        assert np.all(part[cls == 6] == 0) and np.all(part[cls == 2] == 0)
    assert 0 < got[1].max() and 0 < got[2].max() and np.all(got[0] >= got[2])


def test_a_capacity_that_is_not_positive_is_refused():
    study, *_ = _study(0)
    with pytest.raises(ValueError, match="mel_kj"):
        SlopeModels._damage_by_mass(study, object(), None, None, 1.0, 0.0)
