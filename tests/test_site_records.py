"""The typed records of the site file's tables are generated from the one declaration of the file
(riskrf.core.file_schemas.SITE_SCHEMA): every declared field is an attribute with its declared default, in
declaration order, and nothing else is."""
import dataclasses
import pickle

import pytest

from riskrf.core import file_schemas as fs
from riskrf.core.schema import REQUIRED, Field, Table, record_class


@pytest.mark.parametrize("table", fs.SITE_SCHEMA.tables, ids=lambda t: t.name)
def test_record_has_every_declared_field_with_its_default(table):
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
    assert table.record_type is fs.SITE_RECORDS[table.name]     # built once per table


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
             for sub in ("app", "report", "cli") for p in sorted((root / sub).rglob("*.py"))
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if read.search(line)]
    assert found == []
    assert read.search('x = a.site.hazard["n_blocks"]') and read.search("site.inventory.get('path')")
