"""The design standards' factors and rules and a ditch against a published width rule, each value with its source
(docs/validation/design-standards.md), and the plot()/summary() of the position search and the catchment study."""
import matplotlib
import numpy as np
import pandas as pd
import pytest

import simulation
from riskrf.hazard.catchment import catchment_retention, modified_ritchie_width_m
from riskrf.hazard.design_basis import DEFAULT_FACTORS, DesignBasis, onr24810_min_distance_m, permitted_elongation_m
from riskrf.hazard.design_requirement import PositionSearch, design_requirement

from .conftest import ROOT
from .test_design_basis import RHO, _block, _hazard

matplotlib.use("Agg")

ODOT_CUT = ROOT / "simulation" / "scenarios" / "odot_catchment_cut.toml"


def test_uni11211_factor_table_against_the_published_values():
    # UNI 11211-4:2012 partial factors as quoted by the RocFall "UNI 11211 Design Page" and Peila & Ronco (2009,
    # NHESS 9:1291): gamma_Tr (trajectory from back-analysed restitution 1.02 / from literature 1.10), gamma_Dp
    # (topographic survey high 1.02 / low 1.10), gamma_VolF (design-block survey high 1.02 / low 1.10), gamma_gamma
    # (unit weight, generally 1.0).  riskrf's defaults are the conservative entries of that table.
    f = DEFAULT_FACTORS["UNI 11211-4"]
    assert (f["gamma_Tr"], f["gamma_Dp"], f["gamma_VolF"], f["gamma_gamma"]) == (1.10, 1.10, 1.10, 1.0)
    assert f["velocity_percentile"] == 95.0            # v_t is the 95th-percentile speed (same sources)
    # the design energy carries gamma_VolF gamma_gamma (gamma_Tr gamma_Dp)^2: 1.10^5 = 1.61051, 1.02^5 = 1.10408
    for g, combined in ((1.10, 1.61051), (1.02, 1.1040808032)):
        basis = DesignBasis("UNI 11211-4", factors={"gamma_Tr": g, "gamma_Dp": g, "gamma_VolF": g})
        req = design_requirement(_hazard(), basis, block=_block(), density_kg_m3=RHO)
        assert req.E_d_kj / req.E_k_kj == pytest.approx(combined, rel=1e-9)


def test_etag027_energy_classes_and_sel_against_the_published_table():
    # ETAG 027 energy levels 1-7 as tabulated in an Italian thesis on rock fall barrier certification, ch. I
    # section 3.2.2.2 (123dok.org/article/certificazione-delle-barriere-paramassi-barriere-paramassi-elastiche.6qm0759y):
    # "MEL [kJ] >= 100 250 500 1000 1500 2000 3000 4500 >4500", "SEL [kJ] - 85 170 330 500 660 1000 1500 >1500",
    # "MEL ... deve essere pari a 3 volte l'energia del SEL" (a secondary source: the EAD itself was not read).
    from riskrf.core.units import SEL_PER_MEL
    from riskrf.hazard.design_basis import MEL_PRODUCT_CLASSES_KJ
    mel = (100.0, 250.0, 500.0, 1000.0, 1500.0, 2000.0, 3000.0, 4500.0)
    assert MEL_PRODUCT_CLASSES_KJ[:8] == mel
    assert min(MEL_PRODUCT_CLASSES_KJ[8:]) > 4500.0                  # class 8: above 4,500 kJ
    # the table's SEL are MEL / 3 rounded to a round number (85 for 83.3, 660 for 666.7): within 3 %
    for m, sel in zip(mel[1:], (85.0, 170.0, 330.0, 500.0, 660.0, 1000.0, 1500.0)):
        assert m * SEL_PER_MEL == pytest.approx(sel, rel=0.03), m


def test_onr24810_distance_to_the_element_at_risk():
    # ONR 24810 constructive rules (trumerschutzbauten.com/standards/rockfall-standards/onr-24810/constructive/):
    # "1.2 times the maximum elongation as reported during the MEL test ... and shall not be less than one meter
    # greater than the maximum elongation": below 5 m of elongation D + 1 m governs, above it 1.2 D.
    assert onr24810_min_distance_m(2.0) == pytest.approx(3.0)
    assert onr24810_min_distance_m(5.0) == pytest.approx(6.0)          # the two rules meet at 5 m
    assert onr24810_min_distance_m(6.5) == pytest.approx(7.8)
    assert onr24810_min_distance_m(10.0) == pytest.approx(12.0)
    with pytest.raises(ValueError, match="elongation_m"):
        onr24810_min_distance_m(0.0)
    onr = DesignBasis("ONR 24810")
    assert onr.factors["gamma_d"] == 1.2 and "gamma_d" not in onr.unverified
    assert permitted_elongation_m(onr, 20.0) == pytest.approx(20.0 / 1.2)    # 1.2 D governs
    assert permitted_elongation_m(onr, 5.0) == pytest.approx(4.0)            # D + 1 m governs
    # a kit of 4.5 m elongation 5.4 m from the road: 1.2 x 4.5 = 5.4 would pass, 4.5 + 1 = 5.5 m does not
    basis = DesignBasis("ONR 24810", elongation_m={"kit": 4.5})
    req = design_requirement(_hazard(), basis, block=_block(), density_kg_m3=RHO, clearance_m=5.4,
                             candidates=[("kit", 3000.0, 5.0)])
    row = req.candidates[req.candidates["check"].str.startswith("elongation")].iloc[0]
    assert row["demand"] == pytest.approx(5.5) and not row["adequate"]
    assert req.permitted_elongation_m == pytest.approx(4.4)


def test_modified_ritchie_width():
    # Modified Ritchie Criterion, W = 0.2 H + 4.5 m (Ryan & Pryor 2000, EQ 3.1; quoted in the abstract of Warren et
    # al. 2025, SSIM, doi 10.36487/ACG_repo/2535_04): the scenario's 60 ft = 18.3 m cut needs 8.16 m
    assert modified_ritchie_width_m(18.3) == pytest.approx(8.16)
    assert modified_ritchie_width_m(12.19) == pytest.approx(6.938)
    with pytest.raises(ValueError, match="height_m"):
        modified_ritchie_width_m(-1.0)


@pytest.fixture(scope="module")
def odot_study():
    return catchment_retention(simulation.load_scenario(ODOT_CUT), n=600, seed=2)


def test_odot_cut_retention_is_set_beside_the_ritchie_width(odot_study):
    s = odot_study
    assert s.n_over_face >= 0.95 * s.n                  # released at the crest edge, as the ODOT rocks were
    assert s.widths[90.0] <= s.widths[95.0] <= s.widths[99.0]
    row = s.summary().set_index("source").filter(like="Ritchie", axis=0).iloc[0]
    assert row["width_m"] == pytest.approx(8.16)
    assert row["simulated_percent"] == pytest.approx(100 * float(s.retained_at(8.16)))
    d = s.to_dict()["modified_ritchie_criterion"]
    assert d["width_m"] == pytest.approx(8.16) and d["simulated_retained_percent"] == pytest.approx(
        row["simulated_percent"])


def test_odot_cut_90_percent_width_agrees_with_the_modified_ritchie_criterion(odot_study):
    # Compared: the width retaining 90 % of the blocks that went over the face (the performance level Warren et al.
    # 2025 apply to catch benches) against W = 0.2 H + 4.5 m.  Tolerance +-35 %: the criterion is one straight line
    # in H that ignores rock size, face angle and catchment material, which Warren et al. found also govern
    # rollout, and it was set from ditch and bench tests, not from one geometry.  The scenario's materials are the
    # data-derived presets (fitted to the Authume releases and Evans & Hungr's reach, not to any ditch): a
    # prediction, 8.3 m against 8.16 m.  With the earlier riskrf starting values it was 17.3 m (a strict xfail).
    assert odot_study.widths[90.0] == pytest.approx(modified_ritchie_width_m(odot_study.cut_height_m), rel=0.35)


@pytest.mark.parametrize("catchment", ["colluvium", "scree", "meadow"])
def test_the_ritchie_agreement_does_not_hang_on_the_catchment_preset(catchment):
    # the ditch floor of the ODOT tests is not described in what could be read: every soft-ground preset gives
    # a 90 % width within the same tolerance (these three have no data-derived table, so their published values
    # are used; soil, the scenario's, is data-derived)
    import tomllib
    data = tomllib.loads(ODOT_CUT.read_text())
    data["materials"]["catchment"] = {"preset": catchment}
    study = catchment_retention(simulation.scenario_from_dict(data, str(ODOT_CUT)), n=600, seed=2)
    assert study.widths[90.0] == pytest.approx(modified_ritchie_width_m(study.cut_height_m), rel=0.35), catchment


def _search():
    t = pd.DataFrame({"x_m": [60.0, 80.0, 100.0], "ground_z_m": [40.0, 25.0, 12.0], "reach_share": [0.9, 0.8, 0.6],
                      "arrivals_per_year": [2.0, 1.8, 1.3], "E_d_kj": [2500.0, 1600.0, 900.0],
                      "required_mel_kj": [3000.0, 1920.0, 1080.0], "required_class_kj": [3000.0, 2000.0, 1500.0],
                      "required_net_height_m": [5.0, 4.0, 4.5], "clearance_m": [60.0, 40.0, 20.0],
                      "note": ["", "", "barrier line of the hazard"]})
    return PositionSearch(table=t, profile=(np.array([0.0, 60, 100, 120]), np.array([60.0, 40, 12, 10])),
                          basis=DesignBasis("UNI 11211-4"), n=1000, road_x_m=120.0)


def test_position_search_plot_and_summary():
    import matplotlib.pyplot as plt
    ps = _search()
    s = ps.summary()
    assert list(s["position x [m]"]) == [60.0, 80.0, 100.0]
    assert list(s["cheapest"]) == [False, False, True]          # 1,500 kJ class is the smallest
    assert "required MEL [kJ]" in s.columns and "required_mel_kj" not in s.columns
    ax = ps.plot()
    assert isinstance(ax, matplotlib.axes.Axes)
    assert len(ax.figure.axes) == 3                             # profile panel, requirement panel, its height axis
    assert [tuple(line.get_ydata()) for line in ax.get_lines()][0] == (3000.0, 1920.0, 1080.0)
    _, own = plt.subplots()
    assert ps.plot(ax=own) is own
    plt.close("all")


def test_catchment_plot_and_summary(odot_study):
    import matplotlib.pyplot as plt
    s = odot_study.summary()
    assert list(s.columns) == ["source", "width_m", "retained_percent", "simulated_percent"]
    assert len(s) == 4                                          # 90/95/99 % widths and the Ritchie width
    ax = odot_study.plot()
    assert isinstance(ax, matplotlib.axes.Axes)
    assert any("Ritchie" in t.get_text() for t in ax.get_legend().get_texts())
    plt.close("all")
