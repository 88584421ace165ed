"""report.pdf: the assessment as a deliverable a checking engineer can sign.

A4 pages with a title block (project, site, location, revision, date, author, checker from the site file's
``[report]`` table), page numbers "page X of N", a table of contents, the design-values sheet, the design basis
and its checks, the barrier-position search, the slope model (vertices with segment angles, materials with
their sources), every option drawn on the profile, the stop points, the ditch retention, the hazard, the
ranking and the assumptions; data of other sites (a regional record) in an appendix.

Engine: fpdf2 (pure Python, installs with ``pip install .`` alone, no system libraries; tables, outline and
table of contents built in).  Text is set in DejaVu Sans, the font matplotlib ships, so Greek letters and
symbols print on any machine.
"""
from __future__ import annotations

import datetime
import math
import tomllib
from pathlib import Path

import numpy as np

A4_TEXT_WIDTH_MM = 180.0


def _font_paths():
    import matplotlib
    d = Path(matplotlib.get_data_path()) / "fonts" / "ttf"
    return d / "DejaVuSans.ttf", d / "DejaVuSans-Bold.ttf", d / "DejaVuSans-Oblique.ttf"


def fmt(v, digits: int = 3, *, thousands: bool = True) -> str:
    """A number for an engineering table: ``digits`` significant figures, thousands separators for large values
    (never for years or identifiers: pass ``thousands=False`` or use :func:`year`), "n/a" for NaN/None.

    Parameters
    ----------
    v : float, bool, str or None
        The value (text is returned as it is, None as "").
    digits : int
        Significant figures.
    thousands : bool
        Thousands separators for large values.

    Returns
    -------
    str
    """
    if v is None or isinstance(v, str):
        return "" if v is None else v
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    x = float(v)
    if not math.isfinite(x):
        return "n/a" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    if mag >= digits - 1:
        r = int(round(x, -(mag - digits + 1)))          # no more figures than ``digits``
        return f"{r:,}" if thousands else f"{r}"
    if abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{max(digits - 1 - mag, 0)}f}"


def year(v) -> str:
    """A year or return period: an integer without thousands separator.

    Parameters
    ----------
    v : float or None
        The year or return period [yr].

    Returns
    -------
    str
        "n/a" for None or NaN.
    """
    return "n/a" if v is None or not np.isfinite(float(v)) else f"{float(v):.0f}"


def pct(v, digits: int = 1) -> str:
    """A share [-] as a percentage.

    Parameters
    ----------
    v : float or None
        The share [-].
    digits : int
        Decimals of the percentage.

    Returns
    -------
    str
        E.g. "12.5 %"; "n/a" for None or NaN.
    """
    return "n/a" if v is None or not np.isfinite(float(v)) else f"{100 * float(v):.{digits}f} %"


class _Report:
    """fpdf2 document with the title block in the footer and header, sections registered for the contents."""

    def __init__(self, title_block: dict):
        from fpdf import FPDF

        tb = title_block

        class Doc(FPDF):
            def header(self):
                if self.page_no() == 1:
                    return
                self.set_font("DejaVu", "", 7.5)
                self.set_text_color(90)
                self.cell(0, 4, f"{tb['project']} - {tb['site']}", align="L")
                self.set_x(self.l_margin)
                self.cell(0, 4, f"revision {tb['revision']}, {tb['date']}", align="R",
                          new_x="LMARGIN", new_y="NEXT")
                self.line(self.l_margin, self.get_y() + 0.5, self.w - self.r_margin, self.get_y() + 0.5)
                self.ln(3)
                self.set_text_color(0)

            def footer(self):
                self.set_y(-12)
                self.set_font("DejaVu", "", 7.5)
                self.set_text_color(90)
                self.cell(0, 5, f"author {tb['author']}; checker {tb['checker']}", align="L")
                self.set_x(self.l_margin)
                self.cell(0, 5, f"page {self.page_no()} of {{nb}}", align="R")
                self.set_text_color(0)

        pdf = Doc(format="A4", unit="mm")
        regular, bold, italic = _font_paths()
        pdf.add_font("DejaVu", "", str(regular))
        pdf.add_font("DejaVu", "B", str(bold))
        pdf.add_font("DejaVu", "I", str(italic))
        pdf.set_margins(15, 15, 15)
        pdf.set_auto_page_break(True, margin=16)
        pdf.alias_nb_pages()
        pdf.set_font("DejaVu", "", 9.5)
        self.pdf = pdf
        self.section_no = 0
        self.fresh_page = False

    # -- building blocks ------------------------------------------------------------------------------
    def section(self, title: str, *, new_page: bool = True, appendix: str | None = None):
        pdf = self.pdf
        if new_page and not self.fresh_page:
            pdf.add_page()
        self.fresh_page = False
        if appendix is None:
            self.section_no += 1
            label = f"{self.section_no}  {title}"
        else:
            label = f"Appendix {appendix}  {title}"
        pdf.start_section(label, level=0)
        pdf.set_font("DejaVu", "B", 13)
        pdf.multi_cell(0, 7, label, new_x="LMARGIN", new_y="NEXT")
        pdf.ln(1.5)
        pdf.set_font("DejaVu", "", 9.5)

    def sub(self, title: str):
        pdf = self.pdf
        if pdf.get_y() > pdf.h - 45:
            pdf.add_page()
        pdf.start_section(title, level=1)
        pdf.set_font("DejaVu", "B", 10.5)
        pdf.multi_cell(0, 6, title, new_x="LMARGIN", new_y="NEXT")
        pdf.set_font("DejaVu", "", 9.5)

    def text(self, s: str, size: float = 9.5, style: str = ""):
        self.pdf.set_font("DejaVu", style, size)
        self.pdf.multi_cell(0, 4.6, s, new_x="LMARGIN", new_y="NEXT")
        self.pdf.ln(1.2)
        self.pdf.set_font("DejaVu", "", 9.5)

    def table(self, header, rows, widths=None, size: float = 8.0, align=None):
        """A table that fits the A4 text width: ``header`` plain-language column names, ``rows`` of strings."""
        pdf = self.pdf
        pdf.set_font("DejaVu", "", size)
        n = len(header)
        widths = widths or [1] * n
        total = float(sum(widths))
        cw = tuple(A4_TEXT_WIDTH_MM * w / total for w in widths)
        from fpdf.fonts import FontFace
        head = FontFace(emphasis="BOLD", fill_color=(225, 228, 235))
        with pdf.table(col_widths=cw, width=A4_TEXT_WIDTH_MM, headings_style=head, line_height=1.35 * size * 0.3528 + 1,
                       text_align=align or ["LEFT"] + ["RIGHT"] * (n - 1), first_row_as_headings=True,
                       borders_layout="HORIZONTAL_LINES") as t:
            r = t.row()
            for h in header:
                r.cell(str(h))
            for row in rows:
                r = t.row()
                for c in row:
                    r.cell(str(c))
        pdf.ln(2)
        pdf.set_font("DejaVu", "", 9.5)

    def kv(self, pairs, widths=(2, 3), size: float = 8.5):
        self.table(["item", "value"], [[k, v] for k, v in pairs], widths=list(widths), size=size,
                   align=["LEFT", "LEFT"])

    def figure(self, path, caption: str, width: float = A4_TEXT_WIDTH_MM, max_height: float = 200.0):
        path = Path(path)
        if not path.exists():
            return
        pdf = self.pdf
        from PIL import Image
        with Image.open(path) as im:
            w_px, h_px = im.size
        h = width * h_px / w_px
        if h > max_height:
            width, h = width * max_height / h, max_height
        if pdf.get_y() + h + 12 > pdf.h - 16:
            pdf.add_page()
        x = pdf.l_margin + (A4_TEXT_WIDTH_MM - width) / 2
        pdf.image(str(path), x=x, w=width)
        pdf.set_font("DejaVu", "I", 8)
        pdf.multi_cell(0, 4, caption, new_x="LMARGIN", new_y="NEXT")
        pdf.ln(2)
        pdf.set_font("DejaVu", "", 9.5)


def _toc(pdf, outline):
    pdf.set_font("DejaVu", "B", 13)
    pdf.cell(0, 8, "Contents", new_x="LMARGIN", new_y="NEXT")
    pdf.ln(2)
    for s in outline:
        pdf.set_font("DejaVu", "" if s.level else "B", 9.5 if s.level == 0 else 8.5)
        indent = 6 * s.level
        pdf.set_x(pdf.l_margin + indent)
        name = s.name if len(s.name) < 95 else s.name[:92] + "..."
        pdf.cell(A4_TEXT_WIDTH_MM - indent - 15, 5.2, name, link=pdf.add_link(page=s.page_number))
        pdf.cell(15, 5.2, str(s.page_number), align="R", new_x="LMARGIN", new_y="NEXT")


def title_block(site, now: datetime.date | None = None) -> dict:
    """The title-block fields from the site file's ``[report]`` table, with their defaults.

    Parameters
    ----------
    site : Site
        The site (its ``report`` table and name).
    now : datetime.date, optional
        Date used when the table gives none (default: today).

    Returns
    -------
    dict
        ``project``, ``site``, ``location``, ``revision``, ``date``, ``author``, ``checker``, ``client``.
    """
    r = dict(getattr(site, "report", {}) or {})
    d = r.get("date")
    return {"project": str(r.get("project") or site.name), "site": site.name,
            "location": str(r.get("location") or "not stated"), "revision": str(r.get("revision") or "A"),
            "date": str(d) if d is not None else (now or datetime.date.today()).isoformat(),
            "author": str(r.get("author") or "not stated"), "checker": str(r.get("checker") or "not stated"),
            "client": str(r.get("client") or "not stated")}


def _slope_tables(site):
    """(vertex rows, material rows) of the site's scenario: vertices with the angle of the segment that follows,
    materials with their laws and the source of their values."""
    import simulation
    from simulation.materials import ALIASES, SOURCES
    path = site.resolve(site.hazard["scenario"])
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


def write_pdf_report(a, path, figs) -> Path:
    """Write report.pdf for the assessment ``a`` (figures read from ``figs``); returns the path.

    Parameters
    ----------
    a : riskrf.app.assess.Assessment
        The assessment.
    path : str or path
        The PDF written.
    figs : str or path
        Folder of its figures (PNG).

    Returns
    -------
    pathlib.Path
    """
    figs = Path(figs)
    tb = title_block(a.site)
    rep = _Report(tb)
    pdf = rep.pdf
    _title_page(rep, a, tb)

    # ---- contents -------------------------------------------------------------------------------
    pdf.add_page()
    pdf.insert_toc_placeholder(_toc, pages=1)       # it starts the next page itself
    rep.fresh_page = True

    d = a.design
    if d is not None and d.requirement is not None:
        _design_values_sheet(rep, a)
        _design_checks(rep, d)
        if d.positions is not None:
            _barrier_positions(rep, d, figs)
    if a.site.hazard.get("scenario"):
        _slope_model(rep, a.site)
    _options_and_runout(rep, d, figs)
    if d is not None and d.catchment is not None:
        _catchment(rep, d.catchment, figs)
    _hazard(rep, a, figs)
    _ranking(rep, a, figs)
    if getattr(a, "model_uncertainty", None) is not None:
        _model_uncertainty(rep, a.model_uncertainty, a.study.currency, figs)
    _inventory_and_assumptions(rep, a, figs)
    _appendices(rep, a, figs)
    path = Path(path)
    tmp = path.with_suffix(".pdf.part")
    pdf.output(str(tmp))
    tmp.replace(path)
    return path


def _title_page(rep, a, tb):
    """Write the title page: title block, design statement, recommendation and signature fields.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    tb : dict
        The title-block fields (:func:`title_block`).
    """
    pdf = rep.pdf
    d = a.design
    req = d.requirement if d is not None else None
    pdf.add_page()
    pdf.set_font("DejaVu", "B", 18)
    pdf.multi_cell(0, 9, "Rock fall hazard assessment and barrier design", new_x="LMARGIN", new_y="NEXT")
    pdf.set_font("DejaVu", "", 12)
    pdf.multi_cell(0, 7, tb["project"], new_x="LMARGIN", new_y="NEXT")
    pdf.ln(4)
    rep.kv([("project", tb["project"]), ("site", tb["site"]), ("location", tb["location"]),
            ("client", tb["client"]), ("revision", tb["revision"]), ("date", tb["date"]),
            ("author", tb["author"]), ("checker", tb["checker"]),
            ("software", f"riskrf {_version()}"),
            ("seed; simulated blocks", f"{a.seed}; {a.n_blocks:,}")], size=9.5)
    if d is not None and req is None:
        rep.sub("Design statement")
        rep.text(f"{d.basis.basis}: " + "; ".join(d.notes), size=10, style="B")
    if req is not None:
        rep.sub("Design statement")
        rep.text(req.text() + ".", size=10, style="B")
        rep.text(d.basis.text(), size=8.5)
    rec = a.decision["recommendation"]
    rep.text(f"Recommended option by expected total cost and tolerability: {rec['option'] or 'none'} ({rec['basis']}).",
             size=10)
    rep.text("Signature fields: author ____________________   checker ____________________", size=9.5)


def _design_values_sheet(rep, a):
    """Write the design values sheet: design block, speeds, energies, bounce heights and the required barrier.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment; its ``design.requirement`` is not None.
    """
    d = a.design
    req = d.requirement
    hz = a.energy.hazard
    rep.section("Design values sheet")
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
    rep.kv(rows, widths=(2, 3))
    rep.text("Energies in kJ, lengths in m.  The shares stopped / over / through take bounce height and energy "
             "of the arriving falls (under the site's mass law) as independent.", size=8)


def _design_checks(rep, d):
    """Write the design basis, its factors, the requirement at the barrier line and the candidate fences' checks.

    Parameters
    ----------
    rep : _Report
        The document being written.
    d : SiteDesign
        The assessment's design; its ``requirement`` is not None.
    """
    req = d.requirement
    rep.section("Design basis and checks")
    rep.text(d.basis.text())
    rep.table(["factor", "value"], [[k, fmt(v, 3)] for k, v in d.basis.factors.items()], widths=[2, 1])
    rep.sub("Requirement at the barrier line")
    rep.table(["quantity", "value"], [[k, fmt(v) if not isinstance(v, str) else v]
                                      for k, v in req.summary()["value"].items()], widths=[3, 2],
              align=["LEFT", "RIGHT"])
    if len(req.candidates):
        rep.sub("Checks of the candidate fences")
        rep.table(["fence", "check", "demand", "capacity", "unit", "adequate"],
                  [[r["fence"], r["check"], fmt(r["demand"]), fmt(r["capacity"]), r["unit"],
                    "not given" if r["adequate"] is None or (isinstance(r["adequate"], float)
                                                              and np.isnan(r["adequate"]))
                    else ("yes" if r["adequate"] else "NO")]
                   for _, r in req.candidates.iterrows()], widths=[2, 4, 1.2, 1.2, 0.7, 1])
        rep.text("Elongation: state the kit's maximum elongation at MEL (from its European Technical "
                 "Assessment) in [design] elongation_m to check it; the permitted value is the clearance to the "
                 "road divided by gamma_d (ONR 24810: also at most the clearance less 1 m).", size=8)


def _barrier_positions(rep, d, figs):
    """Write the barrier-position search: the requirement at each searched position and the cheapest one.

    Parameters
    ----------
    rep : _Report
        The document being written.
    d : SiteDesign
        The assessment's design; its ``positions`` is not None.
    figs : pathlib.Path
        Directory of the assessment's figures.
    """
    rep.section("Barrier position along the profile")
    t = d.positions.table
    rep.text(f"The requirement of {d.basis.basis} repeated at {len(t)} positions from one simulation of "
             f"{d.positions.n:,} blocks across the site's mass range.")
    rep.table(["x [m]", "ground z [m]", "reaching [%]", "arrivals per year", "E_d [kJ]",
               "required MEL [kJ]", "product class [kJ]", "net height [m]", "to road [m]"],
              [[fmt(r["x_m"], 4), fmt(r["ground_z_m"], 3), f"{100 * r['reach_share']:.1f}",
                fmt(r["arrivals_per_year"]), fmt(r["E_d_kj"]), fmt(r["required_mel_kj"]),
                fmt(r["required_class_kj"]) if np.isfinite(r["required_class_kj"]) else "none",
                fmt(r["required_net_height_m"]), fmt(r["clearance_m"], 3)] for _, r in t.iterrows()])
    best = d.positions.cheapest()
    if best is not None:
        rep.text(f"Smallest product class at x = {fmt(best['x_m'], 4)} m: {fmt(best['required_class_kj'])} kJ, "
                 f"{fmt(best['required_net_height_m'])} m.")
    else:
        rep.text("No searched position can be protected by a single certified kit of the listed classes.")
    rep.figure(figs / "barrier_positions.png", "Required MEL and net height by barrier position.",
               max_height=150)


def _slope_model(rep, site):
    """Write the slope model: the scenario's profile vertices with segment angles and its materials' sources.

    Parameters
    ----------
    rep : _Report
        The document being written.
    site : Site
        The site; its ``hazard`` table names a scenario.
    """
    sc, vert, mats = _slope_tables(site)
    rep.section("Slope model")
    rep.text(f"Scenario {Path(str(site.hazard['scenario'])).name}: {sc.description.strip()}", size=8.5)
    rep.sub("Profile vertices and segment angles")
    rep.table(["vertex", "x [m]", "z [m]", "dip of the segment to the next vertex [°]",
               "material of that segment"], vert, widths=[0.8, 1, 1, 2, 2])
    rep.sub("Materials and the source of their values")
    rep.table(["material", "normal restitution e_N", "tangential: e_T or friction", "rough-ness [m]",
               "ground motion", "ground friction φ_g [°]", "source or calibration"], mats,
              widths=[1.1, 1.6, 1.6, 1.0, 1.0, 1.0, 4.3], size=7,
              align=["LEFT", "LEFT", "LEFT", "RIGHT", "LEFT", "RIGHT", "LEFT"])


def _options_and_runout(rep, d, figs):
    """Write the options on the profile, the trajectories and the stop points with their run-out statistics.

    Parameters
    ----------
    rep : _Report
        The document being written.
    d : SiteDesign or None
        The assessment's design (run-out statistics when it has them).
    figs : pathlib.Path
        Directory of the assessment's figures.
    """
    rep.section("Mitigation options on the profile")
    rep.figure(figs / "options_profile.png", "Every option's geometry on the slope profile, and the barrier the "
                                             "design basis requires (dashed).", max_height=110)
    rep.figure(figs / "profile_trajectories.png", "Simulated trajectories on the existing profile.",
               max_height=110)
    rep.section("Stop points and run-out")
    rep.figure(figs / "stop_points.png", "Where the simulated blocks stopped, on the existing slope and with the "
                                         "recommended option where it changes the slope.", max_height=120)
    rep.figure(figs / "recommended_trajectories.png", "Trajectories on the slope with the recommended option.",
               max_height=100)
    if d is not None and d.runout:
        r = d.runout
        rep.kv([("blocks simulated (scenario seeder masses)", f"{r['blocks']:,}"),
                ("stop point p50 / p95 / p99", f"{fmt(r['stop_x_p50_m'], 4)} / {fmt(r['stop_x_p95_m'], 4)} / "
                                               f"{fmt(r['stop_x_p99_m'], 4)} m"),
                ("share reaching the barrier line", pct(r.get("share_reaching_barrier_line"))),
                ("share reaching the road", pct(r.get("share_reaching_road")))])
        rr = d.recommended_runout()
        if rr is not None:
            rep.kv([(f"with {rr['option']}: blocks simulated", f"{rr['blocks']:,}"),
                    (f"with {rr['option']}: stop point p50 / p95", f"{fmt(rr['stop_x_p50_m'], 4)} / "
                                                                  f"{fmt(rr['stop_x_p95_m'], 4)} m"),
                    (f"with {rr['option']}: share reaching the road", pct(rr.get("share_reaching_road")))])


def _catchment(rep, c, figs):
    """Write the catchment ditch: widths needed for each retention, the Modified Ritchie Criterion, the chart.

    Parameters
    ----------
    rep : _Report
        The document being written.
    c : CatchmentStudy
        The design's catchment study.
    figs : pathlib.Path
        Directory of the assessment's figures.
    """
    rep.section("Catchment ditch at the toe of the cut")
    applies = c.to_dict()["odot_chart_geometry"]
    rep.text(f"Retention against catchment width beyond the toe of the cut (x = {fmt(c.toe_x_m, 4)} m; cut "
             f"{fmt(c.cut_height_m, 3)} m high at {fmt(c.face_angle_deg, 3)}°), re-simulated with the site's "
             f"slope model.  Pierson, Gullixson & Chassie (2001, FHWA-OR-RD-02-04) charts: {applies}.")
    rep.table(["retention", "catchment width needed [m]"],
              [[f"{q:g} %", fmt(w, 3) if np.isfinite(w) else "not reached on the profile"]
               for q, w in c.widths.items()], widths=[1, 2])
    mrc = c.to_dict()["modified_ritchie_criterion"]
    rep.text(f"Published width rule beside it: the Modified Ritchie Criterion W = 0.2 H + 4.5 m (Ryan & Pryor "
             f"2000, after Ritchie 1963) gives {fmt(mrc['width_m'], 3)} m for this cut, within which the "
             f"re-simulation retains {fmt(mrc['simulated_retained_percent'], 3)} % of the blocks that went over "
             "the face.  The rule is for a cut face above a flat catchment; on the ODOT test cut the "
             "re-simulation retains fewer blocks than the rule implies (validation: design standards and "
             "ditch charts).", size=8)
    if c.chart is not None:
        rep.table(["width [m]", "chart retained [%]", "simulated [%]", "difference [points]"],
                  [[fmt(r["width_m"]), fmt(r["retained_percent"]), fmt(r["simulated_percent"]),
                    fmt(r["difference_points"])] for _, r in c.chart.iterrows()])
    rep.figure(figs / "catchment_retention.png", "Retention against catchment width.", max_height=100)


def _hazard(rep, a, figs):
    """Write the impact-energy hazard at the barrier line: rates, return-period energies, the design block.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    """
    hz = a.energy.hazard
    rep.section("Impact-energy hazard at the barrier line")
    rep.text(f"Falls per year at the source {fmt(hz.rate_per_year)}; reach probability {fmt(hz.reach_probability)}; "
             f"arrivals per year {fmt(hz.arrival_rate)}.  Rate: {a.rate_source}.")
    de = a.energy.design
    rep.table(["return period [years]", "annual exceedance", "energy [kJ]", "95 % interval [kJ]",
               "probability in 50 years"],
              [[year(r["T_years"]), fmt(r["annual_exceedance"]), fmt(r["energy_kj"]),
                f"{fmt(r['ci_low_kj'])} - {fmt(r['ci_high_kj'])}", fmt(r["probability_in_50_years"])]
               for _, r in de.iterrows()])
    if a.energy.design_block is not None:
        alt = a.energy.design_block.alternatives
        rep.sub("Design block and its alternatives")
        rep.table(["rule", "mass [kg]", "volume [m³]", "diameter [m]", "v95 [m/s]", "energy at v95 [kJ]", "chosen"],
                  [[r["rule"], fmt(r["mass_kg"]), fmt(r["volume_m3"]), fmt(r["diameter_m"]),
                    fmt(r["velocity_p95_ms"]), fmt(r["energy_at_v95_kj"]), "yes" if r["chosen"] else ""]
                   for _, r in alt.iterrows()], widths=[3, 1, 1, 1, 1, 1.2, 0.7])
        rep.text("Which value designs: the governing basis above; the p95 energy of arriving falls under the site's "
                 "law and the return-period energies are shown for comparison only.", size=8)
    rep.figure(figs / "energy_exceedance.png", "Annual frequency of impacts above an energy at the barrier line.",
               max_height=110)


def _ranking(rep, a, figs):
    """Write the mitigation options ranked by expected total cost, the recommendation and the tornado chart.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    """
    rank = a.decision["ranking"]
    rec = a.decision["recommendation"]
    cur = a.study.currency
    rep.section("Mitigation options ranked")
    rep.table(["option", f"capital [{cur}]", f"expected total cost [{cur}]", "5-95 % [" + cur + "]",
               "road falls per year", "individual risk per year", "societal risk", "meets criteria"],
              [[r["option"], fmt(r["capital"]), fmt(r["expected_total_cost"]),
                f"{fmt(r['cost_p05'])} - {fmt(r['cost_p95'])}", fmt(r["road_falls_per_year"]),
                fmt(r["individual_risk"]), str(r["fn_zone"]), "yes" if r["meets_criteria"] else "no"]
               for _, r in rank.iterrows()], widths=[2.2, 1.2, 1.3, 1.9, 1, 1.1, 1.2, 0.9], size=7.2)
    rep.text(f"Recommendation: {rec['reason']}", size=8.5)
    rep.figure(figs / "tornado.png", "One-way sensitivity of the expected total cost.", max_height=100)


def _model_uncertainty(rep, mu, cur, figs):
    """Write the trajectory model uncertainty: design energy and ranking over draws of the material parameters.

    Parameters
    ----------
    rep : _Report
        The document being written.
    mu : ModelUncertaintyStudy
        The assessment's model-uncertainty study.
    cur : str
        Currency of the costs.
    figs : pathlib.Path
        Directory of the assessment's figures.
    """
    rep.section("Trajectory model uncertainty")
    rep.text(f"The slope re-simulated for {mu.ranking.n_draws} draws of its material parameters ({mu.basis}).",
             size=8.5)
    for line in mu.energy.text(mu.design_T):
        rep.text(line, size=8.5)
    rank_mu = mu.ranking.summary()
    rep.table(["option", f"expected total cost [{cur}]", f"trajectory model 5-95 % [{cur}]", "P(best | model)",
               "cost variance from the model"],
              [[r["option"], fmt(r["expected_total_cost"]), f"{fmt(r['model_cost_p05'])} - "
                f"{fmt(r['model_cost_p95'])}", f"{r['probability_best_given_model']:.2f}",
                f"{r.get('share_of_variance_from_trajectory_model', float('nan')):.0%}"]
               for _, r in rank_mu.iterrows()], widths=[2.2, 1.3, 1.9, 1, 1.2], size=7.2)
    rep.text(mu.verdict(), size=8.5, style="B")
    rep.figure(figs / "design_energy_model_uncertainty.png",
               f"The {mu.design_T:g}-year energy of each draw with its bootstrap interval.", max_height=90)


def _inventory_and_assumptions(rep, a, figs):
    """Write the inventory with its magnitude-frequency law, then the assumptions, defaults and warnings.

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    """
    from ..io.outputs import relative_paths
    rep.section("Inventory and magnitude-frequency law")
    gr = a.frequency.power_law
    rep.kv([("inventory", Path(str(a.inventory.source)).name), ("recorded falls", f"{a.inventory.n_events:,}"),
            ("record length", f"{fmt(a.inventory.duration_years)} years"),
            ("power-law exponent b", f"{fmt(gr.b)} ± {fmt(gr.b_stderr, 2)}"), ("m_min", f"{fmt(gr.m_min)} kg"),
            ("falls per year at or above m_min", fmt(gr.rate_min))])
    rep.figure(figs / "magnitude_frequency.png", "Magnitude-frequency of the inventory.", max_height=110)

    rep.section("Assumptions, defaults and warnings")
    for w in a.warnings:
        rep.text("• " + str(relative_paths(str(w), a.site.path.parent)), size=8.5)
    if a.site.defaults_used:
        rep.sub("Defaults applied (not stated in the site file)")
        rep.text("; ".join(a.site.defaults_used), size=8)


def _appendices(rep, a, figs):
    """Write appendix A (data from other sites, when the assessment has them) and appendix B (the run record).

    Parameters
    ----------
    rep : _Report
        The document being written.
    a : Assessment
        The finished assessment.
    figs : pathlib.Path
        Directory of the assessment's figures.
    """
    if a.maxima_frequency is not None or a.rates is not None:
        rep.section("Data from other sites (reference only)", appendix="A")
        rep.text("These records are not this site's: they show the methods (annual maxima, rainfall rate model) and "
                 "do not enter the design values above.", size=9)
        if a.maxima_frequency is not None:
            mf = a.maxima_frequency
            rep.kv([("record", Path(str(mf.inventory.source)).name), ("events", f"{mf.inventory.n_events:,}"),
                    ("years", f"{year(mf.inventory.duration_years)}")])
            rep.figure(figs / "annual_maxima" / "gumbel_plot.png", "Annual maxima of the regional record.",
                       max_height=100)
        if a.rates is not None:
            rep.text("Rate model: " + a.rates.rate_text(), size=8.5)
    rep.section("Run record", appendix="B")
    rep.kv([("riskrf version", str(_version())), ("seed", str(a.seed)), ("simulated blocks", f"{a.n_blocks:,}"),
            ("site file", a.site.path.name), ("outputs", "report.html, summary.json, CSV tables, figures/")])


def _version():
    from .. import __version__
    return __version__


__all__ = ["fmt", "pct", "title_block", "write_pdf_report", "year"]
