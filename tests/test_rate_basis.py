"""rate_basis in site files: an inventory of falls recorded on the road ("road") or released ("release")."""
import numpy as np
import pytest

from riskrf.app.assess import run_assessment
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
    the road line, counted per class on the same mass-coupled run (the corridor's estimator); one road share for
    all sizes does not."""
    from dataclasses import replace

    from riskrf.hazard.impact_energy import mass_model
    from riskrf.risk.mitigation import MitigationStudy, Option
    a = road_basis
    st = a.study
    opts = (Option("nothing", "none"), Option("again", "none"))
    probe = MitigationStudy(hazard=st.hazard, options=opts, road_share=st.road_share, context=st.context,
                            reference=st.reference, coupled_road_hits=st.coupled_road_hits)
    by_mass = probe.road_share_by_mass()["road_share"].to_numpy()
    assert np.ptp(by_mass) > 0.3 * by_mass.mean()      # the share depends on block size on this slope
    road = np.where(st.coupled_road_hits, 1.0, np.nan)          # the corridor's estimator on the same run
    from riskrf.hazard.mass_coupling import MassCoupledSamples
    v = st.hazard.velocity
    reach = MassCoupledSamples(v.mass_kg, road, road, v.edges_kg, "road").reach_probability(mass_model(st.hazard.mass))
    law = st.hazard.rate_per_year * reach
    got = probe.evaluate("nothing").road_falls_per_year
    assert got == pytest.approx(law, rel=0.01)
    one_share = replace(probe, coupled_road_hits=None).evaluate("nothing").road_falls_per_year   # one share, as before
    assert abs(one_share / law - 1) > abs(got / law - 1)
