"""The typed records of the site file's tables are generated from the one declaration of the file
(riskrf.core.file_schemas.SITE_SCHEMA): every declared field is an attribute with its declared default, in
declaration order, and nothing else is."""
import dataclasses
import pickle

import pytest

from riskrf.core import file_schemas as fs
from riskrf.core.schema import REQUIRED, Field, Table, record_class


@pytest.mark.parametrize("records, table", [(fs.SITE_RECORDS, t) for t in fs.SITE_SCHEMA.tables]
                         + [(fs.CORRIDOR_RECORDS, t) for t in fs.CORRIDOR_SCHEMA.tables],
                         ids=lambda x: x.name if hasattr(x, "fields") else "")
def test_record_has_every_declared_field_with_its_default(records, table):
    rec = table.record({})
    assert [f.name for f in dataclasses.fields(rec)] == [f.name for f in table.fields]
    for f in table.fields:
        want = None if f.default is REQUIRED else f.default
        assert getattr(rec, f.name) == want, (table.name, f.name)
    assert rec.as_dict() == table.defaults()
    with pytest.raises(AttributeError):
        rec.not_a_declared_field
    with pytest.raises(AttributeError):           # frozen (dataclasses.FrozenInstanceError is an AttributeError)
        setattr(rec, table.fields[0].name, 1)
    with pytest.raises(TypeError):                # a key the table does not declare
        table.record({"not_a_declared_field": 1})
    assert pickle.loads(pickle.dumps(rec)) == rec
    assert table.record_type is records[table.name]     # built once per table


def test_record_names_are_unique_across_files():
    """The site's [rates] and the corridor's [rates] are different tables: their records have different names (a
    record pickles by its name in riskrf.core.file_schemas)."""
    assert fs.SITE_RECORDS["rates"].__name__ == "RatesTable"
    assert fs.CORRIDOR_RECORDS["rates"].__name__ == "CorridorRatesTable"
    assert fs.CORRIDOR_RECORDS["traffic"] is fs.SITE_RECORDS["traffic"]        # the same declaration
    for cls in {**fs.SITE_RECORDS, **{f"c.{k}": v for k, v in fs.CORRIDOR_RECORDS.items()}}.values():
        assert getattr(fs, cls.__name__) is cls


def test_as_record_reads_a_dict_or_none_into_the_record():
    from riskrf.core.schema import as_record
    rec = as_record(fs.REQUIRED_BARRIER, {"fixed_cost": 5.0})
    assert type(rec) is fs.SITE_RECORDS["required_barrier"] and rec.fixed_cost == 5.0 and rec.life_years == 25.0
    assert as_record(fs.REQUIRED_BARRIER, rec) is rec
    assert as_record(fs.REQUIRED_BARRIER, None) == fs.REQUIRED_BARRIER.record({})
    with pytest.raises(KeyError, match=r"^'site.toml: unknown field required_barrier.price; allowed: annual_"):
        as_record(fs.REQUIRED_BARRIER, {"price": 1}, source="site.toml", error=KeyError)
    with pytest.raises(ValueError, match=r"site.toml: \[required_barrier\] = 3 must be a table"):
        as_record(fs.REQUIRED_BARRIER, 3, source="site.toml")


def test_public_readers_take_the_record_or_the_dict_alike():
    from riskrf.hazard.design_basis import design_basis_from_site
    from riskrf.risk.required_barrier import cost_model_from_site
    table = {"cost_classes_kj": [1000, 5000], "cost_per_m": [500, 1500], "fixed_cost": 1e4}
    assert cost_model_from_site(table) == cost_model_from_site(fs.REQUIRED_BARRIER.record(table))
    assert cost_model_from_site(None) == cost_model_from_site(fs.REQUIRED_BARRIER.record({}))
    design = {"basis": "ONR 24810", "consequence_class": "CC2", "gamma_m": 1.1, "positions_x_m": [10.0, 20.0]}
    assert design_basis_from_site(design, design_T=50.0) == design_basis_from_site(fs.DESIGN.record(design),
                                                                                   design_T=50.0)
    assert design_basis_from_site(None) == design_basis_from_site({})


def test_given_values_and_copied_list_defaults():
    a, b = fs.HAZARD.record({"n_blocks": 7}), fs.HAZARD.record({})
    assert (a.n_blocks, b.n_blocks) == (7, 50_000)
    assert a.fences_kj == [2000.0, 5000.0] and a.fences_kj is not b.fences_kj
    assert a.fences_kj is not fs.HAZARD.field("fences_kj").default


def test_record_class_extra_attributes_and_bad_names():
    t = Table("demo_table", (Field("x_m", "number", "m", default=1.5),))
    cls = record_class(t, extra=(("read_file", object, None),))
    assert cls.__name__ == "DemoTableTable" and cls(read_file=3).read_file == 3 and cls().x_m == 1.5
    with pytest.raises(ValueError, match="'class'"):
        record_class(Table("t", (Field("class", "text"),)))


def test_site_holds_the_records():
    from pathlib import Path

    import riskrf
    from riskrf.app.site import SiteMitigation, load_site
    site = load_site(Path(riskrf.__file__).parent / "data" / "demo_site.toml")
    for name in ("inventory", "hazard", "design_block", "design", "report", "required_barrier"):
        assert type(getattr(site, name)) is fs.SITE_RECORDS[name]
    assert isinstance(site.mitigation, SiteMitigation) and site.mitigation.options
    assert site.hazard.collector == "barrier"            # filled in by the reader when left out
    # a default the reader applied is both in the record and reported
    for entry in site.defaults_used:
        table, _, rest = entry.partition(".")
        key = rest.split(" = ")[0]
        if table in ("inventory", "hazard", "design_block", "design", "report"):
            assert repr(getattr(getattr(site, table), key)) == rest.split(" = ", 1)[1], entry
    with pytest.raises(AttributeError):
        site.hazard.n_block                              # a misspelt field fails loudly, not a silent None


def test_no_string_key_reads_of_the_site():
    """The site's sections are read by attribute everywhere (a misspelt key would give None or a KeyError at run
    time; a misspelt attribute fails the same way for every site, and this scan keeps the dict reads out)."""
    import re
    from pathlib import Path

    import riskrf
    sections = "inventory|hazard|mitigation|design_block|rates|design|report|model_uncertainty|required_barrier"
    read = re.compile(rf"\bsite\.({sections})(\[|\.get\()")
    root = Path(riskrf.__file__).parent
    found = [f"{p.relative_to(root)}:{i}: {line.strip()}"
             for sub in ("app", "report", "cli", "risk", "hazard") for p in sorted((root / sub).rglob("*.py"))
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if read.search(line)]
    assert found == []
    assert read.search('x = a.site.hazard["n_blocks"]') and read.search("site.inventory.get('path')")


def test_table_readers_read_records_not_dicts():
    """The readers of a site's or a corridor's tables take the typed records and read them by attribute: no
    ``name["field"]`` or ``name.get("field")`` in their source.  The tables as written are read into records at
    one boundary (``riskrf.core.schema.as_record``, ``Table.record``; the dict of a whole file picks its tables);
    the receivers allowed below are not tables of the file."""
    import inspect
    import re

    from riskrf.app.corridor import file as corridor_file
    from riskrf.app.corridor import rates as corridor_rates
    from riskrf.app.corridor import rows as corridor_rows
    from riskrf.app import site as site_module
    from riskrf.hazard import design_basis
    from riskrf.risk import required_barrier, site_rates
    readers = [site_rates.check_rates, site_rates._check_inventory_rate_fields, site_rates._merge_rates_table,
               site_rates._check_rates_files, site_rates._check_rates_model_fields, site_rates._read_rates_inputs,
               site_rates._reader_options, site_rates.check_closure_options, site_rates.evaluate_rates,
               required_barrier.cost_model_from_site, design_basis.design_basis_from_site,
               corridor_file._corridor_settings, corridor_file._materials_template, corridor_rates._shared_rate,
               corridor_rates._mass_law, corridor_rows._share_corridor_rate, site_module._check_design,
               site_module._check_terrain_site, site_module._check_hazard, site_module._check_inventory,
               site_module._check_design_block]
    allowed = {"tables",        # the site's records by table name (riskrf.app.site._merge_site_tables)
               "reader",        # the sections table's reader options, built from the [corridor] record
               "template"}      # the scenario file whose materials the corridor's generated cuts use
    read = re.compile(r"(?<![\w.])(\w+)\s*(\[\s*[\"']|\.get\(\s*[\"'])")
    found = [f"{f.__module__}.{f.__name__}: {line.strip()}" for f in readers
             for line in inspect.getsource(f).splitlines()
             if any(m.group(1) not in allowed for m in read.finditer(line.split("#")[0]))]
    assert found == []
    assert read.search('x = cfg["basis"]') and read.search("table.get('share')")
    assert not read.search('rates.warnings_read["level"]')      # an attribute's DataFrame column
