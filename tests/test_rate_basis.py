"""rate_basis in site files: an inventory of falls recorded on the road ("road") or released ("release")."""
import numpy as np
import pytest

from riskrf.app.assess.run import run_assessment
from riskrf.app.site import SiteError, load_site

from .test_assess import _site_copy


@pytest.fixture(scope="module")
def road_basis(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("road_basis")
    site = _site_copy(tmp, replace={"rate_scale = 0.05 ": "rate_scale = 0.05\nrate_basis = \"road\" ",
                                    "option_blocks = ": "option_blocks = 2000 #"})
    return run_assessment(load_site(site))


def test_road_basis_reproduces_the_falls_recorded_on_the_road(road_basis):
    a = road_basis
    inv = a.inventory
    gr = a.frequency.power_law
    # recorded on the road: the inventory's falls at or above m_min and below it, per year, times rate_scale 0.05
    small = np.sum(inv.masses < gr.m_min)
    recorded = (gr.rate_min + small / inv.duration_years) * 0.05
    assert a.study.evaluate("do nothing").road_falls_per_year == pytest.approx(recorded, rel=1e-9)
    assert a.release_factor > 1          # fewer falls reach the road than are released
    s = a.summary()
    assert s["hazard"]["rate_basis"] == "road" and s["hazard"]["release_factor"] == a.release_factor
    assert "rate_basis = 'road'" in s["hazard"]["rate_source"]


def test_release_basis_is_stated_and_bad_basis_refused(tmp_path):
    site = _site_copy(tmp_path, replace={"rate_scale = 0.05": 'rate_scale = 0.05\nrate_basis = "patrol"'})
    with pytest.raises(SiteError, match="inventory.rate_basis = 'patrol' must be 'release'"):
        load_site(site)


def test_road_share_by_block_size_matches_the_mass_law_reach(road_basis):
    """The road falls of the mitigation engine (one road share per mass class) equal the mass law's own reach of
    the road line, counted per class (the corridor's estimator) on the blocks of both runs of the slope: the
    mass-coupled run and the seeder's reference run, pooled by mass class; one road share for all sizes does not."""
    from dataclasses import replace

    from riskrf.hazard.mass_models import mass_model
    from riskrf.risk.measures import road_crossings
    from riskrf.risk.mitigation import MitigationStudy, Option
    a = road_basis
    st = a.study
    opts = (Option("nothing", "none"), Option("again", "none"))
    probe = MitigationStudy(hazard=st.hazard, options=opts, road_share=st.road_share, context=st.context,
                            reference=st.reference, coupled_road_hits=st.coupled_road_hits)
    by_mass = probe.road_share_by_mass()["road_share"].to_numpy()
    assert np.ptp(by_mass) > 0.3 * by_mass.mean()      # the share depends on block size on this slope
    v, ref = st.hazard.velocity, st.reference
    at_ref = np.zeros(ref.n, dtype=bool)
    at_ref[ref.collector("barrier", first_only=True)["block"].to_numpy()] = True
    road_ref = np.zeros(ref.n, dtype=bool)
    road_ref[road_crossings(ref, "road")] = True
    m_ref = np.asarray(ref.blocks["mass"])
    inside = (m_ref >= v.edges_kg[0]) & (m_ref <= v.edges_kg[-1])
    k_c, k_r = v.class_of(v.mass_kg), v.class_of(m_ref)
    at_c = np.asarray(v.reached, dtype=bool)
    road_c = np.asarray(st.coupled_road_hits, dtype=bool) & at_c
    mm = mass_model(st.hazard.mass)
    law = 0.0
    for c in range(v.n_bins):       # falls per class x reach of the barrier (coupled run) x pooled road share
        p_class = float(mm.sf(v.edges_kg[c]) - mm.sf(v.edges_kg[c + 1]))
        n_at = (at_c & (k_c == c)).sum() + (at_ref & inside & (k_r == c)).sum()
        n_road = (road_c & (k_c == c)).sum() + (road_ref & at_ref & inside & (k_r == c)).sum()
        law += p_class * v.reach_by_class[c] * n_road / n_at
    law *= st.hazard.rate_per_year
    got = probe.evaluate("nothing").road_falls_per_year
    assert got == pytest.approx(law, rel=0.02)          # the engine's bins against the classes' exact boundaries
    one_share = replace(probe, coupled_road_hits=None).evaluate("nothing").road_falls_per_year   # one share, as before
    assert abs(one_share / law - 1) > abs(got / law - 1)
