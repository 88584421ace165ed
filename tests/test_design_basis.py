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
from riskrf.hazard.design_basis import (DesignBasis, design_basis_from_site, design_requirement, position_search,
                                        required_product_class, residual_height_category, round_up)
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
    # the 30-year energy against SEL also bounds the MEL: MEL >= 3 E_30
    e30 = 0.5 * stats.lognorm(s=1.0, scale=3000.0).isf(1.0 / 60.0) * 400 / 1000
    assert req.required_mel_kj == pytest.approx(max(req.E_d_kj, 3 * e30), rel=2e-3)


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
    assert site.design["basis"] == "ONR 24810" and site.report["revision"] == "B"


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


def test_assess_writes_the_pdf_and_the_design_entries(tmp_path):
    """report.pdf beside report.html (title block, page numbers, >= 10 pages), its text naming the design basis and
    the required barrier; summary.json with the basis, required MEL and height, deflection check and chart
    comparison."""
    import json

    from pypdf import PdfReader

    from riskrf.cli import main

    from .test_assess import _site_copy
    site = _site_copy(tmp_path, replace={'basis = "UNI 11211-4"': 'basis = "UNI 11211-4"\nposition_blocks = 600',
                                         'author = "riskrf demo"': 'author = "A. Engineer"',
                                         'checker = "not checked"': 'checker = "B. Checker"',
                                         'revision = "A"': 'revision = "C"',
                                         "option_blocks = 10000": "option_blocks = 1500"})
    out = tmp_path / "out"
    assert main(["assess", str(site), "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["design_basis"]["basis"] == "UNI 11211-4"
    rb = s["required_barrier"]
    assert rb["required_mel_kj"] == pytest.approx(1.2 * rb["E_d_kj"]) or "SEL" in rb["governs"]
    assert rb["required_net_height_m"] >= rb["required_height_m"]
    assert s["deflection_check"]["permitted_max_elongation_m"] == pytest.approx(20.0 / 1.3)   # road 120, line 100
    assert "width_for_retention_m" in s["ditch_chart_comparison"]
    ditch = s["ditch_chart_comparison"]          # the Modified Ritchie width W = 0.2 H + 4.5 m beside the retention
    assert ditch["modified_ritchie_criterion"]["width_m"] == pytest.approx(0.2 * ditch["cut_height_m"] + 4.5)
    assert len(s["position_search"]) >= 5
    reader = PdfReader(out / "report.pdf")
    assert len(reader.pages) >= 10
    text = "\n".join(p.extract_text() for p in reader.pages)
    flat = " ".join(text.split())
    assert "UNI 11211-4 governs" in flat and "required MEL" in flat and "REQUIRED net height" in flat
    assert f"page 3 of {len(reader.pages)}" in flat and "revision C" in flat and "checker B. Checker" in flat
    assert "Contents" in flat and "Appendix A" in flat
    assert "impacts per second" not in flat and "2,020" not in flat
    for name in ("options_profile.png", "stop_points.png", "barrier_positions.png", "catchment_retention.png"):
        assert (out / "figures" / name).exists(), name


def test_option_scenario_builds_the_recommended_option_into_the_slope():
    from riskrf.app.site_design import option_scenario
    site = load_site(ROOT / "riskrf" / "data" / "demo_site.toml")
    sc = simulation.load_scenario(site.resolve(site.hazard["scenario"]))
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
