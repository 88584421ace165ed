"""Rows that both report formats print (report.pdf and report.html): the design values sheet, the slope model's
vertices and materials, the run-out of the simulated blocks.

Each function returns plain rows of strings, numbers written by :func:`riskrf.report.pdf_layout.fmt`; the PDF
(:mod:`riskrf.report.pdf`) and the HTML report (:mod:`riskrf.report.html`) each lay them out.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np

from .pdf_layout import fmt, pct, year


def slope_tables(site):
    """The site's scenario with its vertex rows and material rows (both formats print them).

    Parameters
    ----------
    site : Site
        The site; its ``hazard`` table names a scenario.

    Returns
    -------
    (simulation.Scenario, list, list)
        The scenario; vertices with the dip of the segment that follows and its material
        (:data:`riskrf.report.sections.SLOPE_VERTEX_COLUMNS`); materials with their laws and the source of their
        values (:data:`riskrf.report.sections.SLOPE_MATERIAL_COLUMNS`).
    """
    import simulation
    from simulation.materials import ALIASES, SOURCES
    path = site.resolve(site.hazard.scenario)
    sc = simulation.load_scenario(path)
    raw = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    prof = sc.profile
    x, z = np.asarray(prof.x), np.asarray(prof.z)
    vert = []
    for i in range(x.size):
        if i < x.size - 1:
            ang = math.degrees(math.atan2(z[i] - z[i + 1], x[i + 1] - x[i]))
            seg = f"{ang:.1f}"
            mat = prof.material_names[int(prof.material_index[i])]
        else:
            seg, mat = "", ""
        vert.append([str(i), f"{x[i]:.1f}", f"{z[i]:.1f}", seg, mat])
    mats = []
    laws = {0: "constant", 1: "Wyllie (2014) impact-angle law", 2: "velocity-dependent"}
    for m in sc.materials:
        spec = raw.get("materials", {}).get(m.name, {})
        preset = spec.get("preset")
        key = ALIASES.get(preset, preset)
        own = [k for k in spec if k != "preset"]
        src = (f"preset {preset}: {SOURCES.get(key, '')}" if preset else "stated in the scenario file")
        if preset and own:
            src += f"; replaced in the scenario: {', '.join(own)}"
        en = laws.get(m.en_law, str(m.en_law)) if m.en_law == 1 else f"{m.en_mean:.2f} ± {m.en_std:.2f}"
        et = (f"friction {m.friction_deg:g} ± {m.friction_std_deg:g}°" if m.et_law == 0 or m.friction_deg
              else f"{m.et_mean:.2f} ± {m.et_std:.2f}")
        mats.append([m.name, en, et, fmt(m.roughness_m, 2), m.ground_motion, fmt(m.ground_friction_deg, 3), src])
    return sc, vert, mats


def design_values_rows(a) -> list:
    """(item, value) rows of the design values sheet: design block, speeds, energies, bounce heights and the
    required barrier (both formats print them).

    Parameters
    ----------
    a : Assessment
        The finished assessment; its ``design.requirement`` is not None.

    Returns
    -------
    list of (str, str)
    """
    d = a.design
    req = d.requirement
    hz = a.energy.hazard
    blk = a.energy.design_block
    m = req.block_mass_kg
    v95, v99 = (hz.velocity_percentile(q, mass_kg=m) for q in (95, 99))
    e95, e99 = (float(x) for x in hz.energy_percentile([95, 99]))
    if hz.mass_coupled:
        h95, h99 = (hz.velocity.height_percentile(q, m) for q in (95, 99))
    elif hz.heights_m is not None:
        h95, h99 = (float(hz.height_percentile(q)) for q in (95, 99))
    else:
        h95 = h99 = float("nan")
    sh = req.shares
    rows = [
        ("governing design basis", d.basis.basis),
        ("barrier line", f"x = {fmt(req.x_m, 4)} m"),
        ("design block", f"{fmt(m, 3)} kg, {fmt(m / a.inventory.density_kg_m3, 3)} m³, diameter "
                         f"{fmt(req.block_diameter_m, 3)} m ({req.block_rule})"
         + (f"; rule: {blk.basis}" if blk is not None else "")),
        ("speed of the design block at the line, p95 / p99", f"{fmt(v95)} / {fmt(v99)} m/s"),
        ("impact energy of arriving falls, p95 / p99", f"{fmt(e95)} / {fmt(e99)} kJ"),
        ("bounce height (block centre) at the line, p95 / p99", f"{fmt(h95)} / {fmt(h99)} m"),
        ("design energy E_d", f"{fmt(req.E_d_kj)} kJ ({req.governs})"),
        (f"{year(d.basis.frequent_T_years)}-year energy (frequent events, against SEL)",
         f"{fmt(req.frequent_energy_kj)} kJ"),
        ("REQUIRED MEL", f"{fmt(req.required_mel_kj)} kJ"),
        ("REQUIRED product class", f"{fmt(req.required_class_kj)} kJ" if np.isfinite(req.required_class_kj)
         else f"none: above the largest class ({fmt(max(d.basis.mel_classes_kj))} kJ)"),
        ("REQUIRED net height", f"{fmt(req.required_net_height_m)} m (design passing height h_d "
                                f"{fmt(req.h_d_m)} m + free border; exact {fmt(req.required_height_m)} m)"),
        ("clearance to the road; permitted maximum elongation",
         f"{fmt(req.clearance_m)} m; {fmt(req.permitted_elongation_m)} m"),
        ("required residual-height category (EAD 340059)", req.residual_category),
        ("falls at the line stopped / over / through by the required barrier",
         f"{pct(sh.get('stopped'))} / {pct(sh.get('over'))} / {pct(sh.get('through'))}"),
    ]
    if d.runout:
        rows.append(("simulated blocks reaching the road (run-out)", pct(d.runout.get("share_reaching_road"))))
    return rows


def runout_rows(d) -> list:
    """(item, value) rows of the run-out statistics of the simulated blocks, with the recommended option's where it
    changes the slope (both formats print them).

    Parameters
    ----------
    d : SiteDesign or None
        The assessment's design.

    Returns
    -------
    list of (str, str)
        Empty without a design or run-out statistics.
    """
    if d is None or not d.runout:
        return []
    r = d.runout
    rows = [("blocks simulated (scenario seeder masses)", f"{r['blocks']:,}"),
            ("stop point p50 / p95 / p99", f"{fmt(r['stop_x_p50_m'], 4)} / {fmt(r['stop_x_p95_m'], 4)} / "
                                           f"{fmt(r['stop_x_p99_m'], 4)} m"),
            ("share reaching the barrier line", pct(r.get("share_reaching_barrier_line"))),
            ("share reaching the road", pct(r.get("share_reaching_road")))]
    rr = d.recommended_runout()
    if rr is not None:
        rows += [(f"with {rr['option']}: blocks simulated", f"{rr['blocks']:,}"),
                 (f"with {rr['option']}: stop point p50 / p95", f"{fmt(rr['stop_x_p50_m'], 4)} / "
                                                               f"{fmt(rr['stop_x_p95_m'], 4)} m"),
                 (f"with {rr['option']}: share reaching the road", pct(rr.get("share_reaching_road")))]
    return rows


__all__ = ["design_values_rows", "runout_rows", "slope_tables"]
