"""The design basis a checking engineer signs: design energies, partial factors and required values of
ONR 24810, UNI 11211-4 and a return-period energy (riskrf.hazard.design_basis), and the catchment retention
(riskrf.hazard.catchment)."""
import numpy as np
import pandas as pd
import pytest
from scipy import stats

import simulation
from riskrf.hazard.annual_hazard import EnergyHazard
from riskrf.hazard.design_block import DesignBlock
from riskrf.hazard.catchment import catchment_retention, cut_geometry, odot_chart_applies, with_chart
from riskrf.hazard.design_basis import (DesignBasis, design_basis_from_site, required_product_class,
                                        residual_height_category, round_up)
from riskrf.hazard.design_requirement import design_requirement, position_search
from riskrf.app.site import SiteError, load_site

from .conftest import ROOT

RHO = 2700.0


def _hazard(rate=0.01, v=20.0, h=2.0):
    """One speed (v [m/s]) and one bounce height (h [m]) for every arriving fall: the percentiles are exact."""
    return EnergyHazard(mass=stats.lognorm(s=1.0, scale=3000.0), velocity=np.full(2000, v), rate_per_year=rate,
                        heights_m=np.full(2000, h), collector="barrier")


def _block(volume_m3=2.0):
    m = volume_m3 * RHO
    return DesignBlock(rule="percentile", mass_kg=m, volume_m3=volume_m3,
                       diameter_m=float((6 * volume_m3 / np.pi) ** (1 / 3)), basis="test", assumptions=(),
                       alternatives=pd.DataFrame())


def test_uni11211_worked_example_design_energy_and_required_class():
    # Worked example of shared/research/domain-methods.md section 3.3 ([D]: derived by hand from the UNI 11211-4
    # formula E_d = 1/2 Vol rho gVolF gg (v_t gTr gDp)^2, not a published example): Vol 2 m3, rho 2700 kg/m3,
    # v_t 20 m/s -> E_k 1080 kJ; all factors 1.10 -> E_d 1739.4 kJ; all 1.02 -> 1192.4 kJ.
    req = design_requirement(_hazard(), DesignBasis("UNI 11211-4"), block=_block(), density_kg_m3=RHO,
                             x_m=100.0, clearance_m=20.0)
    assert req.E_k_kj == pytest.approx(1080.0, rel=1e-9)
    assert req.E_d_kj == pytest.approx(1739.4, abs=0.05)
    assert req.v_d_ms == pytest.approx(20 * 1.21)
    assert req.required_mel_kj == pytest.approx(1.2 * 1739.4, abs=0.1)       # E_d <= MEL / gamma_E, gamma_E 1.2
    assert req.required_class_kj == 3000.0                                    # the next class above 2087 kJ
    # height: H_tot >= h_d + f_min, h_d = h_t gTr gDp = 2.42 m, f_min between 0.5 m and half the block size (the
    # RocFall UNI 11211 design page quoting UNI 11211-4:2012), the larger: the radius 0.7816 m -> 3.20 m, a 3.5 m net
    r = (6 * 2.0 / np.pi) ** (1 / 3) / 2
    assert req.required_height_m == pytest.approx(2.0 * 1.21 + r)
    assert req.required_net_height_m == 3.5
    small = design_requirement(_hazard(), DesignBasis("UNI 11211-4"), block=_block(0.1), density_kg_m3=RHO)
    assert small.required_height_m == pytest.approx(2.42 + 0.5)          # radius 0.29 m < 0.5 m: f_min 0.5 m
    # deflection: permitted maximum elongation = clearance / gamma_d (1.3)
    assert req.permitted_elongation_m == pytest.approx(20.0 / 1.3)
    high = design_requirement(_hazard(), DesignBasis("UNI 11211-4", factors={"gamma_Tr": 1.02, "gamma_Dp": 1.02,
                                                                             "gamma_VolF": 1.02}),
                              block=_block(), density_kg_m3=RHO)
    assert high.E_d_kj == pytest.approx(1192.4, abs=0.05)


def test_onr24810_rare_and_frequent_design_events():
    # E_d = 1/2 (m_k gamma_m)(v_k gamma_v)^2: 5400 kg x 1.1 at 20 m/s x 1.1 -> 1080 x 1.1 x 1.21 = 1437.48 kJ
    basis = DesignBasis("ONR 24810", factors={"gamma_m": 1.1, "gamma_v": 1.1}, stated=("gamma_m", "gamma_v"))
    rare = design_requirement(_hazard(rate=0.01), basis, block=_block(), density_kg_m3=RHO)
    assert rare.E_d_kj == pytest.approx(1437.48, rel=1e-9)
    assert rare.design_event == "rare" and rare.required_mel_kj == pytest.approx(1437.48)
    assert rare.required_class_kj == 1500.0
    assert basis.unverified == []                   # stated factors are not flagged; gamma_d = 1.2 has a source
    assert DesignBasis("ONR 24810").unverified == ["gamma_m", "gamma_v"]
    # the same block arriving several times a year: frequent -> designed against SEL = MEL/3
    freq = design_requirement(_hazard(rate=20.0), basis, block=_block(), density_kg_m3=RHO)
    assert freq.design_event == "frequent"
    assert freq.required_mel_kj >= 3 * 1437.48 - 1e-6


def test_return_period_basis_is_the_T_year_energy():
    hz = _hazard(rate=2.0)
    req = design_requirement(hz, DesignBasis("return period", design_T=100.0), block=None, density_kg_m3=RHO)
    m_T = stats.lognorm(s=1.0, scale=3000.0).isf(1.0 / (100.0 * 2.0))
    assert req.E_d_kj == pytest.approx(0.5 * m_T * 20.0 ** 2 / 1000.0, rel=2e-3)
    # no standard sets "30-year energy <= SEL": off by default, the T-year energy alone sets the MEL
    assert req.required_mel_kj == pytest.approx(req.E_d_kj)
    assert "owner option" not in req.governs
    # the owner option on: the 30-year energy against SEL also bounds the MEL: MEL >= 3 E_30
    on = design_requirement(hz, DesignBasis("return period", design_T=100.0, frequent_events_sel=True), block=None,
                            density_kg_m3=RHO)
    e30 = 0.5 * stats.lognorm(s=1.0, scale=3000.0).isf(1.0 / 60.0) * 400 / 1000
    assert on.required_mel_kj == pytest.approx(max(on.E_d_kj, 3 * e30), rel=2e-3)
    assert "owner option frequent_events_sel, not in return period" in on.governs


def test_owner_option_frequent_events_sel_moves_the_uni_mel_and_is_labelled():
    # UNI 11211-4 sets E_d gamma_E <= MEL (RocFall UNI 11211 design page, UNI 11211-4:2012); the 30-year energy vs
    # SEL is an owner option: with it off the MEL is E_d x 1.2; on, max(E_d x 1.2, 3 E_30), labelled "not in UNI"
    hz = _hazard(rate=5.0)                      # 150 falls in 30 years: the 30-year energy is defined
    off = design_requirement(hz, DesignBasis("UNI 11211-4"), block=_block(), density_kg_m3=RHO)
    assert off.required_mel_kj == pytest.approx(1.2 * off.E_d_kj)
    assert off.governs == "E_d x gamma_E (1.2) <= MEL (UNI 11211-4)"
    on = design_requirement(hz, DesignBasis("UNI 11211-4", frequent_events_sel=True), block=_block(),
                            density_kg_m3=RHO)
    e30 = on.frequent_energy_kj
    assert 3 * e30 > 1.2 * on.E_d_kj             # the frequent rule governs here
    assert on.required_mel_kj == pytest.approx(3 * e30)
    assert on.governs.endswith("(frequent events; owner option frequent_events_sel, not in UNI 11211-4)")
    assert "owner option frequent_events_sel, not in UNI 11211-4" in on.text()
    summ = on.summary()["value"]
    assert any("owner option frequent_events_sel ON" in k for k in summ.index)
    assert any("owner option frequent_events_sel off" in k for k in off.summary()["value"].index)
    # the basis text says which rule is from the standard and which are owner options
    t = DesignBasis("UNI 11211-4").text()
    assert "Rules from UNI 11211-4:" in t and "Owner options (not in UNI 11211-4):" in t
    assert "30-year impact energy <= SEL = MEL/3 (frequent_events_sel) [off]" in t
    rules = DesignBasis("UNI 11211-4", frequent_events_sel=True).rules().set_index("rule")
    assert rules.loc["30-year impact energy <= SEL = MEL/3 (frequent_events_sel)", "source"] == \
        "owner option, not in UNI 11211-4"
    assert rules.loc["30-year impact energy <= SEL = MEL/3 (frequent_events_sel)", "in force"] == "yes"
    # the frequent-events check of a candidate appears only with the option on
    cands = [("f", 3000.0, 6.0)]
    chk = lambda r: list(r.candidates["check"])  # noqa: E731
    assert not any(c.startswith("frequent") for c in chk(design_requirement(hz, DesignBasis("UNI 11211-4"),
                                                          block=_block(), density_kg_m3=RHO, candidates=cands)))
    assert any(c.startswith("frequent") for c in chk(design_requirement(
        hz, DesignBasis("UNI 11211-4", frequent_events_sel=True), block=_block(), density_kg_m3=RHO,
        candidates=cands)))


def test_candidate_checks_deflection_and_residual_category():
    basis = DesignBasis("UNI 11211-4", elongation_m={"short": 15.0, "long": 16.0})
    req = design_requirement(_hazard(), basis, block=_block(), density_kg_m3=RHO, clearance_m=20.0,
                             candidates=[("short", 3000.0, 4.0), ("long", 2000.0, 3.0)])
    c = req.candidates.set_index(["fence", "check"])["adequate"]
    elong = {f: v for (f, chk), v in c.items() if chk.startswith("elongation")}
    assert elong == {"short": True, "long": False}        # 15 x 1.3 = 19.5 <= 20; 16 x 1.3 = 20.8 > 20
    energy = {f: v for (f, chk), v in c.items() if chk.startswith("energy")}
    assert energy == {"short": True, "long": False}
    height = {f: v for (f, chk), v in c.items() if chk.startswith("height")}
    assert height == {"short": True, "long": False}       # 3.20 m needed: 4 m passes, 3 m does not
    assert [residual_height_category(s) for s in (0.75, 0.5, 0.49, 0.3, 0.29)] == ["A", "A", "B", "B", "C"]
    with pytest.raises(ValueError, match="between 0 and 1"):
        residual_height_category(1.2)


def test_product_class_and_rounding():
    assert required_product_class(2000.0) == 2000.0
    assert required_product_class(2000.1) == 3000.0
    assert np.isnan(required_product_class(9000.0))
    assert round_up(3.5) == 3.5 and round_up(3.51) == 4.0


def test_bad_basis_and_factors_are_refused():
    with pytest.raises(ValueError, match="design.basis"):
        design_basis_from_site({"basis": "EN 1997"})
    with pytest.raises(ValueError, match="gamma_m is not a factor"):
        design_basis_from_site({"basis": "UNI 11211-4", "gamma_m": 1.1})
    with pytest.raises(ValueError, match="between 1.0 and 2.0"):
        design_basis_from_site({"basis": "UNI 11211-4", "gamma_Tr": 0.9})


def test_site_file_design_errors_name_the_field(tmp_path):
    from .test_assess import _site_copy
    path = _site_copy(tmp_path, replace={'basis = "UNI 11211-4"': 'basis = "SIA 261"'})
    with pytest.raises(SiteError, match="design.basis = 'SIA 261'"):
        load_site(path)
    path = _site_copy(tmp_path, replace={'basis = "UNI 11211-4"': 'basis = "ONR 24810"\ngamma_m = 1.1',
                                         'revision = "A"': 'revision = "B"'})
    site = load_site(path)
    assert site.design.basis == "ONR 24810" and site.report.revision == "B"


def test_position_search_reach_never_grows_downslope():
    from riskrf import fit_gutenberg_richter, read_inventory
    from riskrf.hazard.simulated import energy_hazard
    inv = read_inventory(ROOT / "riskrf" / "data" / "lauterbrunnen_tls_2018.csv")
    gr = fit_gutenberg_richter(inv, m_max=2.0e6)
    sc = simulation.load_scenario(ROOT / "simulation" / "scenarios" / "road_cut_barrier.toml")
    hz = energy_hazard(gr, sc, "barrier", rate_per_year=gr.rate_min * 0.05, n=1200, seed=3)
    ps = position_search(hz, sc, DesignBasis("return period", design_T=100.0), n=1200, seed=3,
                         positions_m=[60.0, 80.0, 100.0, 118.0])
    reach = ps.table["reach_share"].to_numpy()
    assert np.all(np.diff(reach) <= 1e-12)                # a block crossing x2 crossed every x1 < x2 first
    assert list(ps.table["x_m"]) == [60.0, 80.0, 100.0, 118.0]
    assert (ps.table["clearance_m"] == 120.0 - ps.table["x_m"]).all()
    with pytest.raises(ValueError, match="outside the profile"):
        position_search(hz, sc, DesignBasis("return period"), positions_m=[500.0], n=200)


def test_catchment_geometry_widths_and_chart_comparison():
    path = ROOT / "simulation" / "scenarios" / "odot_catchment_cut.toml"
    sc = simulation.load_scenario(path)
    toe, height, angle = cut_geometry(sc.profile)
    # the scenario's 60 ft (18.3 m) 0.25H:1V cut: toe at 3 + 18.3 / 4 = 7.575 m, face atan(4) = 75.96 deg
    assert (toe, height) == (pytest.approx(7.575), pytest.approx(18.3))
    assert angle == pytest.approx(np.degrees(np.arctan(4.0)))
    assert odot_chart_applies(height, angle) == ""
    assert "outside" in odot_chart_applies(50.0, angle)
    study = catchment_retention(sc, n=400, seed=2)
    w = [study.widths[q] for q in (90.0, 95.0, 99.0)]
    assert w[0] <= w[1] <= w[2] or np.isnan(w[2])
    assert np.all(np.diff(study.curve["retained"]) >= 0)
    c = with_chart(study, [(3.0, 80.0)], "a test chart")
    assert c.chart["difference_points"].iloc[0] == pytest.approx(100 * study.retained_at(3.0) - 80.0)
    with pytest.raises(ValueError, match="chart_source"):
        with_chart(study, [(3.0, 80.0)], "")


def test_option_scenario_builds_the_recommended_option_into_the_slope():
    from riskrf.app.site_design import option_scenario
    site = load_site(ROOT / "riskrf" / "data" / "demo_site.toml")
    sc = simulation.load_scenario(site.resolve(site.hazard.scenario))
    dug = option_scenario(site, sc, "catch ditch")          # 8 m x 2 m at x = 85 m
    from riskrf.risk.measures import ground_z
    assert float(ground_z(dug.profile, 89.0)) == pytest.approx(float(ground_z(sc.profile, 93.0)) - 2.0)
    fenced = option_scenario(site, sc, "scaling + fence 5000 kJ")
    barrier = fenced.collectors[fenced.collector_index("barrier")]
    assert (barrier.capacity_kj, barrier.height_m) == (5000.0, 7.0)
    assert option_scenario(site, sc, "rock shed") is None and option_scenario(site, sc, "do nothing") is None


def test_return_period_basis_without_a_T_year_event_says_why():
    hz = _hazard(rate=0.001)                  # 0.1 falls reach the line in 100 years: no 100-year event
    with pytest.raises(ValueError, match="fewer than one fall"):
        design_requirement(hz, DesignBasis("return period", design_T=100.0), block=None)
    # with a design block the basis falls back to it for the height, but the energy is still undefined
    with pytest.raises(ValueError, match="fewer than one fall reaches the line in 100 years"):
        design_requirement(hz, DesignBasis("return period", design_T=100.0), block=_block())


# ---- ONR 24810 event-frequency fractiles and consequence classes, elongation, kits ----
def test_onr24810_event_frequency_class_sets_the_design_block_fractile():
    # Trumer Schutzbauten's summary of ONR 24810, "Design Block" table: EF4 n >= 10/yr V98, EF3 1 <= n < 10 V97,
    # EF2 0.03 <= n < 1 V96, EF1 n < 0.03 V95 (a design-block SIZE fractile)
    from riskrf.hazard.design_basis import onr24810_event_frequency_class as efc
    assert [efc(n)[:2] for n in (1.0, 5.0, 12.0)] == [("EF3", 97.0), ("EF3", 97.0), ("EF4", 98.0)]
    assert [efc(n)[:2] for n in (10.0, 9.99, 0.5, 0.03, 0.0299, 0.0)] == [
        ("EF4", 98.0), ("EF3", 97.0), ("EF2", 96.0), ("EF2", 96.0), ("EF1", 95.0), ("EF1", 95.0)]
    with pytest.raises(ValueError, match="falls_per_year"):
        efc(-1.0)


@pytest.mark.parametrize("rate, cls, q", [(1.0, "EF3", 97.0), (5.0, "EF3", 97.0), (12.0, "EF4", 98.0)])
def test_onr24810_design_requirement_takes_the_fractile_of_the_event_frequency(rate, cls, q):
    from riskrf.hazard.design_block import design_block
    hz = _hazard(rate=rate)
    sizes = np.linspace(0.1, 10.0, 100)                       # block survey [m3]
    block = design_block(hz, rule="percentile", percentile=97.0, survey_volumes_m3=sizes, survey_source="survey",
                         density_kg_m3=RHO)
    basis = DesignBasis("ONR 24810", consequence_class="CC2")
    req = design_requirement(hz, basis, block=block, density_kg_m3=RHO)
    assert req.event_frequency_class == cls and req.design_block_fractile == q
    assert req.block_mass_kg == pytest.approx(np.percentile(sizes, q) * RHO)
    replaced = any("replacing design_block.percentile = 97" in n for n in req.notes)
    assert replaced == (q != 97.0)
    assert req.summary()["value"]["ONR 24810 event-frequency class (falls per year)"] == cls
    # a block of another rule is kept, and the output says it is not the standard approach
    other = design_requirement(hz, basis, block=_block(), density_kg_m3=RHO)
    assert other.block_mass_kg == pytest.approx(2.0 * RHO)
    assert any(f"asks for the V{q:g}" in n and "[confirm against the standard]" in n for n in other.notes)


def test_onr24810_consequence_class_and_its_factors():
    from riskrf.hazard.design_basis import ONR_CONSEQUENCE_CLASSES
    assert set(ONR_CONSEQUENCE_CLASSES) == {"CC1", "CC2", "CC3"}
    # no factor value could be read: not stated -> 1.0 in force and flagged "[confirm against the standard]"
    plain = design_requirement(_hazard(), DesignBasis("ONR 24810", consequence_class="CC3"), block=_block(),
                               density_kg_m3=RHO)
    assert plain.E_d_kj == pytest.approx(1080.0)
    assert any("consequence class CC3 were not read" in n and "[confirm against the standard]" in n
               for n in plain.notes)
    assert "consequence class CC3 (high consequence" in plain.basis.text()
    assert "consequence class NOT STATED" in DesignBasis("ONR 24810").text()
    assert any("consequence class not stated" in n
               for n in design_requirement(_hazard(), DesignBasis("ONR 24810"), block=_block(),
                                           density_kg_m3=RHO).notes)
    # the class's factors, once stated, are applied: E_d = 1/2 (m gamma_m)(v gamma_v)^2 = 1080 x 1.1 x 1.2^2
    stated = design_requirement(_hazard(), design_basis_from_site({"basis": "ONR 24810", "consequence_class": "CC3",
                                                                   "gamma_m": 1.1, "gamma_v": 1.2}),
                                block=_block(), density_kg_m3=RHO)
    assert stated.E_d_kj == pytest.approx(1080.0 * 1.1 * 1.44)
    assert not any("were not read" in n for n in stated.notes)
    with pytest.raises(ValueError, match="design.consequence_class = 'CC4'"):
        design_basis_from_site({"basis": "ONR 24810", "consequence_class": "CC4"})


def test_elongation_in_either_documented_form_and_kits_in_the_checks():
    # one number for every fence, or a table {fence name: metres} (docs/user-guide/design-basis.md)
    one = design_basis_from_site({"elongation_m": 5.0})
    table = design_basis_from_site({"elongation_m": {"fence 2000 kJ": 5.0, "fence 3000 kJ": 7.0}})
    assert one.kit_elongation_m("any fence") == 5.0
    assert table.kit_elongation_m("fence 3000 kJ") == 7.0 and table.kit_elongation_m("other") is None
    for bad in ("five", -1.0, {"fence 2000 kJ": 0.0}, True):
        with pytest.raises(ValueError, match="design.elongation_m"):
            design_basis_from_site({"elongation_m": bad})
    # a kit of the table gives its SEL, elongation at MEL and residual category to the checks
    from riskrf.hazard.barrier_kits import get_kit
    kit = get_kit("generic 2000 kJ")
    req = design_requirement(_hazard(), DesignBasis("UNI 11211-4", residual_category="A"), block=_block(),
                             density_kg_m3=RHO, clearance_m=7.0, candidates=[("f", None, None, kit.name)])
    c = req.candidates.set_index("check")
    elong = c[c.index.str.startswith("elongation")]
    assert elong["demand"].iloc[0] == pytest.approx(kit.max_elongation_mel_m * 1.3)      # 6.0 m x 1.3 = 7.8 m
    assert not elong["adequate"].iloc[0]                                                 # > 7 m of clearance
    assert "GENERIC kit, not a product" in elong.index[0]
    assert c[c.index.str.startswith("height")]["capacity"].iloc[0] == kit.nominal_height_m
    assert bool(c[c.index.str.startswith("residual height")]["adequate"].iloc[0])


def test_site_file_elongation_forms_and_kit_errors_name_file_and_field(tmp_path):
    from riskrf.risk.mitigation_inputs import MitigationError
    from .test_assess import _site_copy
    anchor = 'residual_category = "A"'
    for form, want in (("elongation_m = 5.0", 5.0), ('elongation_m = { "fence 2000 kJ" = 5.0, "fence 3000 kJ" = 7.0 }',
                                                       {"fence 2000 kJ": 5.0, "fence 3000 kJ": 7.0})):
        site = load_site(_site_copy(tmp_path, replace={anchor: f"{anchor}\n{form}"}))
        assert design_basis_from_site(site.design.as_dict()).elongation_m == want
    path = _site_copy(tmp_path, replace={anchor: f'{anchor}\nelongation_m = "five"'})
    with pytest.raises(SiteError, match=r"site.toml: design.elongation_m = 'five' must be one number"):
        load_site(path)
    # a fence naming a kit takes its MEL and height; a kit not in the table is refused with the known kits
    fence = 'capacity_kj = 2000\nheight_m = 5.0'
    site = load_site(_site_copy(tmp_path, replace={fence: 'kit = "generic 2000 kJ"'}))
    f = next(o for o in site.mitigation.options if o.name == "fence 2000 kJ")
    assert (f.kit, f.capacity_kj, f.height_m) == ("generic 2000 kJ", 2000.0, 5.0)
    path = _site_copy(tmp_path, replace={fence: 'kit = "RXI-200"'})
    with pytest.raises((SiteError, MitigationError)) as err:
        load_site(path)
    msg = str(err.value)
    assert "site.toml" in msg and "option 'fence 2000 kJ': kit = 'RXI-200' is not in the kit table" in msg
    assert "known kits: 'generic 100 kJ'" in msg
