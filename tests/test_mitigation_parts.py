"""The parts of the mitigation study: option kinds (riskrf.risk.options), the typed loss engine
(riskrf.risk.loss_engine) and the study (riskrf.risk.mitigation), and the old import paths."""
import numpy as np
import pytest

from riskrf.risk import loss_engine
from riskrf.risk.options import base, chain
from riskrf.risk.mitigation import Option

from .test_mitigation import OPTIONS, study


def test_every_option_kind_has_its_class_and_the_old_names_still_import():
    assert tuple(chain.KIND_CLASSES) == base.OPTION_KINDS
    for kind, cls in chain.KIND_CLASSES.items():
        assert issubclass(cls, base.OptionEffect) and isinstance(chain.effect_of(Option("x", kind)), cls)
    from riskrf.risk.mitigation import (MASS_BINS, OPTION_KINDS, MitigationError, _quantile_map,  # noqa: F401
                                        closure_cost_per_fall)
    from riskrf.risk.mitigation_inputs import SCALING_EFFECTIVENESS, MitigationError as E2
    assert MitigationError is E2 is base.MitigationError and MASS_BINS == loss_engine.MASS_BINS
    assert SCALING_EFFECTIVENESS == 0.8 and _quantile_map is not None


def test_the_engine_takes_typed_arrays_and_names_map_to_their_columns():
    """One capital cost column moves that option's total by exactly its value and nothing else; the named
    parameters of the tornado reach the same column."""
    s = study()
    central = s.central_parameters()
    P = {k: np.array([float(v)]) for k, v in central.items()}
    typed = s._space.typed(P)
    k = [o.name for o in OPTIONS].index("fence")
    assert typed.capital_cost[0, k] == central["capital_cost:fence"]
    assert typed.effect[0, s._space.effects["rate_reduction:scale"]] == 0.5
    base = s._engine.evaluate(typed)
    np.testing.assert_array_equal(base.total, s._central().total)
    bumped = typed.capital_cost.copy()
    bumped[0, k] += 1000.0
    from dataclasses import replace
    r = s._engine.evaluate(replace(typed, capital_cost=bumped))
    d = r.total[0] - base.total[0]
    # + 1,000 capital, its renewal at year 25 of the 50-year horizon discounted at 3 % (1.03^-25), and the
    # replacements after destructive impacts (replacement cost = capital cost) over the horizon (PV factor)
    pvf = (1 - 1.03 ** -50) / 0.03
    expected = 1000.0 * (1.0 + 1.03 ** -25) + pvf * base.replacements[0, k] * 1000.0
    assert base.replacements[0, k] > 0
    assert d[k] == pytest.approx(expected, rel=1e-12)
    assert np.all(np.delete(d, k) == 0.0)
    assert base["total"] is base.total                       # the dict view of earlier versions


def test_effect_basis_of_a_combination_follows_its_kinds():
    drape = Option("d", "drape", 1.0, zone_x_m=(1.0, 2.0))
    scale = Option("s", "scaling", 1.0, zone_x_m=(1.0, 2.0))
    away = Option("a", "realignment", 1.0)
    both = Option("b", "combined", options=("s", "d"))
    basis = chain.effect_basis(both, [scale, drape])       # both assumed parts named
    assert "released under the mesh" in basis and "ASSUMED containment 85%" in basis
    assert "ASSUMED effectiveness" in basis and "others derived" not in basis
    assert chain.effect_basis(scale, [scale]).startswith("derived zone and mass range, ASSUMED effectiveness")
    assert chain.effect_basis(away, [away]) == "geometry: the road leaves the slope"
    typed = Option("t", "fence", 1.0, capacity_kj=100, height_m=2, retention=0.5, repair_days=30)
    assert chain.effect_basis(typed, [typed]) == "ASSUMPTION: typed effectiveness (t)"
